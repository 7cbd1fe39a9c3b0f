"""Scenes: plain, validated data read from TOML files.

A scene says only what it needs; a table it leaves out is not built (no ``[floor]``: no impact
handling; no ``[gravity]``: no gravity; no ``[spring]``: the particles do not interact).

>>> scene = load_scene("scenes/textbook-1d.toml")      # doctest: +SKIP
>>> scene.system.spring.stiffness, scene.run.dt
(200.0, 1e-05)

A :class:`Scene` is the physics (:class:`System`: what solvers and energy formulas read)
plus the settings of the run, the outputs and the pymunk engine. The parsed document is not
kept: :meth:`Scene.to_dict` rebuilds it from the fields, and :meth:`Scene.with_values`
re-validates a copy with keys changed by their dotted names, which is how sweeps vary a scene.

Every failure raises one :class:`SceneError` naming the file, the dotted key and what is
allowed.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SceneError, UsageError
from .checker import MIN_MASS, _check_magnitude, _Checker, _finite, _printable, _show
from .pymunk_settings import PymunkSettings
from .scene_file import MAX_SCENE_BYTES, _read_scene_file, _toml
from .sizes import SIZE_RULE, pixel_size
from .system import (
    DEFAULT_INACCURATE_ENERGY,
    DEFAULT_UNSTABLE_ENERGY,
    Floor,
    GifSettings,
    OutputSettings,
    Particle,
    Rigid,
    RunSettings,
    Spring,
    System,
)

__all__ = ["Scene", "load_scene", "scene_from_dict", "scenes_dir"]

#: Figure names ``[outputs] figures`` may list.
FIGURE_NAMES = ("positions", "kinetic", "potential", "energy", "rotation", "topple", "contact")
#: What a GIF size must be.
#: Radius given to particles that do not state one (m); only pymunk and drawings use it.
DEFAULT_RADIUS = 0.02


@dataclass(frozen=True)
class Scene:
    """A validated scene: a title, the physics (:class:`System`), the default run options, the
    outputs ``dumbbell run`` makes and the pymunk engine's settings. Build it with
    :func:`load_scene` or :func:`scene_from_dict`, not by hand: they check every value.

    Parameters
    ----------
    title : str
        What figures and GIFs are titled.
    system : System
        The physics: the particles, the spring or rigid rod, the floor, ``g`` (m/s²), and
        derived ``M``, ``mu`` (kg), ``omega`` (rad/s).
    run : RunSettings
        The default run: ``t_end`` and ``dt`` (s), ``solver``, ``every``, ...
    outputs : OutputSettings
        What ``dumbbell run`` writes: figures, CSV, GIF settings.
    pymunk : PymunkSettings
        The pymunk engine's settings (iterations, spin, ...).
    source : str, default "<scene>"
        The file it was read from; :attr:`name` (which names outputs) is its stem.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> scene.name, scene.system.spring.stiffness, scene.run.dt
    ('textbook-1d', 200.0, 1e-05)
    >>> round(scene.system.omega, 4)                   # sqrt(k / mu), rad/s
    63.2456
    >>> scene.with_values({"spring.stiffness": 2e4}).system.spring.stiffness
    20000.0
    >>> scene.to_dict()["spring"]
    {'stiffness': 200.0, 'rest_length': 0.2}
    """

    title: str
    system: System
    run: RunSettings
    outputs: OutputSettings
    pymunk: PymunkSettings
    source: str = "<scene>"

    @property
    def name(self) -> str:
        """The scene file's stem, used to name outputs."""
        return Path(self.source).stem if self.source != "<scene>" else "scene"

    def to_dict(self) -> dict[str, Any]:
        """The scene as a parsed TOML document, built afresh from the fields:
        ``scene_from_dict(scene.to_dict(), scene.source) == scene``. Every key is written
        except two that follow another key, as they do in a file: A's position when ``tilt``
        places it, and ``outputs.gif.t_end`` when it is the run's ``t_end``.

        Returns
        -------
        dict
            Tables and keys as a TOML file has them (``{"title": ..., "bodies": {...}}``).

        Examples
        --------
        >>> import dumbbell
        >>> from dumbbell.model.scene import scene_from_dict, scenes_dir
        >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
        >>> scene.to_dict()["bodies"]["A"]
        {'mass': 0.1, 'radius': 0.02, 'height': 1.2, 'velocity': 0.0}
        >>> scene_from_dict(scene.to_dict(), scene.source) == scene
        True
        """
        s, run, out = self.system, self.run, self.outputs
        doc: dict[str, Any] = {"title": self.title, "dimensions": s.dimensions}
        if s.tilt is not None:
            doc["tilt"] = s.tilt
        doc["bodies"] = {"A": _particle_table(s.A, s.dimensions, placed=s.tilt is not None),
                         "B": _particle_table(s.B, s.dimensions, placed=False)}
        if s.spring is not None:
            doc["spring"] = {"stiffness": s.spring.stiffness, "rest_length": s.spring.rest_length}
        if s.rigid is not None:
            doc["rigid"] = {"length": s.rigid.length}
        if s.floor is not None:
            doc["floor"] = {"elasticity": s.floor.elasticity, "friction": s.floor.friction}
        doc["gravity"] = {"g": s.g}
        doc["run"] = {"t_end": run.t_end, "dt": run.dt, "solver": run.solver,
                      "every": run.every, "unstable_energy": run.unstable_energy,
                      "inaccurate_energy": run.inaccurate_energy}
        doc["outputs"] = {"figures": list(out.figures), "csv": out.csv}
        if out.gif is not None:
            gif = {"fps": out.gif.fps, "size": out.gif.size, "strip": out.gif.strip}
            if out.gif.t_end != run.t_end:
                gif["t_end"] = out.gif.t_end
            doc["outputs"]["gif"] = gif
        pymunk = self.pymunk._table()
        if s.discs:
            pymunk["spin"] = True
        if pymunk:
            doc["pymunk"] = pymunk
        return doc

    def with_values(self, values: dict[str, Any]) -> Scene:
        """A new scene with keys replaced by dotted name, validated like a file.

        Parameters
        ----------
        values : dict of str to value
            Dotted key (``"spring.stiffness"``, ``"run.dt"``, ``"bodies.A.mass"``) -> its new
            value, in the units the scene file uses.

        Returns
        -------
        Scene
            The changed copy; this scene is left as it is.

        Raises
        ------
        SceneError
            A key the scene file does not have, or a value it does not allow (one line
            naming the key and what is allowed).

        Examples
        --------
        >>> import dumbbell
        >>> from dumbbell.model.scene import scenes_dir
        >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
        >>> stiff = scene.with_values({"spring.stiffness": 2e4, "run.dt": 1e-4})
        >>> stiff.system.spring.stiffness, stiff.run.dt, scene.system.spring.stiffness
        (20000.0, 0.0001, 200.0)
        >>> scene.with_values({"spring.stiffness": -1})
        Traceback (most recent call last):
        ...
        dumbbell.errors.SceneError: ...textbook-1d.toml: spring.stiffness = -1.0: must be a finite number >= 0 (N/m)
        """
        if not isinstance(values, dict) or not all(isinstance(k, str) for k in values):
            raise SceneError(f"values = {_show(values)}: must be a dict of dotted key names "
                             "(str) to values")
        raw = self.to_dict()
        for dotted, value in values.items():
            parts = dotted.split(".")
            table = raw
            for part in parts[:-1]:
                nxt = table.setdefault(part, {})
                if not isinstance(nxt, dict):
                    raise SceneError(f"{_printable(self.source)}: {_printable(dotted)}: "
                                     f"'{_printable(part)}' is not a table")
                table = nxt
            table[parts[-1]] = value
        return scene_from_dict(raw, source=self.source)


