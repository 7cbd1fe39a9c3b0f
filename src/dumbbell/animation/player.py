"""The interactive player: a run (or runs side by side) as one self-contained HTML page.

>>> dumbbell.player(traj).save("run.html")                       # doctest: +SKIP
>>> dumbbell.player(dumbbell.compare("scenes/tilted-2d.toml"))    # doctest: +SKIP

The page draws in a canvas what the GIF shows, from the same description
(:class:`~.picture.Picture`, given to the page as data with the pixel factors the GIF is drawn
with), so the two cannot drift apart: the world, the energy bars with their values, the strip
with its cursor, the time. It plays, pauses, steps frame by frame, scrubs, changes speed,
loops and jumps from impact to impact; runs side by side share one clock (the others drawn
as ghosts in the world; the bars show the run chosen, the table under the picture every
run's values).

The data are the run's own samples (all of them, up to :data:`MAX_SAMPLES` per run: finer
than the GIF's frames; the frames' times are among them when the run was sampled for its
GIF), stored little-endian and base64-encoded: times as float64, positions as float32, and
energies as float32 chosen so that each prints with the bars' decimals exactly as the
float64 value does (:func:`exact_float32`): the bars read the same numbers as the CSV. The
page needs no network: everything is in the one file, the script included.

A recorded pymunk space gets the same page (``spaces.Recorder(space, "run.html")``), drawn
from the recording painter's own numbers: :mod:`.space_player`.

The JSON is embedded in a ``<script type="application/json">`` with ``<``, ``>``, ``&`` and
every non-ASCII character escaped (so no text of a title or a name can end the script or
be read as markup), and the page puts every text into the document as text (``textContent``)
or draws it on the canvas, never as markup.
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model.trajectory import Trajectory
from .bars import fixed

__all__ = ["Player", "player"]

#: Most samples the page keeps of one run (the rest thinned evenly, keeping the frames'
#: times when they are samples): 40,001 is 10 s at 0.25 ms.
MAX_SAMPLES = 40_001
#: Height (px) of the page's inline frame in a notebook beyond the picture's own.
NOTEBOOK_EXTRA = 230


class Player:
    """An interactive player page (HTML text, self-contained): ``save(path)`` writes it,
    a notebook shows it inline (``_repr_html_``: the page in a frame of its own). Made by
    :func:`player`.

    Parameters
    ----------
    html_text : str
        The page.
    size : tuple of int, default (640, 360)
        The picture's size (px), for the frame a notebook shows it in.

    Raises
    ------
    UsageError
        A page that is not a str; a size not allowed.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> page = dumbbell.player(dumbbell.simulate(scenes_dir() / "textbook-1d.toml",
    ...                                          t_end=1.0), fps=10, size="320x180")
    >>> page.save("textbook.html").name
    'textbook.html'
    >>> page.html.startswith("<!DOCTYPE html>"), page.size
    (True, (320, 180))
    """

    def __init__(self, html_text: str, size: tuple[int, int] = (640, 360)) -> None:
        if not isinstance(html_text, str):
            from ..model import args

            raise UsageError(f"html_text = {args.show(html_text)}: must be the page (str)",
                             param="html_text")
        from .timing import check_size

        self.html = html_text
        self.size = check_size(size)

    def __repr__(self) -> str:
        return f"<Player: {len(self.html.encode()):,} bytes of HTML>"

    def _repr_html_(self) -> str:
        w, h = self.size
        return (f'<iframe srcdoc="{html.escape(self.html, quote=True)}" '
                f'style="width: 100%; max-width: {2 * w}px; aspect-ratio: {w} / '
                f'{h + NOTEBOOK_EXTRA}; border: 0" title="dumbbell player" '
                'sandbox="allow-scripts"></iframe>')

    def save(self, path: str | Path) -> Path:
        """Write the page to an HTML file, whole or not at all: it needs nothing else (no
        network, no other file) to play.

        Parameters
        ----------
        path : str or pathlib.Path
            The HTML file; a name ending in '/' is a folder, refused.

        Returns
        -------
        saved : pathlib.Path
            The page's file.

        Raises
        ------
        UsageError
            A path that cannot be written, in one line naming why.
        """
        from ..files import atomic_output, writable_path

        path = writable_path(path, "path")  # as spelt: "newdir/" is a folder, not a file
        with atomic_output(path) as tmp:
            Path(tmp).write_text(self.html, encoding="utf-8")
        return path


# --- the data --------------------------------------------------------------------------------


def b64_array(values: np.ndarray, dtype: str) -> dict[str, Any]:
    """An array as base64 of its little-endian ``dtype`` ('f4' or 'f8') bytes."""
    data = np.ascontiguousarray(values, dtype=np.dtype(dtype).newbyteorder("<"))
    return {"dtype": dtype, "n": int(data.size), "data": base64.b64encode(data.tobytes()).decode()}


def shown_digits(values: np.ndarray, decimals: int) -> np.ndarray:
    """The integers whose digits :func:`~.bars.fixed` prints for ``values`` with
    ``decimals`` (its text without the point: -0.01 -> -1), as float64; nan where a value is
    not finite. numpy's floor(v 10^d + 0.5) is Python's rounding but within a rounding error
    of a half, where the text itself decides."""
    v = np.asarray(values, dtype=float)
    scale = 10.0 ** decimals
    with np.errstate(invalid="ignore", over="ignore"):
        x = v * scale
        out = np.floor(x + 0.5)
        near = np.abs(x - np.floor(x) - 0.5) <= 1e-6 * np.maximum(1.0, np.abs(x))
    for i in np.flatnonzero(near & np.isfinite(x)).tolist():
        out[i] = float(int(fixed(float(v[i]), decimals).replace(".", "")))
    out[~np.isfinite(x)] = math.nan
    return out


def exact_float32(values: np.ndarray, decimals: int) -> tuple[np.ndarray, bool]:
    """``values`` (float64) as float32 whose text in the page, floor(v 10^d + 0.5) with the
    point put back (the page's rule, on the float64 the float32 widens to), is Python's text
    of the float64 value with ``decimals``: a float32 that would round the other way is
    moved by its last bit towards the float64. Returns the array and whether every finite
    value now prints alike."""
    want = shown_digits(values, decimals)
    v32 = np.asarray(values, dtype=np.float32).copy()
    scale = 10.0 ** decimals
    ok = np.isfinite(want)
    for _ in range(8):
        with np.errstate(invalid="ignore", over="ignore"):
            got = np.floor(v32.astype(float) * scale + 0.5)
        bad = ok & (got != want)
        if not bad.any():
            return v32, True
        toward = np.where(got[bad] < want[bad], np.inf, -np.inf).astype(np.float32)
        v32[bad] = np.nextafter(v32[bad], toward)
    return v32, False


def energy_array(values: np.ndarray, decimals: int) -> dict[str, Any]:
    """An energy column: float32 that prints as the float64 does, else float64."""
    v32, same = exact_float32(values, decimals)
    return b64_array(v32, "f4") if same else b64_array(values, "f8")


@dataclass(frozen=True)
class Run:
    """What the page gets of one run: its ``label`` and verdict (``note``), sample times
    ``t`` (s), positions of A and B (m, (n, 2): x and height), the energy columns the bars
    show (J), L_cm (2D), impact times (s) and lasting contacts ((body, start s, end s))."""

    label: str
    note: str
    t: np.ndarray
    A: np.ndarray
    B: np.ndarray
    energy: Mapping[str, np.ndarray]
    L_cm: np.ndarray | None
    impacts: tuple[float, ...]
    contacts: tuple[tuple[str, float, float], ...] = field(default=())

    def document(self, decimals: int) -> dict[str, Any]:
        """The run as plain data, its arrays base64 (energies printed with ``decimals``)."""
        return {
            "label": self.label, "note": self.note, "t": b64_array(self.t, "f8"),
            "A": b64_array(self.A, "f4"), "B": b64_array(self.B, "f4"),
            "energy": {name: energy_array(v, decimals) for name, v in self.energy.items()},
            "L_cm": None if self.L_cm is None else energy_array(self.L_cm, 4),
            "impacts": [float(t) for t in self.impacts],
            "contacts": [[b, float(t0), float(t1)] for b, t0, t1 in self.contacts],
        }


def run_of(traj: Trajectory, names: Sequence[str], t_end: float, label: str,
           max_samples: int = MAX_SAMPLES, fps: int | None = None) -> Run:
    """The samples of ``traj`` up to ``t_end`` (s) that the page keeps: all of them, or
    evenly thinned to at most ``max_samples`` (every k-th, k a divisor of the samples per
    frame at ``fps`` when one is small enough, so frame times stay samples)."""
    t = traj.t
    keep = np.flatnonzero(t <= t_end + 1e-12)
    n = len(keep)
    if n > max_samples:
        stride = math.ceil(n / max_samples)
        if fps is not None and n > 1:
            per_frame = (1.0 / fps) / float(t[1] - t[0])
            whole = round(per_frame)
            if whole >= 1 and abs(per_frame - whole) < 1e-6 * per_frame:
                fits = [d for d in range(stride, whole + 1) if whole % d == 0]
                stride = fits[0] if fits else stride
        keep = keep[::stride]
    if traj.scene.system.dimensions == 1:
        zero = np.zeros(len(keep))
        A = np.column_stack([zero, traj["xA"][keep]])
        B = np.column_stack([zero, traj["xB"][keep]])
    else:
        A = np.column_stack([traj["xA"][keep], traj["yA"][keep]])
        B = np.column_stack([traj["xB"][keep], traj["yB"][keep]])
    energy = {name: np.asarray(traj[name][keep], dtype=float) for name in names}
    L_cm = traj["L_cm"][keep] if traj.scene.system.dimensions == 2 else None
    note = "" if traj.verdict.ok else str(traj.verdict)
    return Run(label, note, t[keep], A, B, energy, L_cm,
               tuple(e.t for e in traj.events if e.t <= t_end + 1e-12),
               tuple((c.body, c.t_start, c.t_end) for c in traj.contacts if c.t_start <= t_end))


# --- the page ----------------------------------------------------------------------------------


def _asset(name: str) -> str:
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def json_for_script(data: Any) -> str:
    """``data`` as JSON safe inside an HTML ``<script>``: ASCII only (U+2028 and U+2029
    escaped too), and ``<``, ``>``, ``&`` as \\u escapes, so no string in it can close the
    script or open a comment."""
    text = json.dumps(data, ensure_ascii=True, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _finite(data: Any) -> Any:
    """``data`` with every float that is not finite as None (JSON has no nan)."""
    if isinstance(data, float):
        return data if math.isfinite(data) else None
    if isinstance(data, dict):
        return {k: _finite(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [_finite(v) for v in data]
    return data


def page(document: Mapping[str, Any], title: str) -> str:
    """The player page: the template with its style and script, ``document`` (plain data:
    the picture, the runs, the frame rate) embedded as JSON, and ``title`` as the page's
    title (escaped)."""
    template = _asset("player.html")
    parts = {"TITLE": html.escape(title, quote=True), "STYLE": _asset("player.css"),
             "SCRIPT": _asset("player.js"), "DATA": json_for_script(_finite(dict(document)))}
    out = template
    for key in ("STYLE", "SCRIPT", "TITLE"):
        out = out.replace("{{" + key + "}}", parts[key])
    # The data last: no placeholder inside it is ever replaced.
    head, tail = out.split("{{DATA}}")
    return head + parts["DATA"] + tail


def _runs(source: Any, labels: Sequence[str] | None) -> tuple[list[Trajectory], list[str]]:
    """The trajectories of ``source`` (a Trajectory, a Comparison or a sequence of
    trajectories of one scene) and their labels."""
    from ..model import args

    if isinstance(source, Trajectory):
        trajs, names = [source], [source.solver]
    elif hasattr(source, "truth") and hasattr(source, "rows") and hasattr(source, "scene"):
        trajs = [source.truth, *(row.traj for row in source.rows)]
        names = [f"{source.truth.solver} (truth)", *(row.label for row in source.rows)]
    elif isinstance(source, Sequence) and not isinstance(source, str | bytes) and source \
            and all(isinstance(x, Trajectory) for x in source):
        trajs, names = list(source), [x.solver for x in source]
    else:
        raise UsageError(f"source = {args.show(source)}: must be a Trajectory (from simulate), "
                         "a Comparison (from compare) or a list of trajectories of one scene",
                         param="source")
    scene = trajs[0].scene
    if any(x.scene.system != scene.system for x in trajs[1:]):
        raise UsageError("source: the trajectories are of different scenes; runs shown side "
                         "by side share one picture, so they must be of one scene",
                         param="source")
    if any(len(x.t) == 0 for x in trajs):
        raise UsageError(f"source: {scene.source}: a trajectory has no samples to play",
                         param="source")
    if labels is not None:
        if isinstance(labels, str) or not isinstance(labels, Sequence) \
                or len(labels) != len(trajs) or not all(isinstance(s, str) for s in labels):
            raise UsageError(f"labels = {args.show(labels)}: must be one str per run "
                             f"({len(trajs)})", param="labels")
        names = list(labels)
    # Two runs of one solver (two steps) are told apart by their step.
    if len(set(names)) < len(names):
        names = [f"{n} dt={x.dt:g} s" if names.count(n) > 1 else n
                 for n, x in zip(names, trajs, strict=True)]
    return trajs, names


def player(source: Any, *, fps: int | None = None, size: str | tuple[int, int] | None = None,
           strip: bool | None = None, t_end: float | None = None,
           labels: Sequence[str] | None = None, max_samples: int = MAX_SAMPLES) -> Player:
    """An interactive player of ``source``: a :class:`Trajectory` (from ``simulate``), a
    ``Comparison`` (from ``compare``: the truth and each run side by side on one clock) or a
    list of trajectories of one scene. ``fps`` is the frame rate that the frame steps and
    the GIF's frames follow, ``size`` the picture 'WxH' (px, scaled to the window), ``strip``
    the energy time series; by default the scene's ``[outputs.gif]`` settings, else 25 fps,
    640x360, strip on. ``t_end`` (s) ends it early (default: the longest run's end);
    ``labels`` name the runs (default: the solvers). At most ``max_samples`` samples of each
    run are kept (evenly thinned beyond).

    Parameters
    ----------
    source : Trajectory or Comparison or list of Trajectory
        What to play.
    fps : int or None, default None
        Frames per second.
    size : str or tuple of int or None, default None
        The picture, 'WxH' (px).
    strip : bool or None, default None
        Show the energy time series.
    t_end : float or None, default None
        End early (s).
    labels : sequence of str or None, default None
        The runs' names.
    max_samples : int, default 40001
        Samples kept of each run.

    Returns
    -------
    Player
        ``.save(path)`` writes the HTML file; a notebook shows it inline.

    Raises
    ------
    UsageError
        A source or an argument not allowed, named in one line.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> runs = [dumbbell.simulate(scenes_dir() / "textbook-1d.toml", solver=name, t_end=1.0,
    ...                           dt=1e-3) for name in ("exact", "verlet")]
    >>> dumbbell.player(runs, labels=["exact", "verlet"], fps=10).save("two.html").name
    'two.html'
    """
    from ..model import args
    from ..model.scene import GifSettings
    from .picture import describe
    from .render import frames_of
    from .timing import check_fps, check_size

    trajs, names = _runs(source, labels)
    scene = trajs[0].scene
    gif = scene.outputs.gif or GifSettings(scene.run.t_end)
    fps = check_fps(gif.fps if fps is None else fps)
    width, height = check_size(gif.size if size is None else size)
    strip = gif.strip if strip is None else args.flag(strip, "strip")
    end = max(float(x.t[-1]) for x in trajs)
    t_end = end if t_end is None else min(args.real(t_end, "t_end", "s"), end)
    if not t_end >= 0:
        raise UsageError(f"t_end = {t_end:g} s: must be at least 0", param="t_end")
    max_samples = args.whole(max_samples, "max_samples", "samples", lo=2)
    from .render import MAX_FRAMES, check_frames

    check_frames(max(t_end, 1.0 / fps), fps, MAX_FRAMES)
    frames = [frames_of(x, fps, t_end) for x in trajs]
    picture = describe(scene, frames, (width, height), strip, names)
    decimals = picture.bars.scale.decimals
    runs = [run_of(x, picture.names, fr.t_end, name, max_samples, fps).document(decimals)
            for x, fr, name in zip(trajs, frames, names, strict=True)]
    doc = {"kind": "scene", "fps": fps, "t_end": max(fr.t_end for fr in frames),
           "picture": picture.document(), "runs": runs,
           "units": {"energy": "J", "time": "s", "L_cm": "kg m²/s"}}
    return Player(page(doc, scene.title or scene.name), (width, height))

