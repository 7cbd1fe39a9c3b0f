"""Offline recording of any pymunk space to a GIF (or MP4), with energy bars and a strip.

>>> with Recorder(space, "out.gif", fps=25) as rec:          # doctest: +SKIP
...     for _ in range(250):
...         step(space, 1 / 25, substeps=20)
...         rec.capture()

**Times.** The recorder keeps the space as it is when the recorder is made as frame 0, at
``t0`` (0 by default); each :meth:`Recorder.capture` after the space has been stepped is the
next frame, 1/fps later. So the loop above (step, then capture) gives 251 frames at t = 0,
0.04, ..., 10 s, each label the time of its picture. A capture before any step replaces frame
0 (the loop "capture, then step" gives frames at 0, 0.04, ... as well); a capture with no step
since the previous one shows the same time again. ``capture(t=...)`` gives a frame's time
yourself (in the space's time unit), when frames are not 1/fps of simulated time apart.
Whether the space was stepped is learnt from a pymunk post-step callback, which touches
nothing else of the space.

**Orientation.** ``y_up=None`` draws y the way the program's window does, decided when the
recorder is made from what the program has imported
(:func:`._recorder_checks.window_y_up`): y up when ``pymunk.pygame_util.positive_y_is_up``
is True; with pygame imported, y down (pygame's window), unless gravity points to -y (the
program then flips y itself, as pymunk's ``newtons_cradle`` does: in a y-down window its
bodies would fall up); with pyglet, arcade or kivy imported (and not pygame), y up; with no
window library (or both kinds), up against gravity, and up without vertical gravity.
``y_up=True`` or False says it; a ``world`` box (left, right, bottom, top) with bottom > top
is y down. ``rec.orientation`` says which way and why.

:class:`PaletteDrawOptions` is a ``pymunk.SpaceDebugDrawOptions``: ``space.debug_draw`` hands it
circles, segments and polygons, which it keeps as primitives in world coordinates; it adds the
constraints itself. The painting, framing and writing are
:mod:`dumbbell.animation.recording`'s.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Self

import numpy as np

from ..errors import DumbbellError, UsageError

# The arguments' checks, the window's orientation, the note's names, the potential terms.
from ._recorder_checks import (
    POTENTIALS,
    check_camera,
    check_path,
    check_reference,
    check_world,
    every_body,
    listed,
    window_y_up,
)

# The units' rule, the one every printed value of a space follows.
from .units import SI, UNIT_CHARS  # noqa: F401 - re-exported
from .units import check_units as _check_units
from .units import energy_unit as _energy_unit

#: Energy terms shown: the fields of :func:`dumbbell.spaces.energy` they come from.
TERMS = ("K_trans", "K_rot", "U_g", "U_spring", "E")
#: Labels of the rows when the potentials are shown from a reference.
DELTA_LABELS = {"U_g": "ΔU_g", "U_spring": "ΔU_spring", "E": "K + ΔU"}
#: Largest magnitude of a frame's time (``t0``, ``capture(t=...)``; the space's time unit):
#: its label, with two decimals or more, fits the frame.
TIME_MAX = 1e9

__all__ = ["PaletteDrawOptions", "Recorder", "draw_options"]  # noqa: F822 - see __getattr__


def _options_class() -> type:
    """``PaletteDrawOptions``: it subclasses pymunk's class, so its module imports pymunk."""
    from ._draw import PaletteDrawOptions

    return PaletteDrawOptions


def draw_options() -> Any:
    """A new ``PaletteDrawOptions`` (a ``pymunk.SpaceDebugDrawOptions``).

    Returns
    -------
    PaletteDrawOptions
        Options for ``space.debug_draw``.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> options = spaces.draw_options()
    >>> isinstance(options, pymunk.SpaceDebugDrawOptions)
    True
    >>> pymunk.Space().debug_draw(options)         # collects what the recorder draws
    """
    return _options_class()()