# --- validation -----------------------------------------------------------------------------


def _velocity(c: _Checker, dims: int) -> tuple[float, float]:
    c.used.add("velocity")
    if "velocity" not in c.table:
        return 0.0, 0.0
    value = c.table["velocity"]
    dotted = c.key("velocity")
    if dims == 1:
        if _finite(value) is None:
            c.fail(dotted, value, "must be a finite number (m/s, upward) in a 1D scene")
        _check_magnitude(c, dotted, float(value), "m/s")
        return 0.0, float(value)
    ok = (
        isinstance(value, list)
        and len(value) == 2
        and all(_finite(v) is not None for v in value)
    )
    if not ok:
        c.fail(dotted, value, "must be a list of two finite numbers [vx, vy] (m/s) in a 2D scene")
    for v in value:
        _check_magnitude(c, dotted, float(v), "m/s")
    return float(value[0]), float(value[1])


def _particle(c: _Checker, name: str, dims: int, placed: bool) -> Particle:
    mass = c.number("mass", lo=0.0, lo_open=True, unit="kg")
    if mass < MIN_MASS:
        c.fail(c.key("mass"), mass, f"must be at least {MIN_MASS:g} (kg): smaller masses "
                                    "overflow the spring's frequency")
    radius = c.number("radius", DEFAULT_RADIUS, lo=0.0, unit="m")
    if placed:
        # A placed from B by the tilt: its own position would contradict it.
        for key in ("height", "x"):
            if c.has(key):
                c.fail(c.key(key), c.table[key], "must be left out when 'tilt' places A")
        height = x = 0.0
    else:
        height = c.number("height", unit="m, initial height of the centre")
        x = c.number("x", 0.0, unit="m") if dims == 2 else 0.0
    vx, vy = _velocity(c, dims)
    spin = c.number("spin", 0.0, unit="rad/s") if dims == 2 else 0.0
    c.done()
    return Particle(name, mass, x, height, vx, vy, radius, spin)


