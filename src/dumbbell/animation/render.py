"""GIF animations of a :class:`Trajectory`: frame sampling and the GIF file.

>>> render_gif(traj, "renders/textbook-1d.gif", fps=25, size="640x360")   # doctest: +SKIP

Frames are taken at times k/fps (k = 0, 1, ...; 10 s at 25 fps is 250 frames) from the
trajectory sample nearest to each frame time: no interpolation, so no energy is made up across
an impact. ``dumbbell render`` chooses the sampling so that samples fall exactly on frame
times (see :func:`sample_every`).

GIF facts: delays are stored in 10 ms units. When 100/fps is a whole number (fps 1, 2, 4, 5,
10, 20, 25, 50) every frame lasts exactly 1000/fps ms. Otherwise delays of the two nearest
whole units alternate so that frame k still starts at round(k*100/fps) units: the animation
keeps real time to within 5 ms (30 fps: 30, 40, 30, 30, 40, ... ms). fps above 50 is refused
(browsers show delays of 10 ms or less as 100 ms). The GIF loops forever.

The file is written by :mod:`dumbbell.animation.gif`, not by Pillow's multi-frame writer: one
global palette, and each frame after the first holds only the rectangle that changed, with
unchanged pixels in it marked transparent (disposal 'leave in place'); Pillow's C encoder
compresses each rectangle (LZW). Drawing and encoding take about the same time per frame.
"""

from __future__ import annotations

import contextlib
import io
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self, overload

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model.scene import GifSettings
from ..model.trajectory import Trajectory
from .timing import _delays, check_fps, check_size, delays_cs  # noqa: F401 - delays_cs re-exported

if TYPE_CHECKING:
    from .frames import Frames

__all__ = ["Gif", "render_gif"]

#: Most frames an animation may have unless told otherwise (``max_frames``, ``--max-frames``):
#: 10 minutes at 25 fps, about a minute of drawing per 1,000 frames on one core.
MAX_FRAMES = 15_000
#: Samples per second the strip of the energy time series needs: it shows 1 s on ~390 px
#: (about one sample per pixel column), and the textbook spring's 20 Hz energy oscillations
#: keep their peaks to 1 % with 25 samples per oscillation.
STRIP_RATE = 500.0
#: Most samples kept for the strip over the whole animation (memory of very long runs).
STRIP_SAMPLES = 200_000


def frame_count(t_end: float, fps: int) -> int:
    """Frames of an animation of ``t_end`` s at ``fps``: times 0, 1/fps, ... below t_end."""
    from ..model import args

    return _frame_count(args.real(t_end, "t_end", "s"), check_fps(fps))


def _frame_count(t_end: float, fps: int) -> int:
    """:func:`frame_count` of values checked already."""
    if not t_end * fps <= 1e15:
        raise UsageError(f"t_end = {t_end:g} s at {fps} fps: more than 1e15 frames", param="t_end")
    return max(1, math.ceil(t_end * fps - 1e-9))


def check_frames(t_end: float, fps: int, max_frames: int, where: str = "t_end") -> int:
    """The frame count of ``t_end`` s at ``fps``, or a UsageError when it passes
    ``max_frames``; compared before multiplying, so a huge ``t_end`` cannot overflow."""
    from ..model import args

    where = args.text(where, "where", "the argument's name for the message (str)")
    return _check_frames(args.real(t_end, "t_end", "s"), check_fps(fps),
                         args.whole(max_frames, "max_frames", "frames"), where)


def _check_frames(t_end: float, fps: int, max_frames: int, where: str = "t_end") -> int:
    """:func:`check_frames` of values checked already (a scene's GIF settings, say)."""
    if t_end * fps <= max_frames + 1:
        n = _frame_count(t_end, fps)
        if n <= max_frames:
            return n
        count = counted(n, "frame", grouped=True)
    else:
        count = (f"{math.ceil(t_end * fps):,} frames" if math.isfinite(t_end * fps)
                 else "more than 1e308 frames")
    raise UsageError(f"{where} = {t_end:g} s at {fps} fps is {count}, past the budget of "
                     f"{max_frames:,}", fixes=("shorten the animation ({t_end})", "lower {fps}",
                                               "raise the budget ({max_frames})"))





