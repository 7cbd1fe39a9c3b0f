"""What the recorder (:mod:`.recorder`) checks and reads when it is made, and how its note
names bodies: its arguments at the border (the path, the world box, the camera, the
potentials' reference), each refused with a UsageError naming it; which way y points in the
program's window; the bodies named in a line."""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import UsageError

__all__: list[str] = []

#: Potential terms, shown from a reference (their value at t0, or one you set).
POTENTIALS = ("U_g", "U_spring")

#: Libraries whose windows have y up (pyglet's, arcade's and kivy's origin is the
#: bottom-left corner); pygame's has y down.
Y_UP_WINDOWS = ("pyglet", "arcade", "kivy")


def window_y_up(space: Any) -> tuple[bool, str]:
    """Whether y points up in the window the program draws ``space`` in, and why: read from
    the window libraries the program has imported (``sys.modules``),
    ``pymunk.pygame_util.positive_y_is_up`` and the space's gravity (the rule: see
    :mod:`.recorder`'s docstring)."""
    import sys

    modules = sys.modules
    gy = float(space.gravity.y)
    gy = gy if math.isfinite(gy) else 0.0
    util = modules.get("pymunk.pygame_util")
    if util is not None and bool(getattr(util, "positive_y_is_up", False)):
        return True, "pymunk.pygame_util.positive_y_is_up is True"
    # (A name set to None in sys.modules is an import blocked, not a library imported.)
    pygame = modules.get("pygame") is not None
    up = [name for name in Y_UP_WINDOWS if modules.get(name) is not None]
    if pygame and not up:
        if gy < 0:
            return True, ("pygame is imported (its window has y down) and gravity points to "
                          "-y, so the program flips y itself (else its bodies would fall up); "
                          "give y_up=False if it does not")
        flag = "; pymunk.pygame_util.positive_y_is_up is False" if util is not None else ""
        return False, (f"pygame is imported (its window has y down{flag}); give y_up=True if "
                       "the program flips y itself")
    if up and not pygame:
        return True, f"{up[0]} is imported (its window has y up)"
    found = f"pygame and {up[0]} are both imported" if up else "no window library is imported"
    if gy != 0:
        return gy < 0, f"{found}; up is against gravity"
    return True, f"{found} and gravity has no vertical part"


def check_path(path: Any) -> Path:
    """``path`` as a Path the recording can be written to, else a UsageError naming it and
    what is wrong: checked before any capture, so a long run is not lost at the end."""
    from ..animation.writer import mp4_problem
    from ..files import check_writable, is_special
    from ..model import args

    shown = args.show(path) if isinstance(path, str | os.PathLike) else None
    if shown is not None and "\0" in str(path):
        raise UsageError(f"path = {shown}: a path cannot hold a NUL character", param="path")
    text = path
    path = args.path(path, "path")
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4", ".html", ".htm"):
        raise UsageError(f"path {args.show(str(path))}: must end in .gif, .mp4 or .html (the "
                         "interactive player)", param="path")
    try:
        # As spelt (a Path drops a final '/': 'a.gif/' names a folder, not a file).
        check_writable(text, "path")
    except UsageError as exc:
        from ..cli.app import clip  # its echo of the path, bounded

        raise UsageError(clip(exc.reason), param="path") from None
    if suffix == ".mp4" and (problem := mp4_problem()) is not None:
        raise UsageError(f"path {args.show(str(path))}: {problem}", param="path")
    if not is_special(path):
        # The one sure test of a folder (read-only file systems, /proc, folders only root
        # may write): make and remove a file in it, as the writer will.
        here = path.parent
        while not here.exists() and here != here.parent:
            here = here.parent
        try:
            fd, probe = tempfile.mkstemp(prefix=f".{path.name[:40]}.", suffix=".probe", dir=here)
        except OSError as exc:
            raise UsageError(f"path {args.show(str(path))}: cannot write in {here} "
                             f"({exc.strerror or exc})", param="path") from None
        os.close(fd)
        os.unlink(probe)
    return path