def _particle_table(p: Particle, dims: int, placed: bool) -> dict[str, Any]:
    """The [bodies.NAME] table of ``p``, as :func:`_particle` reads it; without the position
    when the tilt places the particle."""
    table: dict[str, Any] = {"mass": p.mass, "radius": p.radius}
    if not placed:
        table["height"] = p.height
        if dims == 2:
            table["x"] = p.x
    table["velocity"] = [p.vx, p.vy] if dims == 2 else p.vy
    if dims == 2:
        table["spin"] = p.spin
    return table


def scene_from_dict(data: dict[str, Any], source: str = "<scene>") -> Scene:
    """Validate a parsed TOML document and build a :class:`Scene`, as :func:`load_scene` does
    with a file's.

    Parameters
    ----------
    data : dict
        The document: tables and keys as in a scene file (docs/scenes.md).
    source : str, default "<scene>"
        What messages and outputs call the scene (a file's path, for a file).

    Returns
    -------
    Scene
        The validated, frozen scene.

    Raises
    ------
    SceneError
        Any key or value the scene file does not allow, in one line naming it.

    Examples
    --------
    >>> from dumbbell.model.scene import scene_from_dict
    >>> scene = scene_from_dict({
    ...     "dimensions": 1,
    ...     "bodies": {"A": {"mass": 0.1, "height": 1.2}, "B": {"mass": 0.1, "height": 1.0}},
    ...     "spring": {"stiffness": 200.0, "rest_length": 0.2},
    ...     "floor": {"elasticity": 1.0},
    ...     "gravity": {"g": 9.8},
    ...     "run": {"t_end": 1.0, "dt": 1e-4},
    ... }, source="mine.toml")
    >>> scene.name, scene.system.M, scene.system.g    # without [gravity], g = 0
    ('mine', 0.2, 9.8)
    >>> scene_from_dict({"dimensions": 3})
    Traceback (most recent call last):
    ...
    dumbbell.errors.SceneError: <scene>: ...
    """
    if not isinstance(data, dict):
        raise SceneError(f"data = {_show(data)}: must be a dict (a parsed scene document)")
    if not isinstance(source, str):
        raise SceneError(f"source = {_show(source)}: must be a str (the scene's file name)")
    try:
        return _scene_from_dict(data, source)
    except RecursionError:
        raise SceneError(f"{_printable(source)}: nested too deeply to be a scene") from None