#: Longest frame interval, in steps, whose divisors :func:`sample_every` searches (dt down to
#: 2 ns at 50 fps); past it a search would take too long and the samples are too dense anyway.
MAX_DIVISOR_SEARCH = 10**7


def sample_every(dt: float, fps: int, t_end: float, every: int | None = None) -> int:
    """Steps between kept samples so that samples fall on frame times when 1/fps is a whole
    number of steps ``dt`` (s), about :data:`STRIP_RATE` samples per second for the strip and
    at most about :data:`STRIP_SAMPLES` over ``t_end`` (s). Never fewer than half the steps
    that target asks for, so a render keeps at most 2 * STRIP_SAMPLES + 1 samples.

    ``every``, the scene's own ``run.every``, is kept when it does all that at least as well
    (samples as dense or denser, on the frame times, within the bound): then ``dumbbell
    render`` draws from the same samples as ``dumbbell run``, and the two GIFs are the same
    bytes."""
    from ..model import args

    return _sample_every(args.real(dt, "dt", "s"), check_fps(fps), args.real(t_end, "t_end", "s"),
                         None if every is None else args.whole(every, "every", "steps"))


def _sample_every(dt: float, fps: int, t_end: float, every: int | None = None) -> int:
    """:func:`sample_every` of values checked already."""
    steps = max(1.0, t_end / dt)  # inf only past the step cap, which a run checks first
    # At most the run's steps, so that a subnormal dt cannot make it overflow.
    target = min(steps, max(1.0, 1.0 / (dt * STRIP_RATE), t_end / dt / STRIP_SAMPLES))
    frame_steps = 1.0 / (fps * dt)
    if every is not None and every <= target and steps / every <= 2 * STRIP_SAMPLES:
        whole = abs(frame_steps - round(frame_steps)) <= 1e-9 * frame_steps
        if not whole or round(frame_steps) % every == 0:
            return every
    if not (frame_steps <= MAX_DIVISOR_SEARCH and math.isfinite(target)):
        return math.floor(target) if math.isfinite(target) else 1
    per_frame = max(1, round(frame_steps))
    divisors = [d for d in range(1, math.isqrt(per_frame) + 1) if per_frame % d == 0]
    divisors += [per_frame // d for d in divisors]
    best = max(d for d in divisors if d <= target)  # 1 always fits
    if 2 * best < target:
        # No divisor of the frame interval comes near the target (23 fps at dt = 1e-5 s:
        # 4348 steps, best divisor 4 of a target of 200): keeping every 4th step would keep
        # 50 times the samples needed. Frames then take the nearest sample instead, at most
        # half a sample spacing (1 ms; t_end / STRIP_SAMPLES / 2 for long runs) away.
        return math.floor(target)
    return best


def frames_of(traj: Trajectory, fps: int, t_end: float) -> Frames:
    """The frames of ``traj`` up to ``t_end`` (s): nearest samples at times k/fps."""
    from ..model import args

    return _frames_of(args.trajectory(traj), check_fps(fps), args.real(t_end, "t_end", "s"))


def _frames_of(traj: Trajectory, fps: int, t_end: float) -> Frames:
    """:func:`frames_of` of values checked already."""
    from .frames import Frames

    t = traj.t
    if len(t) == 0:
        raise UsageError(f"{traj.scene.source}: the trajectory has no samples to render")
    half = float(t[1] - t[0]) / 2 if len(t) > 1 else 0.0
    end = min(t_end, float(t[-1]) + half + 1e-12)
    ft = np.arange(_frame_count(end, fps)) / fps
    ft = ft[ft <= float(t[-1]) + half + 1e-12]
    i = np.clip(np.searchsorted(t, ft), 1, max(1, len(t) - 1))
    idx = np.where(np.abs(t[i - 1] - ft) <= np.abs(t[np.minimum(i, len(t) - 1)] - ft), i - 1,
                   np.minimum(i, len(t) - 1))
    if traj.scene.system.dimensions == 1:
        zero = np.zeros(len(t))
        A, B = np.column_stack([zero, traj["xA"]]), np.column_stack([zero, traj["xB"]])
    else:
        A = np.column_stack([traj["xA"], traj["yA"]])
        B = np.column_stack([traj["xB"], traj["yB"]])
    energy = traj.energy
    # Least and largest value of each term from the previous frame's sample to this one's.
    lo = {k: since_previous(v, idx, np.minimum) for k, v in energy.items()}
    hi = {k: since_previous(v, idx, np.maximum) for k, v in energy.items()}
    # The animation lasts len(ft)/fps s; the strip shows the samples of that window.
    window = min(len(ft) / fps, float(t[-1]))
    keep = t <= window + 1e-12
    return Frames(
        t=ft, A=A[idx], B=B[idx], energy={k: v[idx] for k, v in energy.items()}, lo=lo, hi=hi,
        series_t=t[keep], series={k: v[keep] for k, v in energy.items()},
        impacts=tuple(e.t for e in traj.events), t_end=max(window, 1e-9),
        L_cm=traj["L_cm"][idx] if traj.scene.system.dimensions == 2 else None,
        contacts=tuple((c.body, c.t_start, c.t_end) for c in traj.contacts),
    )


def since_previous(values: np.ndarray, idx: np.ndarray, ufunc: np.ufunc) -> np.ndarray:
    """For each frame k, ``ufunc`` (np.minimum or np.maximum) over the samples from frame
    k-1's index to frame k's, both included (frame 0: its own sample); ``idx`` non-decreasing."""
    v = values[: idx[-1] + 1]
    segments = ufunc.reduceat(v, idx)   # over idx[j] .. idx[j+1] - 1
    out = v[idx].copy()
    out[1:] = ufunc(segments[:-1], v[idx[1:]])
    return out


class Gif(bytes):
    """The bytes of a GIF file that shows itself in a notebook: ``_repr_html_`` embeds the
    animation, ``_repr_png_`` gives its first frame. It is ``bytes`` in every other way.

    Parameters
    ----------
    data : bytes-like, default b""
        The GIF file's bytes.

    Raises
    ------
    UsageError
        Data that is not bytes-like.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> traj = dumbbell.simulate(scenes_dir() / "tilted-2d.toml", t_end=0.5)
    >>> gif = dumbbell.render_gif(traj, fps=10, size="320x180", quiet=True)
    >>> gif[:6], type(gif).__name__
    (b'GIF89a', 'Gif')
    >>> dumbbell.Gif(gif.data) == gif, gif.save("tilted.gif").name
    (True, 'tilted.gif')
    """

    def __new__(cls, data: bytes | bytearray | memoryview = b"") -> Self:
        if not isinstance(data, bytes | bytearray | memoryview):
            from ..model import args

            raise UsageError(f"data = {args.show(data)}: must be the GIF's bytes", param="data")
        return super().__new__(cls, data)

    @property
    def data(self) -> bytes:
        """The GIF file's bytes as plain ``bytes``."""
        return bytes(self)

    def __repr__(self) -> str:
        return f"<Gif: {len(self)} bytes>"

    def _repr_html_(self) -> str:
        import base64

        return f'<img src="data:image/gif;base64,{base64.b64encode(self).decode()}"/>'

    def _repr_png_(self) -> bytes:
        from PIL import Image

        with Image.open(io.BytesIO(self)) as image:
            out = io.BytesIO()
            image.convert("RGB").save(out, format="PNG")
        return out.getvalue()

    def save(self, path: str | Path) -> Path:
        """Write the GIF to a file, whole or not at all: a stop signal or a full disk leaves
        no partial file behind.

        Parameters
        ----------
        path : str or pathlib.Path
            The GIF file (``.gif`` is usual), replaced only once the whole GIF is written.

        Returns
        -------
        written : pathlib.Path
            ``path``, as a ``Path``.

        Raises
        ------
        UsageError
            A folder, or a path that cannot be written, said in one line.
        """
        from ..files import writable_path
        from .writer import binary_output

        path = writable_path(path)
        with binary_output(path) as fh:
            fh.write(self)
        return path


@overload
def render_gif(traj: Trajectory, path: None = None, **options: Any) -> Gif: ...
@overload
def render_gif(traj: Trajectory, path: str | Path, **options: Any) -> Path: ...


def render_gif(
    traj: Trajectory,
    path: str | Path | None = None,
    *,
    quiet: bool = False,
    fps: int = GifSettings.fps,
    size: str | tuple[int, int] = GifSettings.size,
    strip: bool = GifSettings.strip,
    t_end: float | None = None,
    timing: dict[str, float] | None = None,
    max_frames: int = MAX_FRAMES,
) -> Path | Gif:
    """An animated GIF of ``traj``: written to ``path`` (atomically) and the path returned,
    or with no path its bytes returned as a :class:`Gif`, which a notebook shows inline.

    Parameters
    ----------
    traj : Trajectory
        The run.
    path : str or pathlib.Path or None, default None
        The GIF file; None: return the bytes.
    quiet : bool, default False
        No progress bar.
    fps : int, default 25
        Frames per second (1..50).
    size : str or tuple of int, default "640x360"
        'WxH' or (W, H), in px.
    strip : bool, default True
        Add the energy time series with a cursor below the picture.
    t_end : float or None, default None
        End the animation early (s; None: the trajectory's end).
    timing : dict or None, default None
        When given, receives the seconds spent drawing and encoding.
    max_frames : int, default 15000
        More frames than this are refused before any is drawn.

    Returns
    -------
    pathlib.Path or Gif
        The file written, or the GIF's bytes.

    Raises
    ------
    UsageError
        An argument that is not allowed, or a path that cannot be written.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> traj = dumbbell.simulate(scenes_dir() / "textbook-1d.toml", solver="exact", t_end=1.0)
    >>> dumbbell.render_gif(traj, "textbook.gif", fps=10, size=(320, 180), quiet=True).name
    'textbook.gif'
    >>> dumbbell.render_gif(traj, fps=100)
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: fps = 100: ...
    """
    from ..model import args

    if not isinstance(traj, Trajectory):
        raise UsageError(f"traj = {args.show(traj)}: must be a Trajectory (from simulate)",
                         param="traj")
    if path is not None:
        from ..files import writable_path

        path = writable_path(path)  # before the work: a folder, /proc, 'newdir/', ...
    quiet = args.flag(quiet, "quiet")
    fps = check_fps(fps)
    width, height = check_size(size)
    strip = args.flag(strip, "strip")
    if timing is not None:
        args.instance(timing, "timing", dict, "a dict (it receives the seconds spent) or None")
    max_frames = args.whole(max_frames, "max_frames", "frames")
    t_end = float(traj.t[-1]) if t_end is None and len(traj.t) else t_end
    t_end = args.real(t_end, "t_end", "s")
    _check_frames(t_end, fps, max_frames)
    gif = GifSettings(t_end, fps, f"{width}x{height}", strip)
    return _render_gif(traj, path, gif, quiet, timing)


def _render_gif(traj: Trajectory, path: Path | None, gif: GifSettings, quiet: bool,
                timing: dict[str, float] | None) -> Path | Gif:
    """:func:`render_gif` of values checked already (its frame count too): the scene's GIF
    settings on the way from ``dumbbell run``, checked when the scene was read."""
    from .. import progress
    from ..model.sizes import pixel_size
    from .picture import describe
    from .world import scene_painter
    from .writer import binary_output

    (width, height), fps, strip, t_end = pixel_size(gif.size), gif.fps, gif.strip, gif.t_end
    t0 = time.perf_counter()
    frames = _frames_of(traj, fps, t_end)
    painter = scene_painter(describe(traj.scene, (frames,), (width, height), strip))
    stats = {"setup": time.perf_counter() - t0, "draw": 0.0, "encode": 0.0, "frames": 0}
    label = f"render {Path(path).name}" if path is not None else "render GIF"
    with contextlib.ExitStack() as stack:
        if path is None:
            fh = stack.enter_context(io.BytesIO())
        else:
            fh = stack.enter_context(binary_output(path))
        pbar = stack.enter_context(progress.bar(len(frames.t), label, "frame", quiet))
        stats["draw"], stats["encode"] = painter.write_gif(fh, fps, on_frame=lambda: pbar.update(1))
        result = Gif(fh.getvalue()) if path is None else Path(path)
    stats["frames"] = len(frames.t)
    if timing is not None:
        timing.update(stats)
    return result