def check_world(world: Any, unit: str = "space units") -> tuple[float, float, float, float]:
    """``world`` = (left, right, bottom, top) as floats that can be drawn (in the length
    ``unit``), else a UsageError."""
    from ..animation.camera import SPAN_MAX, SPAN_MIN
    from ..model import args

    allowed = ("must be four finite numbers (left, right, bottom, top) in the space's length "
               "unit, right > left and bottom != top (bottom > top: y is down)")
    if type(world).__name__ == "ndarray":
        world = tuple(world.tolist()) if world.ndim == 1 else None
    if not isinstance(world, tuple | list) or len(world) != 4:
        raise UsageError(f"world = {args.show(world)}: {allowed}", param="world")
    x0, x1, y0, y1 = (args.real(v, "world", unit, positive=False) for v in world)
    if not (x1 > x0 and y1 != y0):
        raise UsageError(f"world = {args.show(world)}: {allowed}", param="world")
    for lo, hi in ((x0, x1), (min(y0, y1), max(y0, y1))):
        span = hi - lo
        if not (SPAN_MIN <= span <= SPAN_MAX and span >= 1e-9 * max(abs(lo), abs(hi))):
            raise UsageError(f"world = {args.show(world)}: each side must span between "
                             f"{SPAN_MIN:g} and {SPAN_MAX:g} {unit}, and at least 1e-9 of its "
                             "coordinates (else no pixel can be told from the next)",
                             param="world")
    return x0, x1, y0, y1


def check_camera(camera: Any, world: Any, space: Any) -> Any:
    """``camera`` checked: 'auto', 'all' or a moving pymunk.Body of ``space`` to follow;
    with a fixed ``world`` box, 'auto' only."""
    import pymunk

    from ..model import args

    if isinstance(camera, pymunk.Body):
        if camera.body_type == pymunk.Body.STATIC:
            raise UsageError("camera: a static body cannot be followed; give a moving "
                             "body, 'auto' or 'all'", param="camera")
        if camera.space is not space:
            raise UsageError("camera: the body to follow is not in the space recorded (add "
                             "it first, or follow one of the space's bodies)", param="camera")
    elif not (isinstance(camera, str) and camera in ("auto", "all")):
        raise UsageError(f"camera = {args.show(camera)}: must be 'auto', 'all' or a "
                         "pymunk.Body to follow", param="camera")
    if world is not None and camera != "auto":
        raise UsageError(f"camera = {args.show(camera)}: give world (a fixed box) or "
                         "camera, not both", param="camera")
    return camera


def check_reference(reference: Any, unit: str = "energy units") -> str | dict[str, float]:
    from ..model import args

    allowed = ("must be 'start' (potential energies from their values at t0), 'space' (as "
               "spaces.energy reports them) or a mapping of U_g and/or U_spring to the "
               "energies to measure them from")
    if isinstance(reference, str):
        if reference not in ("start", "space"):
            raise UsageError(f"reference = {args.show(reference)}: {allowed}", param="reference")
        return reference
    if not isinstance(reference, Mapping) or not reference or not set(reference) <= set(
            POTENTIALS):
        raise UsageError(f"reference = {args.show(reference)}: {allowed}", param="reference")
    return {k: args.real(v, "reference", unit, positive=False)
            for k, v in reference.items()}


def every_body(names: list[str]) -> str:
    """Every name of ``names``, bodies named by their place ("body 3") in order and runs of
    three or more consecutive ones as one range ("bodies 3-9"): the note names each body
    drawn larger than to scale, however many (a gas of 10,000 particles is "bodies 0-9999")."""
    import re

    places = sorted({int(m.group(1)) for n in names if (m := re.fullmatch(r"body (\d+)", n))})
    parts: list[str] = []
    start = 0
    for k in range(1, len(places) + 1):
        if k < len(places) and places[k] == places[k - 1] + 1:
            continue
        run = places[start:k]
        parts += ([f"bodies {run[0]}-{run[-1]}"] if len(run) >= 3 else
                  [f"body {i}" for i in run])
        start = k
    return ", ".join(parts + [n for n in names if not re.fullmatch(r"body \d+", n)])


def listed(names: list[str], most: int = 8) -> str:
    """``names`` joined by commas, the first ``most`` of them and how many more."""
    shown = ", ".join(names[:most])
    return shown if len(names) <= most else f"{shown} and {len(names) - most} more"