def _scene_from_dict(data: dict[str, Any], source: str) -> Scene:
    """The scene of a document: one reader per table, in the order a file is checked, so
    the first problem found is the one reported."""
    top = _Checker(source, data, "")
    title = top.string("title", Path(source).stem)
    if not isinstance(title, str):
        top.fail("title", title, "must be a string")
    dims = top.integer("dimensions", 1, lo=1, hi=2)
    tilt = None
    if dims == 2 and top.has("tilt"):
        tilt = top.number("tilt", lo=-180.0, hi=180.0, unit="degrees of the axis from vertical")
    cA, cB = _bodies_tables(top, source)
    spring = _spring(top)
    rigid = _rigid(top, dims, spring)
    if tilt is not None and spring is None and rigid is None:
        top.fail("tilt", tilt, "needs a [spring] or [rigid] to set the distance from B to A")
    length = rigid.length if rigid else spring.rest_length if spring else None
    A, B = _particles(cA, cB, dims, tilt, length)
    floor = _floor(top, dims)
    _check_placement(A, B, dims, floor, source)
    _check_rod(A, B, rigid, source)
    g = _gravity(top)
    run = _run(top, source)
    outputs = _outputs(top, dims, floor is not None, rigid is not None, run.t_end)
    pm, discs = _pymunk(top)
    top.done()
    system = System(dimensions=dims, A=A, B=B, spring=spring, rigid=rigid, floor=floor, g=g,
                    tilt=tilt, discs=discs and dims == 2)
    return Scene(title=title, system=system, run=run, outputs=outputs, pymunk=pm, source=source)


def _bodies_tables(top: _Checker, source: str) -> tuple[_Checker, _Checker]:
    """The checkers of [bodies.A] and [bodies.B], both required."""
    bodies = top.sub("bodies")
    if bodies is None:
        raise SceneError(f"{_printable(source)}: "
                         "[bodies] is missing: needs [bodies.A] and [bodies.B]")
    cA, cB = bodies.sub("A"), bodies.sub("B")
    if cA is None or cB is None:
        missing = "bodies.A" if cA is None else "bodies.B"
        raise SceneError(f"{_printable(source)}: "
                         f"[{missing}] is missing: a dumbbell has particles A and B")
    bodies.done()
    return cA, cB


def _spring(top: _Checker) -> Spring | None:
    """[spring]: stiffness (N/m) and rest length (m)."""
    cs = top.sub("spring")
    if cs is None:
        return None
    spring = Spring(cs.number("stiffness", lo=0.0, unit="N/m"),
                    cs.number("rest_length", lo=0.0, unit="m"))
    cs.done()
    return spring


def _rigid(top: _Checker, dims: int, spring: Spring | None) -> Rigid | None:
    """[rigid]: a massless rod of ``length`` (m) between A and B, in 2D only."""
    cr = top.sub("rigid")
    if cr is None:
        return None
    if dims != 2:
        cr.fail("rigid", "[rigid]", "a rigid rod needs dimensions = 2")
    if spring is not None:
        cr.fail("rigid", "[rigid]", "a scene has either [spring] or [rigid], not both")
    rigid = Rigid(cr.number("length", lo=0.0, lo_open=True, unit="m"))
    cr.done()
    return rigid


