"""spaces.Recorder on pymunk's own example programs (loaded from the installed package, run
headless): the first and last frames show the ground at the bottom and every body the right
way up and at a readable size, measured on the pixels (each part drawn alone through the
same view, found as the non-white pixels, and checked to be in the recorded frame); frame 0 is
t = 0 and every label is the time of its picture."""

from __future__ import annotations

import numpy as np
import pytest

from .pymunk_corpus import EXAMPLES
from .recorder_corpus import (
    NAMES,
    body_size,
    dynamic,
    frame,
    ground,
    in_view,
    orientation,
    picture,
    record,
    rows,
    scene_mask,
    screen_order,
    smallest_px,
)

pytest.importorskip("pygame")

#: Simulated time recorded per example (s).
SECONDS = 1.0
#: A body is readable when drawn at least this many pixels across (640 x 360 frame).
MIN_PX = 4


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = record(name, SECONDS, tmp_path_factory.mktemp(name) / f"{name}.gif")
        return cache[name]

    return get


@pytest.mark.parametrize("name", NAMES)
def test_frames_are_at_the_times_of_their_pictures(name, recorded):
    r = recorded(name)
    t = np.array(r.rec.times)
    fps = r.rec.fps
    assert t[0] == 0.0 and (np.diff(t) > 0).all()
    # Frame k is the first step at or past k / fps: no later than one step after it.
    dt = max(r.run.dts)
    k = np.arange(len(t))
    assert (t >= k / fps - 1e-9).all() and (t < k / fps + dt + 1e-9).all()
    assert r.run.t - dt < t[-1] <= r.run.t + 1e-9 or r.run.t - t[-1] < 1 / fps
    with __import__("PIL.Image").Image.open(r.path) as im:
        assert im.n_frames == r.rec.frames == len(t)


@pytest.mark.parametrize("which", [0, -1], ids=["first", "last"])
@pytest.mark.parametrize("name", NAMES)
def test_ground_at_the_bottom_and_bodies_readable(name, which, recorded):
    r = recorded(name)
    rec, run = r.rec, r.run
    space = r.first if which == 0 else r.last
    shown = scene_mask(frame(r.path, which), rec)
    bodies = dynamic(space)
    if not bodies:
        pytest.skip(f"{name} has no dynamic body at this frame")
    alone = picture(space, rec, bodies=bodies)
    # The parts drawn alone are what the recorder drew in its frame.
    assert alone.sum() > 0
    assert (alone & shown).sum() >= 0.9 * alone.sum()
    # Readable: the smallest body in view is drawn at least MIN_PX across.
    visible = [i for i in bodies if in_view(space, rec, i)]
    assert len(visible) >= 0.8 * len(bodies)
    assert smallest_px(space, rec) >= MIN_PX
    # The right way up: the bodies highest and lowest on the program's own screen keep
    # their order in the picture.
    order = [i for i in screen_order(run, space) if i in visible]
    top, bottom = order[0], order[-1]
    ys = [list(space.bodies)[i].position.y for i in (top, bottom)]
    if len(order) >= 2 and abs(ys[0] - ys[1]) > 2 * max(
            body_size(list(space.bodies)[i]) for i in (top, bottom)):
        high = rows(picture(space, rec, bodies=[top]))
        low = rows(picture(space, rec, bodies=[bottom]))
        assert np.median(high) < np.median(low)
    # The ground (the static segment nearest below the lowest body, along gravity) is in
    # the picture, below the bodies.
    g = ground(space)
    if g is not None:
        floor = picture(space, rec, statics=[g])
        assert floor.any()
        assert below(floor, alone) > 0


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_y_points_the_way_each_programs_window_shows_it(name, tmp_path):
    # Every program of the corpus, pygame (pygame_util's flag either way, or its own flipy),
    # pyglet, with and without gravity: the recorder made inside the running program draws
    # y as the program's own window does (breakout, pygame_util told y is up and no gravity,
    # was drawn y down before issue 28).
    r = record(name, 0.2, tmp_path / f"{name}.gif", energy=False)
    assert orientation(r.rec) == ("up" if r.run.y_up else "down")
    assert r.rec.orientation.startswith(f"y {orientation(r.rec)}: ")


def below(floor, bodies):
    """How far (px) the floor's pixels lie below the bodies' in the columns that hold both
    (the median over those columns of the difference of their mean rows); on a slope too."""
    rows = np.arange(floor.shape[0])[:, None]
    both = floor.any(axis=0) & bodies.any(axis=0)
    assert both.sum() >= 3, "the floor does not run under the bodies in the picture"
    f = (floor * rows).sum(axis=0)[both] / floor.sum(axis=0)[both]
    b = (bodies * rows).sum(axis=0)[both] / bodies.sum(axis=0)[both]
    return float(np.median(f - b))


@pytest.mark.parametrize("name", ["constraints", "tank", "spiderweb", "flipper", "planet"])
def test_captured_primitives_are_what_pymunk_draws(name):
    # The recorder moves each shape's local geometry by its body's pose itself; pymunk's own
    # debug drawing of the same space (its cached shape geometry brought up to date: the
    # flipper program moves its flippers by hand after each step) hands the same circles,
    # segments and polygons to the same draw options.
    from dumbbell import spaces

    from .pymunk_corpus import run_example

    run = run_example(name, 20)
    ours, theirs = spaces.draw_options(), spaces.draw_options()
    moving = [it for it in ours.capture(run.space) if it[0] in ("circle", "seg", "poly")]
    theirs.items, theirs.static = [], []
    for shape in run.space.shapes:
        shape.cache_bb()
    run.space.debug_draw(theirs)
    assert moving
    for mine, pymunks in ((moving, theirs.items), (ours.static, theirs.static)):
        assert len(mine) == len(pymunks)
        for a, b in zip(sorted(mine, key=_order), sorted(pymunks, key=_order), strict=True):
            assert a[0] == b[0] and (a[1] < 0) == (b[1] < 0) and (a[2] < 0) == (b[2] < 0)
            assert _numbers(a) == pytest.approx(_numbers(b), abs=1e-9)


def _numbers(it):
    if it[0] == "poly":
        return [*it[3], it[4]]
    return list(it[3:])


def _order(it):
    return (it[0], [round(v, 6) for v in _numbers(it)])


@pytest.mark.parametrize("name", NAMES)
def test_drawing_only_what_changed_gives_the_frames_drawn_whole(name, recorded, tmp_path,
                                                                monkeypatch):
    # The painter draws again only the boxes where a primitive's whole pixels changed (and
    # the label, a bar, the cursor when theirs did): every frame drawn from nothing gives the
    # same file, byte for byte, on each program (flat or smooth, bodies coming and going).
    from dumbbell.animation import recording

    whole = recording.Painter.frame

    def from_nothing(self, k):
        self._canvas = None
        return whole(self, k)

    r = recorded(name)
    monkeypatch.setattr(recording.Painter, "frame", from_nothing)
    recording.write(tmp_path / "whole.gif", r.rec.recording())
    assert (tmp_path / "whole.gif").read_bytes() == r.path.read_bytes()
