"""The recorder on pymunk's own example programs: record a run, and measure its frames.

:func:`record` runs a corpus program (:mod:`tests.pymunk_corpus`) headless and records it
with :class:`dumbbell.spaces.Recorder`: frame 0 is the space as built, then one frame at the
first step at or past each 1/fps of simulated time, labelled with the time of that step. It
keeps copies of the space at the first and last frames.

The measurements read pixels, not the recorder's numbers: :func:`picture` draws a part of a
space (some bodies, one static shape) alone through the same view as the recording, so the
part's pixels can be found as the non-white ones; :func:`extent` and :func:`centre` read them.
Used by ``tests/test_spaces_recorder_corpus.py`` and ``benchmarks/spaces_recorder.py``.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from .pymunk_corpus import run_example

#: The examples issue 20 names (the corpus holds a few more).
NAMES = ("constraints", "newtons_cradle", "planet", "box2d_pyramid", "slide_and_pinjoint",
         "damped_rotary_spring_pointer", "spiderweb", "tank", "flipper",
         "contact_with_friction", "bouncing_balls", "box2d_vertical_stack")
#: The programs' units: pixels, an arbitrary mass unit, seconds.
UNITS = ("px", "kg", "s")


@dataclass
class Recorded:
    """A recorded run: the corpus run, the recorder, the GIF's path, copies of the space at
    the first and last frames, and the time spent recording (capturing and writing, s)."""

    run: Any
    rec: Any
    path: Path
    first: Any = None
    last: Any = None
    seconds: float = 0.0
    timing: dict[str, float] = field(default_factory=dict)


def record(name: str, seconds: float, path: str | Path, fps: int = 25, **options: Any
           ) -> Recorded:
    """Run corpus program ``name`` for ``seconds`` of simulated time and record it into
    ``path`` (``options`` go to the Recorder; units default to :data:`UNITS`)."""
    import time

    from dumbbell import spaces

    options.setdefault("units", UNITS)
    state: dict[str, Any] = {"t": 0.0, "next": 1, "spent": 0.0}

    def on_start(space: Any) -> None:
        t0 = time.perf_counter()
        state["rec"] = spaces.Recorder(space, path, fps=fps, **options)
        state["spent"] += time.perf_counter() - t0
        state["first"] = snapshot(space)

    def on_step(space: Any, dt: float) -> None:
        state["t"] += dt
        if state["t"] >= state["next"] / fps - 1e-9:
            t0 = time.perf_counter()
            state["rec"].capture(t=state["t"])
            state["spent"] += time.perf_counter() - t0
            state["next"] += 1

    dt = run_example(name, 1).dts[0]
    run = run_example(name, math.ceil(seconds / dt - 1e-9), on_start=on_start, on_step=on_step)
    rec = state["rec"]
    t0 = time.perf_counter()
    rec.write()
    spent = state["spent"] + time.perf_counter() - t0
    return Recorded(run, rec, Path(path), state["first"], snapshot(run.space), spent,
                    dict(rec.timing))


def snapshot(space: Any) -> Any:
    """A copy of every dynamic body and static shape of ``space`` as it is now (see
    :func:`part`), in the same order."""
    import pymunk

    bodies = [i for i, b in enumerate(space.bodies) if b.body_type == pymunk.Body.DYNAMIC]
    statics = [i for i, s in enumerate(space.shapes) if s.body.body_type == pymunk.Body.STATIC]
    return part(space, bodies, statics)


def frame(path: str | Path, k: int) -> np.ndarray:
    """Frame ``k`` of a GIF as RGB (height x width x 3); -1 is the last."""
    with Image.open(path) as im:
        im.seek(k if k >= 0 else im.n_frames + k)
        return np.asarray(im.convert("RGB"))


def part(space: Any, bodies: list[int] | None = None, statics: list[int] | None = None
         ) -> Any:
    """A new space holding copies of the dynamic bodies at ``bodies`` (indices into
    ``space.bodies``) with their shapes, and of the static shapes at ``statics`` (indices into
    ``space.shapes``): same positions, angles and geometry, nothing else (``Space.copy``
    pickles collision handlers' data, which some programs cannot)."""
    import pymunk

    out = pymunk.Space()
    out.gravity = space.gravity
    made: dict[int, Any] = {}

    def body_like(body: Any) -> Any:
        if body.body_type == pymunk.Body.STATIC and body is space.static_body:
            return out.static_body
        if id(body) not in made:
            new = pymunk.Body(body.mass, body.moment, body_type=body.body_type) \
                if body.body_type == pymunk.Body.DYNAMIC else pymunk.Body(body_type=body.body_type)
            new.position, new.angle = body.position, body.angle
            new.center_of_gravity = body.center_of_gravity
            made[id(body)] = new
            out.add(new)
        return made[id(body)]

    def shape_like(shape: Any, body: Any) -> Any:
        if isinstance(shape, pymunk.Circle):
            return pymunk.Circle(body, shape.radius, shape.offset)
        if isinstance(shape, pymunk.Segment):
            return pymunk.Segment(body, shape.a, shape.b, shape.radius)
        return pymunk.Poly(body, shape.get_vertices(), radius=shape.radius)

    all_bodies, all_shapes = list(space.bodies), list(space.shapes)
    for i in bodies or ():
        b = all_bodies[i]
        new = body_like(b)
        out.add(*(shape_like(s, new) for s in b.shapes))
    for i in statics or ():
        s = all_shapes[i]
        out.add(shape_like(s, body_like(s.body)))
    return out


def picture(space: Any, rec: Any, bodies: list[int] | None = None,
            statics: list[int] | None = None) -> np.ndarray:
    """The :func:`part` of ``space`` with the dynamic ``bodies`` and the static shapes
    ``statics``, drawn alone through ``rec``'s view, size and panel: True where the scene
    panel is not white (the time label's band left out)."""
    from dumbbell import spaces

    alone = part(space, bodies, statics)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "part.gif"
        with spaces.Recorder(alone, out, fps=rec.fps, energy=rec.energy, size=(rec.W, rec.H),
                             world=rec.view, units=rec.units) as one:
            one.capture()
        image = frame(out, 0)
    return scene_mask(image, rec)


def scene_mask(image: np.ndarray, rec: Any) -> np.ndarray:
    """True where the scene panel of a frame is not white, the time label's corner and the
    title's band left out (False elsewhere)."""
    u = min(rec.W / 640, rec.H / 360)
    mask = (image != 255).any(axis=2)
    width = round(0.56 * rec.W) if rec.energy else rec.W
    mask[:, width - 2:] = False
    mask[: round(26 * u), :] = False
    return mask


def extent(mask: np.ndarray) -> float:
    """The larger side (px) of the box of the True pixels (0 when there are none)."""
    rows, cols = np.nonzero(mask)
    if not len(rows):
        return 0.0
    return float(max(rows.max() - rows.min() + 1, cols.max() - cols.min() + 1))


def rows(mask: np.ndarray) -> np.ndarray:
    """The row (px, from the top) of every True pixel."""
    return np.nonzero(mask)[0]


def dynamic(space: Any) -> list[int]:
    """Indices into ``space.bodies`` of its dynamic bodies that have shapes."""
    import pymunk

    return [i for i, b in enumerate(space.bodies)
            if b.body_type == pymunk.Body.DYNAMIC and b.shapes]


def body_size(body: Any) -> float:
    """The larger side of a body's shapes' box (world units)."""
    boxes = [s.cache_bb() for s in body.shapes]
    return max(max(bb.right - bb.left, bb.top - bb.bottom) for bb in boxes)


def smallest(space: Any) -> int | None:
    """Index of the dynamic body with the smallest shapes, or None."""
    found = dynamic(space)
    return min(found, key=lambda i: body_size(list(space.bodies)[i])) if found else None


def in_view(space: Any, rec: Any, i: int) -> bool:
    """Whether body ``i`` of ``space`` has its position inside the recording's view."""
    x0, x1, y0, y1 = rec.view
    p = list(space.bodies)[i].position
    return min(x0, x1) <= p.x <= max(x0, x1) and min(y0, y1) <= p.y <= max(y0, y1)


def smallest_in_view(space: Any, rec: Any) -> int | None:
    """Index of the dynamic body with the smallest shapes among those in the view, or
    None."""
    visible = [i for i in dynamic(space) if in_view(space, rec, i)]
    return min(visible, key=lambda i: body_size(list(space.bodies)[i])) if visible else None


def smallest_px(space: Any, rec: Any) -> float | None:
    """How large (px, the larger side of its pixels) the smallest body in the view is drawn:
    that body drawn alone through the recording's view, measured on its pixels; None
    without a dynamic body in the view."""
    i = smallest_in_view(space, rec)
    return None if i is None else extent(picture(space, rec, bodies=[i]))


def orientation(rec: Any) -> str:
    """'up' or 'down': which way y points in the recording's picture."""
    return "up" if rec.view[3] > rec.view[2] else "down"


def ground(space: Any) -> int | None:
    """Index into ``space.shapes`` of the ground: the static segment nearest below the
    lowest dynamic body along gravity, among those that reach under the bodies (None without
    gravity, bodies or such a segment)."""
    import pymunk

    g = space.gravity
    if g.length == 0 or not dynamic(space):
        return None
    down = g.normalized()
    across = down.perpendicular()
    bodies = [list(space.bodies)[i] for i in dynamic(space)]
    lowest = max(b.position.dot(down) for b in bodies)
    left = min(b.position.dot(across) for b in bodies)
    right = max(b.position.dot(across) for b in bodies)
    best, best_depth = None, math.inf
    for i, s in enumerate(space.shapes):
        if s.body.body_type != pymunk.Body.STATIC or not isinstance(s, pymunk.Segment):
            continue
        a, b = s.body.local_to_world(s.a), s.body.local_to_world(s.b)
        depth = (a.dot(down) + b.dot(down)) / 2
        lo, hi = sorted((a.dot(across), b.dot(across)))
        if depth > lowest and hi >= left and lo <= right and depth < best_depth:
            best, best_depth = i, depth
    return best


def screen_order(run: Any, space: Any) -> list[int]:
    """Dynamic bodies (indices) from the top of the program's own screen to its bottom
    (pygame draws y down unless the program says otherwise; y up is flipped)."""
    sign = -1 if run.y_up else 1
    return sorted(dynamic(space), key=lambda i: sign * list(space.bodies)[i].position.y)