def _particles(cA: _Checker, cB: _Checker, dims: int, tilt: float | None,
               length: float | None) -> tuple[Particle, Particle]:
    """A and B; with ``tilt`` (degrees from vertical) A is placed from B along the axis, at
    ``length`` (m: the rod's or the spring's rest length) from it."""
    B = _particle(cB, "B", dims, placed=False)
    A = _particle(cA, "A", dims, placed=tilt is not None)
    M = A.mass + B.mass
    if not (math.isfinite(M) and A.mass * B.mass / M > 0):
        raise SceneError(f"{_printable(cB.source)}: "
                         f"bodies.A.mass = {_show(A.mass)}, bodies.B.mass = "
                         f"{_show(B.mass)}: their total and reduced mass must be finite and "
                         "> 0 (kg)")
    if tilt is not None:
        assert length is not None  # a tilt needs a spring or a rod (checked before)
        theta = math.radians(tilt)
        A = Particle(
            "A", A.mass, B.x + length * math.sin(theta), B.height + length * math.cos(theta),
            A.vx, A.vy, A.radius, A.spin,
        )
    return A, B


def _floor(top: _Checker, dims: int) -> Floor | None:
    """[floor]: elasticity (restitution) and Coulomb friction (2D only)."""
    cf = top.sub("floor")
    if cf is None:
        return None
    elasticity = cf.number("elasticity", 1.0, lo=0.0, hi=1.0, unit="restitution")
    friction = cf.number("friction", 0.0, lo=0.0, unit="Coulomb coefficient")
    if dims == 1 and friction > 0:
        cf.fail("floor.friction", friction, "must be 0 in a 1D scene (no sideways motion)")
    cf.done()
    return Floor(elasticity, friction)


def _check_placement(A: Particle, B: Particle, dims: int, floor: Floor | None,
                     source: str) -> None:
    """Both particles above the floor, and A above B in 1D."""
    if floor is not None:
        for p in (A, B):
            if p.height < 0:
                raise SceneError(
                    f"{_printable(source)}: "
                    f"bodies.{p.name}.height = {_show(p.height)}: must be >= 0 "
                    "(the particle would start below the floor)"
                )
    if dims == 1 and A.height < B.height:
        raise SceneError(
            f"{_printable(source)}: "
            f"bodies.A.height = {_show(A.height)}: must be >= bodies.B.height = "
            f"{_show(B.height)} (A is the top particle in 1D)"
        )


def _check_rod(A: Particle, B: Particle, rigid: Rigid | None, source: str) -> None:
    """A rod as long as A is from B."""
    if rigid is not None:
        dist = math.hypot(A.x - B.x, A.height - B.height)
        if abs(dist - rigid.length) > 1e-9 * max(1.0, rigid.length):
            raise SceneError(
                f"{_printable(source)}: "
                f"rigid.length = {_show(rigid.length)}: must equal the distance "
                f"from B to A ({dist:.6g} m)"
            )


def _gravity(top: _Checker) -> float:
    """[gravity]: g (m/s^2, downward); 0 without the table."""
    cg = top.sub("gravity")
    if cg is None:
        return 0.0
    g = cg.number("g", lo=0.0, unit="m/s^2, downward")
    cg.done()
    return g


def _run(top: _Checker, source: str) -> RunSettings:
    """[run]: t_end and dt (s), solver, every, unstable_energy, inaccurate_energy."""
    crun = top.sub("run")
    if crun is None:
        raise SceneError(f"{_printable(source)}: [run] is missing: needs t_end and dt (s)")
    t_end = crun.number("t_end", lo=0.0, lo_open=True, unit="s")
    dt = crun.number("dt", lo=0.0, lo_open=True, unit="s")
    if dt > t_end:
        crun.fail("run.dt", dt, f"must be > 0 and <= run.t_end = {t_end:g} (s)")
    # Which names exist is the solvers' registry's to say (dumbbell.solvers.scene_solver).
    solver = crun.string("solver", "euler-cromer")
    every = crun.integer("every", 1, lo=1)
    unstable = crun.number(
        "unstable_energy", DEFAULT_UNSTABLE_ENERGY, lo=0.0, lo_open=True,
        unit="relative energy error that makes a run unstable",
    )
    inaccurate = crun.number(
        "inaccurate_energy", DEFAULT_INACCURATE_ENERGY, lo=0.0, lo_open=True,
        unit="relative energy error past which a stable run is inaccurate",
    )
    crun.done()
    return RunSettings(t_end, dt, solver, every, unstable, inaccurate)