def __getattr__(name: str) -> Any:
    # PaletteDrawOptions subclasses pymunk's class, so it is made when first asked for.
    if name == "PaletteDrawOptions":
        return _options_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: What a copy of a :class:`Recorder` keeps beside its frozen recording (see
#: ``Recorder.__reduce__``): its settings, its frames' times, what it wrote and why.
_KEPT_BY_A_COPY = frozenset({
    "path", "fps", "W", "H", "units", "energy", "strip", "world", "span", "y_up", "_up",
    "orientation", "reference", "t0", "title", "about", "timing", "view", "note", "_names",
    "_captured", "t"})


def _frozen_recorder(state: dict[str, Any]) -> Recorder:
    """A copy of a recorder (see ``Recorder.__reduce__``)."""
    rec = object.__new__(Recorder)
    rec.__dict__.update(state)
    return rec


class Recorder:
    """Records ``space`` into ``path`` (.gif, or .mp4 with the ``[mp4]`` extra) at ``fps``
    frames per second: step the space yourself and call :meth:`capture` once per frame; the
    file is written when the ``with`` block ends (nothing is written if it raises). The path
    is checked when the recorder is made.

    - Times (see the module docstring): frame 0 is the space when the recorder is made, at
      ``t0``; each capture after stepping is 1/fps later, or at ``capture(t=...)``.
    - ``energy``: bars of K_trans, K_rot, the potentials and E on one fixed scale, and a
      ``strip`` of them over the whole recording with a cursor; a ``heat`` counter
      (:class:`~dumbbell.spaces.HeatCounter`) adds its total and E + heat. ``reference``:
      ``"start"`` shows each potential energy as its change since frame 0 (ΔU_g, ΔU_spring)
      and E as K + ΔU, so the bars mean something whatever the space's origin; ``"space"``
      as :func:`~dumbbell.spaces.energy` reports them; a mapping (``{"U_g": -4.5e6}``) as the
      change from energies you set. ``units`` = (length, mass, time), or the length unit
      alone (mass in kg, time in s, as the guard's ``units``), names the space's units on
      every label (energy in mass·length²/time², J in SI).
    - The view: ``camera="auto"`` frames where the moving bodies move (one fixed view for
      the file, robust to a body flying away; static shapes never shrink the bodies: see
      :mod:`dumbbell.animation.recording`), ``"all"`` everything captured, a
      ``pymunk.Body`` follows that body (a view ``span`` units across, default 8 times the
      body's size); ``world`` = (left, right, bottom, top) fixes the box (bottom > top: y is
      down). ``y_up``: None (as the program's window shows it, see the module docstring),
      True or False. ``size`` 'WxH' px; ``title`` is written at the top; ``about`` is the
      point angular momentum is taken about.
    - Every moving body is drawn at least 4 px across, larger than to scale if need be.
      After writing, :attr:`view` is the box shown and :attr:`note` says what the picture
      does not show as it is: which way y points and why (:attr:`orientation`), the bodies
      drawn larger than to scale, those outside the picture in some frames.

    Parameters
    ----------
    space : pymunk.Space
        The space.
    path : str or pathlib.Path
        The file (.gif; .mp4 with the ``[mp4]`` extra).
    fps : int, default 25
        Frames per second.
    energy : bool, default True
        Draw the energy bars and strip.
    size : str or tuple of int, default '640x360'
        The picture, 'WxH' (px).
    strip : bool, default True
        The energy strip over the whole recording.
    heat : HeatCounter or None, default None
        Add its total and E + heat.
    world : tuple of float or None, default None
        The view (x0, y0, x1, y1) in length units; None: the camera's.
    camera : str or tuple, default 'auto'
        How the view follows the bodies.
    span : float or None, default None
        The time the strip shows.
    y_up : bool or None, default None
        Which way y points on screen; None: as the program's window does.
    units : str or tuple of str or None, default None
        The space's units ('m', 'px' or (length, mass, time)); None: not named.
    reference : str or float, default 'start'
        Where the potentials are counted from.
    t0 : float, default 0.0
        The time of frame 0.
    title : str, default ''
        A title.
    about : tuple of float, default (0.0, 0.0)
        The point angular momentum is taken about.

    Raises
    ------
    UsageError
        An argument that is not allowed, naming it, before any work.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a rod thrown up, tumbling, SI units
    >>> space.gravity = (0.0, -9.8)
    >>> rod = pymunk.Body(1.0, pymunk.moment_for_segment(1.0, (-0.3, 0), (0.3, 0), 0.02))
    >>> rod.velocity, rod.angular_velocity = (0.5, 4.0), 6.0
    >>> space.add(rod, pymunk.Segment(rod, (-0.3, 0), (0.3, 0), 0.02))
    >>> rec = spaces.Recorder(space, "rod.gif", fps=10, size="320x180", units="m")
    >>> for frame in range(10):
    ...     spaces.step(space, 1 / 10, substeps=10)
    ...     rec.capture()
    >>> len(rec.recording().t)                     # frame 0 and ten captures
    11
    >>> rec.write().name            # a ``with`` block (``with Recorder(...) as rec:``) writes
    'rod.gif'
    >>> open("rod.gif", "rb").read(6)
    b'GIF89a'
    """

    def __init__(self, space: Any, path: str | Path, fps: int = 25, energy: bool = True, *,
                 size: str | tuple[int, int] = "640x360", strip: bool = True,
                 heat: Any = None, world: tuple[float, float, float, float] | None = None,
                 camera: Any = "auto", span: float | None = None, y_up: bool | None = None,
                 units: str | tuple[str, str, str] | None = None, reference: Any = "start",
                 t0: float = 0.0,
                 title: str = "", about: tuple[float, float] = (0.0, 0.0)) -> None:
        import pymunk

        from ..animation.timing import check_fps, check_size
        from ..model import args
        from .heat import HeatCounter

        self.space = args.space(space)
        self.path = check_path(path)
        self.fps = check_fps(fps)
        self.W, self.H = check_size(size)
        self.units = _check_units(units)
        self.energy = args.flag(energy, "energy")
        self.strip = args.flag(strip, "strip") and self.energy
        self.heat = None if heat is None else args.instance(
            heat, "heat", HeatCounter, "a dumbbell.spaces.HeatCounter or None")
        if self.heat is not None and self.heat.__dict__.get("space") is not self.space:
            raise UsageError("heat: a HeatCounter of another space (or a copy, which counts "
                             "nothing): give the one attached to the space recorded",
                             param="heat")
        self.world = None if world is None else check_world(world, self.units[0])
        self.camera: Any = check_camera(camera, self.world, self.space)
        self.span = None if span is None else args.real(span, "span", self.units[0])
        if self.span is not None and not isinstance(self.camera, pymunk.Body):
            raise UsageError(f"span = {args.show(span)}: only for a followed body "
                             "(camera=<a pymunk.Body>)", param="span")
        self.y_up = None if y_up is None else args.flag(y_up, "y_up")
        if self.world is not None and self.y_up is not None and self.y_up != (
                self.world[3] > self.world[2]):
            raise UsageError(f"y_up = {y_up}: the world box {args.show(world)} says y is "
                             f"{'up' if self.world[3] > self.world[2] else 'down'}; give one "
                             "of them", param="y_up")
        if self.world is not None:
            up, why = self.world[3] > self.world[2], "the world box says so"
        elif self.y_up is not None:
            up, why = self.y_up, "y_up says so"
        else:
            up, why = window_y_up(self.space)
        self._up = up
        #: Which way y points in the picture, and why (see the module docstring).
        self.orientation = f"y {'up' if up else 'down'}: {why}"
        self.reference = check_reference(reference, _energy_unit(self.units))
        self.t0 = args.real(t0, "t0", self.units[2], lo=-TIME_MAX, hi=TIME_MAX)
        self.title = args.text(title, "title", "a str (written at the top)")
        if any(ord(c) < 32 or ord(c) == 127 for c in self.title):
            raise UsageError(f"title = {args.show(self.title)}: must be one line (no newline "
                             "or other control character)", param="title")
        self.about = args.pair(about, "about", self.units[0])
        self.options = draw_options()
        self._no_frames()
        if self.energy:
            from ._refusals import refuse_settings
            from ._sampler import _Sampler

            refuse_settings(self.space)
            self._sampler = _Sampler(self.space)
        self.timing: dict[str, float] = {}
        #: The world box shown (left, right, bottom, top, y up) once the file is written.
        self.view: tuple[float, float, float, float] | None = None
        #: Once the file is written: what the picture does not show as it is, one line each
        #: (the orientation and why; the bodies drawn larger than to scale; those outside
        #: the picture in some frames).
        self.note: str | None = None
        self._names: dict[int, str] = {}  # moving body's number -> "body i" when first seen
        self._key = ("dumbbell.spaces.Recorder", id(self))
        self._stepped = False
        self._captured = False
        self._clock = (self.t0, 0)  # (the last time given, frames since)
        self._keep(self.t0)

    def _no_frames(self) -> None:
        """What the frames keep, empty. Per frame: its set of moving shapes (an index into
        shape_sets), its bodies' poses, its constraints' primitives, its static set (an index
        into statics), its time, the followed point, the heat so far."""
        self.shape_sets: list[Any] = []
        self.shape_of: list[int] = []
        self.poses: list[np.ndarray] = []
        self.extras: list[tuple[tuple, ...]] = []
        self.statics: list[tuple[tuple, ...]] = []
        self.static_of: list[int] = []
        self.t: list[float] = []
        self.follow: list[tuple[float, float]] = []
        self.heat_total: list[float] = []
        self._geometry: Any = None
        self._static_pose: np.ndarray | None = None

    def __repr__(self) -> str:
        from ..model import args

        return (f"Recorder({args.show(str(self.path))}, {self.fps} fps, {self.W}x{self.H}, "
                f"frames={self.frames}, energy={self.energy})")

    def __enter__(self) -> Self:
        return self

    def __reduce__(self) -> tuple[Any, ...]:
        # Copied or pickled (alone, or with its space: space.copy(), copy.deepcopy), a
        # recorder is what it captured so far, frozen: the copy does not capture, and
        # writes those frames. (The draw options it captures through hold C memory, and
        # number this space's bodies only.)
        state = {k: v for k, v in self.__dict__.items() if k in _KEPT_BY_A_COPY}
        state.update(t=list(self.t), timing=dict(self.timing), _names=dict(self._names),
                     _frozen=self.recording())
        return (_frozen_recorder, (state,))

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        if exc_type is None:
            self.write()

    @property
    def frames(self) -> int:
        """Frames so far (frame 0, the space when the recorder was made, included)."""
        return len(self.t)

    @property
    def times(self) -> tuple[float, ...]:
        """The time of each frame so far (the space's time unit)."""
        return tuple(self.t)

    def _on_step(self, space: Any, key: Any) -> None:
        self._stepped = True

    def capture(self, t: float | None = None) -> None:
        """Keep the space as it is now as the next frame, at time ``t`` (the space's time
        unit; default: 1/fps after the previous frame if the space was stepped since, else
        the previous frame's time). Before any step, it replaces frame 0.

        Parameters
        ----------
        t : float or None, default None
            The frame's time (the space's time unit).

        Raises
        ------
        UsageError
            A time that is not a finite number within the allowed range.
        DumbbellError
            A copy of a recorder (copying or pickling a recorder or its space freezes it).
        """
        from ..model import args

        if "_frozen" in self.__dict__:
            raise DumbbellError(f"{self.path}: this recorder is a copy (of a recorder, or of "
                                "its space): it does not capture; make a new Recorder")
        previous = self.t[-1]
        if t is not None:
            t = args.real(t, "t", self.units[2], lo=-TIME_MAX, hi=TIME_MAX)
        first = not self._captured and not self._stepped
        if t is not None and not first and not t >= previous:
            raise UsageError(f"t = {t:g}: must be at least the previous frame's time "
                             f"{previous:g} {self.units[2]}", param="t")
        if first:
            self._drop_last()
        if t is not None:
            self._clock = (t, 0)  # times counted on from here
        elif not first and self._stepped:
            # Counted in whole frames from the last time given, not summed: 50 frames at
            # 25 fps end at 2.0 s, not 2.0000000000000004.
            self._clock = (self._clock[0], self._clock[1] + 1)
        self._keep(self._clock[0] + self._clock[1] / self.fps)
        self._captured = True

    def _keep(self, t: float) -> None:
        """Keep the space now as a frame at time ``t``: its bodies' poses (the shapes are
        placed when the file is drawn), its constraints' primitives, and its energy."""
        from ._draw import constraint_items

        space = self.space
        geometry = self.options._geometry_of(space)
        pose = geometry.poses(space)
        if geometry is not self._geometry:
            self._name(geometry.bodies)
            self._geometry, self._static_pose = geometry, None
            self.shape_sets.append(geometry.moving)
        static_pose = pose[geometry.static_rows]
        if self._static_pose is None or not np.array_equal(static_pose, self._static_pose):
            static = tuple(geometry.static.items(pose))
            if not self.statics or static != self.statics[-1]:
                self.statics.append(static)
            self._static_pose = static_pose
        self.shape_of.append(len(self.shape_sets) - 1)
        self.poses.append(pose)
        self.extras.append(tuple(constraint_items(space, self.options._number_of)))
        self.static_of.append(len(self.statics) - 1)
        self.t.append(float(t))
        if not isinstance(self.camera, str):
            p = self.camera.local_to_world(self.camera.center_of_gravity)
            self.follow.append((float(p.x), float(p.y)))
        if self.energy:
            self._sampler.sample()
            self.heat_total.append(float(self.heat.total) if self.heat is not None else 0.0)
        self._stepped = False
        space.add_post_step_callback(self._on_step, self._key)

    def _drop_last(self) -> None:
        for values in (self.shape_of, self.poses, self.extras, self.static_of, self.t,
                       self.follow, self.heat_total):
            if values:
                values.pop()
        if self.energy:
            self._sampler.drop()
        if self.static_of.count(len(self.statics) - 1) == 0 and len(self.statics) > 1:
            self.statics.pop()
        elif not self.static_of:
            self.statics.clear()
        self._geometry = self._static_pose = None  # the next frame takes them again

    # --- writing -------------------------------------------------------------------------

    def _rows(self) -> tuple[dict[str, np.ndarray], dict[str, str]]:
        """The energy rows shown (name -> values) and their labels."""
        terms = self._sampler.terms(self.about)
        e = {name: terms[name] for name in TERMS}
        labels = {name: name for name in TERMS}
        if self.reference != "space":
            refs = ({n: float(e[n][0]) for n in POTENTIALS} if self.reference == "start"
                    else {n: self.reference.get(n, 0.0) for n in POTENTIALS})
            for name in POTENTIALS:
                e[name] = e[name] - refs[name]
            e["E"] = e["E"] - sum(refs.values())
            labels.update(DELTA_LABELS)
        if self.heat is not None:
            e["heat"] = np.asarray(self.heat_total, dtype=float)
            labels["heat"] = "heat"
        return e, labels

    def recording(self) -> Any:
        """The frozen :class:`dumbbell.animation.recorded.Recording` of what was captured.

        Returns
        -------
        dumbbell.animation.recorded.Recording
            What was captured, frozen.
        """
        from ..animation.camera import item_box
        from ..animation.recorded import Recording

        frozen = self.__dict__.get("_frozen")
        if frozen is not None:
            return frozen
        kw: dict[str, Any] = {}
        if self.energy:
            rows, labels = self._rows()
            kw.update(energy=rows, labels=labels, heat=self.heat is not None,
                      energy_title=f"Energy ({_energy_unit(self.units)})")
        if self.world is not None:
            x0, x1, y0, y1 = self.world
            kw.update(camera="box", box=(x0, x1, min(y0, y1), max(y0, y1)))
        elif isinstance(self.camera, str):
            kw.update(camera=self.camera)
        else:
            span = self.span
            if span is None:
                # 8 times the body's size: its shapes' box when first seen.
                boxes = [item_box(it) for it in self._shapes_of(self.camera)]
                size = max((max(b[1] - b[0], b[3] - b[2]) for b in boxes), default=0.0)
                span = 8 * size if size > 0 and math.isfinite(size) else 1.0
            kw.update(camera="follow", follow=tuple(self.follow), span=span)
        return Recording(shapes=tuple(self.shape_sets), shape_of=tuple(self.shape_of),
                         poses=tuple(self.poses), extras=tuple(self.extras),
                         statics=tuple(self.statics), static_of=tuple(self.static_of),
                         t=tuple(self.t),
                         size=(self.W, self.H), fps=self.fps, y_up=self._up,
                         strip=self.strip, title=self.title, time_unit=self.units[2], **kw)

    def _shapes_of(self, body: Any) -> list[tuple]:
        """The followed body's shapes in the first frame that shows them."""
        number = self.options._number_of(body)
        for k, i in enumerate(self.shape_of):
            if k and i == self.shape_of[k - 1]:
                continue  # the same shapes as the frame before
            shapes = [it for it in self.shape_sets[i].items(self.poses[k]) if it[2] == number]
            if shapes:
                return shapes
        return []

    def write(self) -> Path:
        """Draw and write the file (called when the ``with`` block ends).

        Returns
        -------
        pathlib.Path
            The file written.
        """
        from ..animation import recording

        if not self._captured:
            raise DumbbellError(f"{self.path}: no frames captured (call capture() after each "
                                "frame's steps)")
        if self.path.suffix.lower() in (".html", ".htm"):  # the interactive player
            from ..animation import space_player

            panel = space_player.write(self.path, self.recording(), self.timing)
        else:
            panel = recording.write(self.path, self.recording(), self.timing)
        x0, x1, y0, y1 = panel.view
        self.view = (x0, x1, y0, y1) if panel.rec.y_up else (x0, x1, y1, y0)
        self.note = self._note(panel)
        return self.path

    def _name(self, bodies: list[Any]) -> None:
        """Name the moving bodies not named yet by their place in the space now, as the
        accounting names them ("body 3")."""
        number = self.options._number_of
        new = [b for b in bodies if number(b) >= 0 and number(b) not in self._names]
        if new:
            place = {id(b): i for i, b in enumerate(self.space.bodies)}
            for b in new:
                i = place.get(id(b))
                self._names[number(b)] = "a body not in the space" if i is None else f"body {i}"

    def _note(self, panel: Any) -> str:
        """The note on the picture (see :attr:`note`), from the view panel that drew it."""
        lines = [self.orientation]
        name = self._names.get
        if panel.grown:
            grown = sorted(panel.grown)
            lines.append(f"drawn larger than to scale, to be {panel.body_px:g} px across: "
                         f"{every_body([name(n, f'body #{n}') for n in grown])} "
                         f"({len(grown)} of {len(self._names)} moving bodies; camera=<a body> "
                         "follows one at a larger scale)")
        seen, shown = panel.frames_in, panel.frames_shown
        out = np.flatnonzero(shown < seen).tolist()
        if out:
            lines.append("outside the picture (or not drawable) in some frames: " + listed(
                [f"{name(n, f'body #{n}')} in {seen[n] - shown[n]} of {seen[n]}" for n in out]))
        return "\n".join(lines)