def _outputs(top: _Checker, dims: int, has_floor: bool, has_rigid: bool, t_end: float
             ) -> OutputSettings:
    """[outputs]: figures (names), csv, and [outputs.gif] (fps, size, strip, t_end in s)."""
    co = top.sub("outputs")
    if co is None:
        return OutputSettings((), False, None)
    figures: tuple[str, ...] = ()
    co.used.add("figures")
    if co.has("figures"):
        value = co.table["figures"]
        if not isinstance(value, list) or any(v not in FIGURE_NAMES for v in value):
            co.fail("outputs.figures", value, "must be a list of " + ", ".join(FIGURE_NAMES))
        twice = next((v for i, v in enumerate(value) if v in value[:i]), None) \
            if len(set(value)) < len(value) else None
        if twice is not None:
            co.fail("outputs.figures", value, f"names '{twice}' more than once: each figure "
                    "is one file, list it once")
        if "rotation" in value and dims != 2:
            co.fail("outputs.figures", value, "'rotation' needs a 2D scene (dimensions = 2)")
        if "contact" in value and (dims != 2 or not has_floor):
            co.fail("outputs.figures", value, "'contact' needs a 2D scene with a [floor]")
        if "topple" in value and not has_rigid:
            co.fail("outputs.figures", value, "'topple' needs a rigid 2D dumbbell ([rigid])")
        figures = tuple(value)
    csv = bool(co.boolean("csv", False))
    gif = None
    cgif = co.sub("gif")
    if cgif is not None:
        gif = GifSettings(
            fps=cgif.integer("fps", GifSettings.fps, lo=1, hi=50),
            size=cgif.string("size", GifSettings.size),
            strip=bool(cgif.boolean("strip", GifSettings.strip)),
            t_end=cgif.number("t_end", t_end, lo=0.0, lo_open=True, unit="s"),
        )
        if pixel_size(gif.size) is None:
            cgif.fail("outputs.gif.size", gif.size, "must be WIDTHxHEIGHT in pixels, "
                      "each between 64 and 4096")
        cgif.done()
    co.done()
    return OutputSettings(figures, csv, gif)


def _pymunk(top: _Checker) -> tuple[Any, bool]:
    """[pymunk]: the engine's settings, as :class:`~.pymunk_settings.PymunkSettings` reads them, and
    the table's ``spin`` key, which says whether the particles are spinning discs
    (:attr:`System.discs`)."""
    owner = PymunkSettings
    cp = top.sub("pymunk")
    if cp is None:
        return owner._read(None), False
    settings = owner._read(cp)
    discs = bool(cp.boolean("spin", False))
    cp.done()
    return settings, discs


def parse_size(text: str) -> tuple[int, int]:
    """Parse 'WIDTHxHEIGHT' (pixels); raises UsageError (a ValueError) with the allowed form."""
    size = pixel_size(text)
    if size is None:
        raise UsageError(f"text = {_show(text)}: {SIZE_RULE}", param="text")
    return size


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file (TOML) of at most :data:`MAX_SCENE_BYTES` bytes.

    Parameters
    ----------
    path : str or pathlib.Path
        The scene file (docs/scenes.md lists its keys; the shipped ones are in
        :func:`scenes_dir`).

    Returns
    -------
    Scene
        The validated, frozen scene; ``scene.source`` is ``path``.

    Raises
    ------
    SceneError
        Any problem, in one line naming the file, the key and what is allowed; also when
        ``path`` is not a regular file.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> scene.title
    'Bouncing dumbbell, textbook section 13.5.1'
    >>> dumbbell.load_scene("nowhere.toml")
    Traceback (most recent call last):
    ...
    dumbbell.errors.SceneError: nowhere.toml: no such scene file
    """
    if not isinstance(path, str | os.PathLike) or str(path) == "":
        raise SceneError(f"path = {_show(path)}: must be the path of a scene file (str or "
                         "pathlib.Path)")
    return load_scene_file(Path(path), str(path))


def load_scene_file(path: Path, source: str) -> Scene:
    """:func:`load_scene` of the file ``path``, named ``source`` in messages and outputs
    (the showcase names a packaged scene ``scenes/NAME.toml``, not by its place in the
    installation). Reads at most :data:`MAX_SCENE_BYTES` + 1 bytes of it, whatever it is."""
    try:
        data = _read_scene_file(path, source)
    except FileNotFoundError:
        raise SceneError(f"{_printable(source)}: no such scene file") from None
    except IsADirectoryError:
        raise SceneError(f"{_printable(source)}: is a directory, not a scene file") from None
    except OSError as exc:
        raise SceneError(f"{_printable(source)}: cannot read: {exc.strerror or exc}") from None
    return load_scene_bytes(data, source)


def load_scene_bytes(data: bytes, source: str) -> Scene:
    """Validate a scene given as the bytes of a TOML document (at most
    :data:`MAX_SCENE_BYTES`), read from ``source`` (which names it in messages and outputs,
    as a file's path does). Raises :class:`SceneError` on any problem."""
    if not isinstance(source, str):
        raise SceneError(f"source = {_show(source)}: must be a str naming the scene")
    if not isinstance(data, bytes | bytearray):
        raise SceneError(f"{_printable(source)}: data = {_show(data)}: must be the bytes of a TOML "
                         "document")
    if len(data) > MAX_SCENE_BYTES:
        raise SceneError(f"{_printable(source)}: "
                         f"more than {MAX_SCENE_BYTES:,} bytes; a scene may be at "
                         "most 1 MB")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SceneError(f"{_printable(source)}: not UTF-8 text; a scene is a TOML file") from None
    try:
        data = _toml(text)
    except ValueError as exc:  # TOMLDecodeError
        message = " ".join(str(exc).split())[:200]
        raise SceneError(f"{_printable(source)}: not valid TOML: {message}") from None
    except RecursionError:
        raise SceneError(f"{_printable(source)}: not valid TOML: nested too deeply") from None
    return scene_from_dict(data, source=source)


def packaged_scene(name: str = "textbook-1d") -> Path:
    """Path of a scene shipped with the package (wheel) or found in the source checkout."""
    if not isinstance(name, str) or not name or Path(name).name != name:
        raise UsageError(f"name = {_show(name)}: must be the name of a shipped scene (a file "
                         "name without .toml)", param="name")
    package = Path(__file__).resolve().parent.parent  # src/dumbbell, or dumbbell in a wheel
    for folder in (package / "scenes", package.parent.parent / "scenes"):
        candidate = folder / f"{name}.toml"
        if candidate.is_file():
            return candidate
    raise SceneError(f"name = {name!r}: no packaged scene {name}.toml (looked in the package "
                     "and scenes/)")


def scenes_dir() -> Path:
    """The folder of shipped scenes (package data in a wheel, ``scenes/`` in a checkout).

    Returns
    -------
    pathlib.Path
        The folder holding ``textbook-1d.toml`` and the other shipped scenes.

    Examples
    --------
    >>> from dumbbell.model.scene import scenes_dir
    >>> sorted(p.name for p in scenes_dir().glob("*.toml"))[:3]
    ['friction-2d.toml', 'rigid-2d.toml', 'textbook-1d.toml']
    """
    return packaged_scene("textbook-1d").parent
