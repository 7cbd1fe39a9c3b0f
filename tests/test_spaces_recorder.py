"""spaces.Recorder: frames, timing and loop read back from the GIF; MP4 frame count; same bytes
for the same captures; nothing written when the block fails."""

from __future__ import annotations

import importlib.util
import math
import os
from pathlib import Path

import numpy as np
import pymunk
import pytest
from PIL import Image

from dumbbell import spaces
from dumbbell.errors import DumbbellError, UsageError


def _space() -> pymunk.Space:
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    floor = pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.02)
    floor.elasticity = 0.8
    box = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.1)))
    box.position, box.angular_velocity = (0.0, 0.8), 3.0
    poly = pymunk.Poly.create_box(box, (0.2, 0.1))
    poly.elasticity = 0.8
    ball = pymunk.Body(0.5, pymunk.moment_for_circle(0.5, 0, 0.05))
    ball.position = (0.4, 0.5)
    circle = pymunk.Circle(ball, 0.05)
    space.add(floor, box, poly, ball, circle,
              pymunk.DampedSpring(box, ball, (0.1, 0), (0, 0), 0.3, 50.0, 0.0),
              pymunk.PinJoint(space.static_body, ball, (0.6, 1.0), (0, 0)))
    return space


def _record(path, frames: int, fps: int, **kw) -> spaces.Recorder:
    space = _space()
    with spaces.Recorder(space, path, fps=fps, **kw) as rec:
        for _ in range(frames):
            rec.capture()
            spaces.step(space, 1.0 / fps, substeps=10)
    return rec


@pytest.mark.parametrize("fps, frames", [(25, 30), (30, 17), (10, 5)])
def test_gif_frames_timing_and_loop(tmp_path, fps, frames):
    path = tmp_path / "out.gif"
    rec = _record(path, frames, fps)
    assert rec.frames == frames
    with Image.open(path) as im:
        assert im.n_frames == frames
        assert im.info["loop"] == 0  # forever
        durations = []
        for k in range(frames):
            im.seek(k)
            durations.append(im.info["duration"])
    # Frame k starts at round(k * 1000 / fps) ms to the GIF's 10 ms: real time kept.
    starts = np.cumsum([0, *durations])
    want = [10 * math.floor(k * 100 / fps + 0.5) for k in range(frames + 1)]
    assert starts.tolist() == want


def test_same_captures_same_bytes_and_frames_differ(tmp_path):
    a, b = tmp_path / "a.gif", tmp_path / "b.gif"
    _record(a, 12, 25)
    _record(b, 12, 25)
    assert a.read_bytes() == b.read_bytes()
    with Image.open(a) as im:
        im.seek(0)
        first = np.asarray(im.convert("RGB"))
        im.seek(11)
        last = np.asarray(im.convert("RGB"))
    assert (first != last).any(axis=2).sum() > 100  # the bodies moved
    # Without energy the frame is all scene; with it the panel is there.
    c = tmp_path / "c.gif"
    _record(c, 3, 25, energy=False)
    assert c.read_bytes() != a.read_bytes()


def test_nothing_written_when_the_block_fails(tmp_path):
    path = tmp_path / "out.gif"
    with pytest.raises(RuntimeError), spaces.Recorder(_space(), path) as rec:
        rec.capture()
        raise RuntimeError("user's bug")
    assert list(tmp_path.iterdir()) == []


def test_bad_arguments_are_one_clear_error(tmp_path):
    from dumbbell.errors import DumbbellError, UsageError

    with pytest.raises(UsageError, match="fps = 0"):
        spaces.Recorder(_space(), tmp_path / "a.gif", fps=0)
    with pytest.raises(UsageError, match=r"\.gif, \.mp4 or \.html"):
        spaces.Recorder(_space(), tmp_path / "a.png")
    with pytest.raises(DumbbellError, match="no frames"), spaces.Recorder(_space(),
                                                                         tmp_path / "a.gif"):
        pass
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kw, param", [
    ({"fps": 10**5000}, "fps"),
    ({"fps": "9" * 100_000}, "fps"),
    ({"fps": 51}, "fps"),
    ({"size": (10**5000, 360)}, "size"),
    ({"size": (640, -10**5000)}, "size"),
    ({"size": ("9" * 100_000, 360)}, "size"),
    ({"size": "9" * 100_000}, "size"),
    ({"size": (640.0, 360.0)}, "size"),
    ({"t0": 1e308}, "t0"),
    ({"t0": -2e9}, "t0"),
    ({"t0": 10**5000}, "t0"),
    ({"t0": "9" * 100_000}, "t0"),
])
def test_huge_arguments_are_one_short_line_before_any_work(tmp_path, kw, param):
    # Issue 30: fps=10**5000 and size=(10**5000, 360) raised ValueError from int -> str,
    # fps='9' * 100000 gave a 100,000-character message.
    with pytest.raises(UsageError) as info:
        spaces.Recorder(_space(), tmp_path / "a.gif", **kw)
    message = str(info.value)
    assert message.startswith(param) and info.value.param == param
    assert "\n" not in message and len(message) <= 250
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("t", [1e308, -1e308, 2e9, 10**5000, float("nan"), "1"],
                         ids=["1e308", "-1e308", "2e9", "10**5000", "nan", "str"])
def test_a_frame_time_beyond_what_a_label_shows_is_refused_and_the_recording_goes_on(
        tmp_path, t):
    # Issue 30: capture(t=1e308) raised OverflowError when the file was written.
    space, _ = _ball()
    with spaces.Recorder(space, tmp_path / "a.gif", energy=True) as rec:
        space.step(0.04)
        with pytest.raises(UsageError, match=r"^t = .{1,60}: must be a finite number from "
                                             r"-1e\+09 to 1e\+09 \(s\)$"):
            rec.capture(t=t)
        rec.capture(t=1e9)  # the largest: its label fits
        space.step(0.04)
        rec.capture()
    assert rec.times == (0.0, 1e9, 1e9 + 0.04)


def test_a_long_time_label_is_drawn_whole_over_the_one_before(tmp_path, monkeypatch):
    # Labels wider than the usual box (t near 1e9 with 5 decimals, a 12-character unit):
    # the file is the one made of every frame drawn whole and compared whole.
    from dumbbell.animation import recording

    space, _ = _ball()
    kw = {"energy": False, "units": ("m", "kg", "fortnights__"), "t0": 999_999_999.8}
    with spaces.Recorder(space, tmp_path / "a.gif", **kw) as rec:
        for k in range(1, 4):
            space.step(0.04)
            rec.capture(t=999_999_999.8 + k * 1e-5)  # "t = 999999999.80003 fortnights__"
    from dumbbell.animation import painter

    whole = painter.Painter.frame

    def from_nothing(self, k):
        self._canvas = None
        return whole(self, k)

    monkeypatch.setattr(painter.Painter, "frame", from_nothing)
    monkeypatch.setattr(painter.Painter, "region", lambda self, k: None)
    recording.write(tmp_path / "b.gif", rec.recording())
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


@pytest.mark.parametrize("name", ["a.gif/", "a.gif/.", "sub/a.gif/"])
def test_a_path_naming_a_folder_is_refused(tmp_path, name):
    # Issue 30: Recorder(s, "a.gif/") wrote a file named without the slash.
    message = _refused(f"{tmp_path}/{name}", "names a folder")
    assert name.rstrip("/.") in message
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["a" * 100_000 + ".gif", "a b " * 25_000 + ".gif",
                                  "d/" * 30_000 + "a.gif"])
def test_a_huge_path_is_echoed_clipped(tmp_path, name):
    # Issue 30: a 100,000-character path gave a 100,000-character message.
    message = _refused(f"{tmp_path}/{name}", ".")
    assert len(message) <= 1000
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None,
                    reason="the [mp4] extra (imageio-ffmpeg) is not installed")
def test_mp4_frame_count(tmp_path):
    import imageio.v3 as iio

    path = tmp_path / "out.mp4"
    _record(path, 23, 25)
    frames = iio.imread(path, plugin="pyav") if importlib.util.find_spec("av") else None
    if frames is None:
        import imageio.v2 as iio2

        reader = iio2.get_reader(path, format="FFMPEG")
        count = sum(1 for _ in reader)
        reader.close()
    else:
        count = len(frames)
    assert count == 23


# --- times: frame 0 is t = 0 and each label is the time of its picture ---------------------


def _ball(y: float = 0.5, vy: float = 0.0, g: float = -9.81) -> tuple[pymunk.Space, pymunk.Body]:
    space = pymunk.Space()
    space.gravity = (0.0, g)
    body = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.05))
    body.position, body.velocity = (0.0, y), (0.0, vy)
    space.add(body, pymunk.Circle(body, 0.05))
    return space, body


def _frames(path) -> list[np.ndarray]:
    with Image.open(path) as im:
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB")))
    return out


def _label(frame: np.ndarray) -> np.ndarray:
    """The time label's corner of a frame."""
    return frame[:24, :150]


def test_step_then_capture_starts_at_zero_and_ends_at_the_time_simulated(tmp_path):
    # Issue 20: with this loop the first frame read 0.00 s after one step and the last
    # 1.56 s after 1.6 s simulated. Now frame 0 is the space before any step.
    space, body = _ball()
    y0 = body.position.y
    with spaces.Recorder(space, tmp_path / "a.gif", fps=25, energy=False) as rec:
        ys = [y0]
        for _ in range(40):
            spaces.step(space, 1 / 25, substeps=10)
            rec.capture()
            ys.append(body.position.y)
    assert rec.frames == 41
    assert rec.times == pytest.approx([k / 25 for k in range(41)], abs=1e-12)
    assert rec.times[-1] == pytest.approx(1.6)
    # Frame 0 is the picture of the space before any step: the same as a one-frame
    # recording of a fresh ball; the last frame's label is the one of a frame at 1.6 s.
    fresh, _ = _ball()
    with spaces.Recorder(fresh, tmp_path / "b.gif", fps=25, energy=False,
                         world=rec.view) as one:
        one.capture(t=1.6)
    recorded, alone = _frames(tmp_path / "a.gif"), _frames(tmp_path / "b.gif")[0]
    scene = (slice(30, None), slice(None))
    assert (recorded[0][scene] == alone[scene]).all()
    assert (recorded[-1][:24, :150] == alone[:24, :150]).all()  # "t = 1.60 s"
    assert not (recorded[0][:24, :150] == alone[:24, :150]).all()  # "t = 0.00 s"


def test_capture_then_step_gives_the_same_times(tmp_path):
    space, _ = _ball()
    with spaces.Recorder(space, tmp_path / "a.gif", fps=10, energy=False) as rec:
        for _ in range(5):
            rec.capture()  # the first, before any step, replaces frame 0
            spaces.step(space, 0.1, substeps=4)
    assert rec.frames == 5 and rec.times == pytest.approx([0, 0.1, 0.2, 0.3, 0.4])


def test_a_capture_without_a_step_shows_the_same_time_and_t_can_be_given(tmp_path):
    space, _ = _ball()
    with spaces.Recorder(space, tmp_path / "a.gif", fps=20, energy=False, t0=2.0) as rec:
        space.step(0.05)
        rec.capture()
        rec.capture()            # no step since: the same time again
        for _ in range(3):
            space.step(1 / 60)
        rec.capture(t=2.1)       # frames not 1/fps apart: say when
        with pytest.raises(UsageError, match=r"t = 2: must be at least"):
            rec.capture(t=2.0)
    assert rec.times == pytest.approx([2.0, 2.05, 2.05, 2.1])


# --- orientation ----------------------------------------------------------------------------


def _ball_and_floor(g: float, floor_y: float, ball_y: float) -> pymunk.Space:
    space, _ = _ball(ball_y, g=g)
    space.add(pymunk.Segment(space.static_body, (-1, floor_y), (1, floor_y), 0.01))
    return space


def _ink_mask(frame: np.ndarray, k: int = 0) -> np.ndarray:
    """Where a frame (from row 30) shows the colour of body k (its outline or its fill)."""
    from dumbbell.animation.palette import blend
    from dumbbell.animation.pens import BODY_INKS

    f = frame[30:].astype(int)
    near = [np.abs(f - np.array(c)).sum(axis=2) < 30 for c in (BODY_INKS[k],
                                                                 blend(BODY_INKS[k], 0.33))]
    return near[0] | near[1]


def _coloured(frame: np.ndarray) -> np.ndarray:
    """Where a frame (below the time label, from row 30) shows a body's colour."""
    f = frame[30:].astype(int)
    return (f.max(axis=2) - f.min(axis=2)) > 40


def _grey(frame: np.ndarray) -> np.ndarray:
    """Where a frame (below the time label, from row 30) shows a static shape's grey."""
    f = frame[30:].astype(int)
    return ((f.max(axis=2) - f.min(axis=2)) <= 6) & (f.max(axis=2) < 200)


@pytest.mark.parametrize("g, floor_y, ball_y, kw", [
    (-9.81, 0.0, 0.5, {}),                        # y up: gravity says so
    (900.0, 500.0, 100.0, {}),                    # y down (pygame): gravity says so
    (0.0, 500.0, 100.0, {"y_up": False}),         # no gravity: say it
    (0.0, 500.0, 100.0, {"world": (-1.0, 1.0, 600.0, 0.0)}),   # or give a y-down box
    (-9.81, 0.0, 0.5, {"world": (-1.0, 1.0, -0.2, 1.0)}),      # a y-up box
])
def test_the_ground_is_at_the_bottom_in_y_up_and_y_down_worlds(tmp_path, g, floor_y, ball_y,
                                                              kw):
    space = _ball_and_floor(g, floor_y, ball_y)
    kw.setdefault("camera", "all") if "world" not in kw else None
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False, **kw) as rec:
        rec.capture()
    frame = _frames(tmp_path / "a.gif")[0]
    ball, floor = np.nonzero(_coloured(frame))[0], np.nonzero(_grey(frame))[0]
    assert len(ball) and len(floor)
    assert floor.min() > ball.max()


def _window(monkeypatch, imported: tuple[str, ...], flag: bool | None = None) -> None:
    """Make sys.modules hold exactly these window libraries (stand-ins: the recorder only
    looks at which are imported), and pymunk.pygame_util with ``flag`` when it is given."""
    import sys
    import types

    for name in ("pygame", "pymunk.pygame_util", "pyglet", "arcade", "kivy"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    for name in imported:
        name, _, blocked = name.partition("=")
        monkeypatch.setitem(sys.modules, name, None if blocked else types.ModuleType(name))
    if flag is not None:
        util = types.ModuleType("pymunk.pygame_util")
        util.positive_y_is_up = flag
        monkeypatch.setitem(sys.modules, "pygame", types.ModuleType("pygame"))
        monkeypatch.setitem(sys.modules, "pymunk.pygame_util", util)


def _ball_above_floor(path) -> bool:
    """Whether the ball is drawn above the floor (rows from the top) in a one-frame GIF."""
    frame = _frames(path)[0]
    ball, floor = np.nonzero(_coloured(frame))[0], np.nonzero(_grey(frame))[0]
    assert len(ball) and len(floor)
    assert ball.max() < floor.min() or floor.max() < ball.min()
    return bool(ball.max() < floor.min())


#: The window rule: (window libraries imported, pygame_util's flag or None when it is not
#: imported, gravity's y, whether y is up in the picture). The ball is at y = 100, the floor
#: at y = 500: y down puts the ball above the floor.
WINDOWS = [
    (("pygame",), None, 0.0, False),         # pygame drawn by hand, no gravity: y down
    (("pygame",), None, 900.0, False),
    (("pygame",), None, -900.0, True),       # its own flipy: gravity -y says so
    ((), False, 0.0, False),                 # pygame_util, y down
    ((), False, 900.0, False),
    ((), True, 0.0, True),                   # pygame_util told y is up ...
    ((), True, 900.0, True),                 # ... whatever the gravity
    (("pyglet",), None, 0.0, True),          # pyglet, arcade, kivy: y up, whatever the gravity
    (("pyglet",), None, 900.0, True),
    (("arcade",), None, 0.0, True),
    (("kivy",), None, 900.0, True),
    ((), None, 0.0, True),                   # no window library: up against gravity, else up
    ((), None, 900.0, False),
    ((), None, -900.0, True),
    (("pygame", "pyglet"), None, 0.0, True),     # both kinds: as with none
    (("pygame", "pyglet"), None, 900.0, False),
    (("pyglet", "pygame=None"), None, 0.0, True),  # an import blocked is no import
]


@pytest.mark.parametrize("imported, flag, g, up", WINDOWS)
def test_y_points_the_way_the_programs_window_shows_it(tmp_path, monkeypatch, imported, flag,
                                                       g, up):
    _window(monkeypatch, imported, flag)
    space = _ball_and_floor(g, 500.0, 100.0)
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False, camera="all") as rec:
        rec.capture()
    assert _ball_above_floor(tmp_path / "a.gif") is not up
    assert rec.orientation.startswith(f"y {'up' if up else 'down'}: ")
    assert rec.note.splitlines()[0] == rec.orientation
    _, _, bottom, top = rec.view
    assert (top > bottom) is up


@pytest.mark.parametrize("imported, flag, g, up", WINDOWS[::3])
def test_y_up_given_wins_and_the_rule_is_read_when_the_recorder_is_made(
        tmp_path, monkeypatch, imported, flag, g, up):
    _window(monkeypatch, imported, flag)
    space = _ball_and_floor(g, 500.0, 100.0)
    for given in (True, False):
        with spaces.Recorder(space, tmp_path / "a.gif", energy=False, camera="all",
                             y_up=given) as rec:
            rec.capture()
        assert _ball_above_floor(tmp_path / "a.gif") is not given
    rec = spaces.Recorder(space, tmp_path / "b.gif", energy=False, camera="all")
    _window(monkeypatch, () if imported or flag is not None else ("pygame",))  # changes after
    space.gravity = (0.0, -g)
    rec.capture()
    rec.write()
    assert _ball_above_floor(tmp_path / "b.gif") is not up


def test_a_world_box_that_contradicts_y_up_is_refused(tmp_path):
    with pytest.raises(UsageError, match="y_up"):
        spaces.Recorder(_space(), tmp_path / "a.gif", world=(0, 600, 600, 0), y_up=True)


# --- the camera -------------------------------------------------------------------------------


def _row_of_balls(n: int = 5, runaway: float = 0.0) -> tuple[pymunk.Space, list[pymunk.Body]]:
    """n balls of radius 0.05 m at rest on a floor, the last thrown sideways at ``runaway``."""
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    space.add(pymunk.Segment(space.static_body, (-50, 0), (50, 0), 0.01))
    balls = []
    for i in range(n):
        b = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.05))
        b.position = (0.15 * i, 0.06)
        space.add(b, pymunk.Circle(b, 0.05))
        balls.append(b)
    space.gravity = (0.0, 0.0) if runaway else space.gravity
    balls[-1].velocity = (runaway, 0.0)
    return space, balls


def _extent(mask: np.ndarray) -> float:
    ys, xs = np.nonzero(mask)
    return float(max(ys.max() - ys.min(), xs.max() - xs.min()) + 1) if len(ys) else 0.0


def test_one_ball_flying_away_does_not_shrink_the_others(tmp_path):
    # Five balls; the last flies off at 40 m/s for 2 s (80 m). Everything in view
    # ("all") makes the first ball a few pixels across; the automatic camera keeps it large
    # and lets the runaway leave the picture.
    sizes = {}
    for camera in ("all", "auto"):
        space, _ = _row_of_balls(runaway=40.0)
        path = tmp_path / f"{camera}.gif"
        with spaces.Recorder(space, path, energy=False, camera=camera) as rec:
            for _ in range(50):
                spaces.step(space, 1 / 25, substeps=2)
                rec.capture()
        first_ball = _coloured(_frames(path)[-1]) & _ink_mask(_frames(path)[-1])
        sizes[camera] = _extent(first_ball)
    # Hand computation: 'auto' shows the four resting balls (0..0.6 m plus the padding and
    # the runaway's first metres): 0.1 m is > 40 px of ~620; 'all' shows 80 m: < 2 px.
    assert sizes["auto"] > 40 and sizes["all"] < 5


def test_the_automatic_view_holds_still(tmp_path):
    space, balls = _row_of_balls()
    balls[0].velocity = (0.5, 2.0)
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False) as rec:
        for _ in range(15):
            spaces.step(space, 1 / 25, substeps=4)
            rec.capture()
    frames = _frames(tmp_path / "a.gif")
    # The floor's pixels do not move from frame to frame: one view for the whole file
    # (compared in the columns no ball ever covers).
    clear = ~np.any([_coloured(f).any(axis=0) for f in frames], axis=0)
    floors = [_grey(f)[:, clear] for f in frames]
    assert floors[0].sum() > 100 and all(np.array_equal(floors[0], f) for f in floors)


def test_following_a_body_keeps_it_at_the_centre(tmp_path):
    space, body = _ball(y=5.0, g=-9.81)
    space.add(pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.02))
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False, camera=body, span=1.0) as rec:
        for _ in range(20):
            spaces.step(space, 1 / 25, substeps=4)
            rec.capture()
    centres = []
    for f in _frames(tmp_path / "a.gif"):
        ys, xs = np.nonzero(_coloured(f))
        centres.append(((ys.min() + ys.max()) / 2 + 30, (xs.min() + xs.max()) / 2))
    centres = np.array(centres)
    assert np.ptp(centres, axis=0).max() <= 1.0  # the ball holds still in the picture ...
    # ... in the middle of the scene area (8..632 px across, 30..352 px down at 640x360).
    assert centres[0] == pytest.approx((30 + 322 / 2, 8 + 624 / 2), abs=1.5)
    with pytest.raises(UsageError, match="span"):
        spaces.Recorder(space, tmp_path / "b.gif", span=1.0)


def test_a_fixed_box_maps_world_to_pixels_as_computed_by_hand(tmp_path):
    # world (0, 6.24, 0, 3.22) m fills the scene area 624 x 322 px from (8, 30): 100 px/m.
    space, _ = _ball(y=1.0)
    next(iter(space.bodies)).position = (2.0, 1.0)
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False,
                         world=(0.0, 6.24, 0.0, 3.22)) as rec:
        rec.capture()
    ys, xs = np.nonzero(_coloured(_frames(tmp_path / "a.gif")[0]))
    assert (xs.min() + xs.max()) / 2 == pytest.approx(8 + 200, abs=1)
    assert (ys.min() + ys.max()) / 2 + 30 == pytest.approx(30 + 322 - 100, abs=1)


def test_static_shapes_added_later_are_drawn_from_then_on(tmp_path):
    space, _ = _ball()
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False,
                         world=(-1.0, 1.0, -0.5, 1.0)) as rec:
        for k in range(6):
            if k == 3:
                space.add(pymunk.Segment(space.static_body, (-0.8, 0), (0.8, 0), 0.02))
            spaces.step(space, 1 / 25)
            rec.capture()
    drawn = [_grey(f).sum() for f in _frames(tmp_path / "a.gif")]
    assert drawn[:4] == [0] * 4 and min(drawn[4:]) > 100


def _small_parts(far: bool = False, angle: float = 0.0) -> pymunk.Space:
    """A pixel space (y down, no gravity) of bodies spread over 2,000 px: a 60 x 30 px
    chassis, and small parts of each kind (a 3 x 2 px box, a 5 px rod of radius 0, a circle
    of radius 1 px, a body of two 2 px boxes), turned by ``angle``; a floor under them,
    and (``far``) a static segment 100,000 px away."""
    space = pymunk.Space()
    space.add(pymunk.Segment(space.static_body, (-100, 40), (2100, 40), 2))
    if far:
        space.add(pymunk.Segment(space.static_body, (1e5, -5e4), (1.2e5, -5e4), 3))
    parts = [
        (0.0, [pymunk.Poly.create_box(None, (60, 30))]),
        (500.0, [pymunk.Poly.create_box(None, (3, 2))]),
        (1000.0, [pymunk.Segment(None, (-2.5, 0), (2.5, 0), 0)]),
        (1500.0, [pymunk.Circle(None, 1.0)]),
        (2000.0, [pymunk.Poly(None, [(0, 0), (2, 0), (2, 2), (0, 2)]),
                  pymunk.Poly(None, [(3, 0), (5, 0), (5, 2), (3, 2)])]),
    ]
    for x, shapes in parts:
        body = pymunk.Body(1.0, 10.0)
        body.position, body.angle = (x, 0.0), angle
        for shape in shapes:
            shape.body = body
        space.add(body, *shapes)
    return space


@pytest.mark.parametrize("angle", [0.0, 0.4, math.pi / 4])
def test_every_body_is_drawn_at_least_4_px_and_far_static_shapes_change_nothing(
        tmp_path, angle):
    from .recorder_corpus import extent, picture

    views, notes = [], []
    for far in (False, True):
        space = _small_parts(far, angle)
        with spaces.Recorder(space, tmp_path / f"{far}.gif", y_up=False) as rec:
            rec.capture()
        views.append(rec.view)
        notes.append(rec.note)
    # The far segment neither widens nor moves the view: the frames are the same.
    assert views[0] == views[1] and notes[0] == notes[1]
    assert (tmp_path / "False.gif").read_bytes() == (tmp_path / "True.gif").read_bytes()
    # At this view (~0.16 px per px of the space) the parts would be 0.3 to 1 px; each is
    # drawn at least 4 px across (measured on its pixels, drawn alone), the chassis to scale.
    s = 0.56 * 640 - 16
    scale = s / (rec.view[1] - rec.view[0])
    drawn = [extent(picture(space, rec, bodies=[i])) for i in range(5)]
    assert all(d >= 4 for d in drawn), drawn
    c, si = abs(math.cos(angle)), abs(math.sin(angle))
    assert drawn[0] == pytest.approx(scale * max(60 * c + 30 * si, 60 * si + 30 * c), abs=2.5)
    # The note names the parts drawn larger than to scale, and not the chassis.
    grown = rec.note.splitlines()[1]
    assert grown.startswith("drawn larger than to scale, to be 4 px across: ")
    assert "bodies 1-4 (4 of 5 moving bodies; " in grown
    assert len(rec.note.splitlines()) == 2  # nothing outside the picture


def _pair_and_walls(size: float, walls: float | None) -> pymunk.Space:
    """Two boxes ``size`` px across, 1,000 px apart (y down, no gravity), and static walls
    at ``walls`` px outside them on each side."""
    space = pymunk.Space()
    for x in (0.0, 1000.0):
        body = pymunk.Body(1.0, 10.0)
        body.position = (x, 0.0)
        space.add(body, pymunk.Poly.create_box(body, (size, size)))
    if walls is not None:
        for x in (-walls, 1000.0 + walls):
            space.add(pymunk.Segment(space.static_body, (x, -10), (x, 10), 1))
    return space


@pytest.mark.parametrize("size", [10.0, 40.0])
def test_static_shapes_near_the_bodies_never_make_one_smaller_than_4_px(tmp_path, size):
    from .recorder_corpus import extent, picture

    def record(walls):
        with spaces.Recorder(_pair_and_walls(size, walls), tmp_path / "a.gif", energy=False,
                             y_up=False) as rec:
            rec.capture()
        return rec, rec.view[1] - rec.view[0]

    rec, bodies_only = record(None)
    # Walls 250 px outside the bodies are near them (within a quarter of their box's width):
    # shown, as long as the bodies stay at least 4 px across to scale.
    rec, with_walls = record(250.0)
    area = 640 - 16  # the scene's width without the energy panel (px)
    to_scale = size * math.cos(math.pi / 64)  # (the least side as measured, 16 turns)
    if size * area / (1502 * 1.1) >= 4:
        # Large bodies: the view holds the walls, as it always did.
        assert with_walls == pytest.approx(1502 * 1.1, rel=1e-9)
    else:
        # Small ones: the view widens only until they are 4 px across, to scale.
        assert with_walls == pytest.approx(to_scale * area / 4, rel=1e-9)
        assert bodies_only < with_walls < 1502 * 1.1
    assert len(rec.note.splitlines()) == 1  # none drawn larger than to scale
    drawn = [extent(picture(rec.space, rec, bodies=[i])) for i in range(2)]
    assert min(drawn) >= 4
    assert extent(picture(rec.space, rec, statics=[0])) > 0  # the walls are in the picture
    # Walls beyond the near zone change nothing.
    assert record(2000.0)[1] == bodies_only


def test_a_body_that_leaves_the_picture_is_named(tmp_path):
    space, _ = _row_of_balls(runaway=40.0)
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False) as rec:
        for _ in range(50):
            spaces.step(space, 1 / 25, substeps=2)
            rec.capture()
    lines = rec.note.splitlines()
    assert lines[-1].startswith("outside the picture (or not drawable) in some frames: body 4 ")
    out = int(lines[-1].split(" in ")[-1].split(" of ")[0])
    # The runaway flies 1.6 m per frame: the view (about 1 m wide) loses it within a frame
    # or two.
    assert 45 <= out <= 50 and lines[-1].endswith(" of 51")


def test_far_and_tiny_things_do_not_break_the_drawing(tmp_path):
    space, _ = _ball()
    far = pymunk.Body(1.0, 1.0)
    far.position = (1e200, -1e200)
    space.add(far, pymunk.Circle(far, 1e150))
    for camera in ("auto", "all"):
        with spaces.Recorder(space, tmp_path / f"{camera}.gif", camera=camera) as rec:
            rec.capture()
        assert len(_frames(tmp_path / f"{camera}.gif")) == 1


@pytest.mark.parametrize("world", [(0, 1e-300, 0, 1e-300), (0, 1, 0, 1e-300), (0, 1e40, 0, 1),
                                   (1e20, 1e20 + 1, 0, 1), (0, float("inf"), 0, 1),
                                   (0, 1, 0, float("nan")), (1, 0, 0, 1), (0, 1, 1, 1)])
def test_bad_worlds_are_refused_when_the_recorder_is_made(tmp_path, world):
    with pytest.raises(UsageError, match=r"^world"):
        spaces.Recorder(_space(), tmp_path / "a.gif", world=world)
    assert list(tmp_path.iterdir()) == []


def test_refusals_name_the_spaces_units(tmp_path):
    # Issue 29: a value of a space carries the space's unit wherever it is printed.
    space = _space()
    body = next(b for b in space.bodies if b.body_type == pymunk.Body.DYNAMIC)
    for kw, unit in [({"world": (0, "a", 0, 1)}, "(px)"), ({"world": (0, 1e40, 0, 1)}, " px,"),
                     ({"camera": body, "span": -1.0}, "(px)"),
                     ({"reference": {"U_g": math.nan}}, "(kg px²/s²)"),
                     ({"t0": math.inf}, "(s)")]:
        with pytest.raises(UsageError) as info:
            spaces.Recorder(space, tmp_path / "a.gif", units="px", **kw)
        assert unit in str(info.value)
    with pytest.raises(UsageError, match=r"\(J\)$"):
        spaces.Recorder(space, tmp_path / "a.gif", units="m", reference={"U_g": math.nan})
    # Units not named: no unit is claimed (a pixel space's energy is not in J).
    with pytest.raises(UsageError, match=r"\(energy units\)$"):
        spaces.Recorder(space, tmp_path / "a.gif", reference={"U_g": math.nan})


# --- energy bars --------------------------------------------------------------------------------


def test_bars_show_changes_from_the_start_in_the_spaces_units(tmp_path):
    # A 2 kg ball falls freely in a pixel space (g = 900 px/s^2 down, y up). Hand computation
    # at each frame from its height and speed: dU_g = m g (y - y0), K = m v^2 / 2, and
    # K + dU_g stays 0 (pymunk's free fall keeps it to its step error).
    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    body = pymunk.Body(2.0, pymunk.moment_for_circle(2.0, 0, 10))
    body.position = (300.0, 5000.0)
    space.add(body, pymunk.Circle(body, 10))
    ys, vs = [body.position.y], [0.0]
    with spaces.Recorder(space, tmp_path / "a.gif", units=("px", "kg", "s")) as rec:
        for _ in range(25):
            spaces.step(space, 1 / 25, substeps=20)
            rec.capture()
            ys.append(body.position.y)
            vs.append(body.velocity.length)
    r = rec.recording()
    assert r.energy_title == "Energy (kg px²/s²)" and r.time_unit == "s"
    for units, title in (("px", "Energy (kg px²/s²)"), (("cm", "g", "s"), "Energy (g cm²/s²)"),
                         (("m", "kg", "s"), "Energy (J)")):
        with spaces.Recorder(space, tmp_path / "u.gif", units=units) as one:
            one.capture()
        assert one.recording().energy_title == title
    with pytest.raises(UsageError, match="^units"):
        spaces.Recorder(space, tmp_path / "u.gif", units=("px", "kg"))
    assert r.labels["U_g"] == "ΔU_g" and r.labels["E"] == "K + ΔU"
    du = 2.0 * 900.0 * (np.array(ys) - ys[0])
    k = 0.5 * 2.0 * np.array(vs) ** 2
    assert r.energy["U_g"] == pytest.approx(du, rel=1e-12, abs=1e-6)
    assert r.energy["K_trans"] == pytest.approx(k, rel=1e-12, abs=1e-6)
    assert np.abs(r.energy["E"]).max() < 0.01 * k[-1]
    # Without the reference, U_g is m g y = 9e6 against a K of 4e5 at the end.
    with spaces.Recorder(space, tmp_path / "b.gif", reference="space") as rec2:
        rec2.capture()
    assert rec2.recording().energy["U_g"][0] == pytest.approx(2 * 900 * body.position.y)
    # On the pixels: the last frame's K bar and dU_g bar are as long as each other.
    last = _frames(tmp_path / "a.gif")[-1]
    from dumbbell.animation.bars import SPACE_INKS as TERM_INKS

    lengths = [((last[:200] == TERM_INKS[n]).all(axis=2)).sum(axis=1).max()
               for n in ("K_trans", "U_g")]
    assert lengths[0] > 50 and abs(lengths[0] - lengths[1]) <= 2


def test_the_energy_panel_is_spaces_energy_at_every_frame_whatever_changes(tmp_path):
    # The panel samples the space in bulk and takes its inventory again only when something
    # it rests on changes. Hand-checked against spaces.energy(space) at each capture while the
    # run changes, one at a time: a spring's rest length and stiffness, a body's mass and
    # centre of gravity, gravity, a body added, a spring's force function, a body's type.
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    a = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    b = pymunk.Body(2.0, pymunk.moment_for_circle(2.0, 0, 0.1))
    a.position, b.position = (0.0, 1.0), (0.5, 1.2)
    a.velocity, b.angular_velocity = (0.3, 0.0), 2.0
    spring = pymunk.DampedSpring(a, b, (0.05, 0), (0, 0.02), 0.4, 30.0, 0.1)
    rotary = pymunk.DampedRotarySpring(space.static_body, b, 0.1, 5.0, 0.0)
    space.add(a, pymunk.Circle(a, 0.1), b, pymunk.Circle(b, 0.1), spring, rotary)
    late = pymunk.Body(1.5, 1.0)
    late.position, late.velocity = (1.0, 2.0), (0.0, 1.0)

    def change(k):
        if k == 2:
            spring.rest_length, spring.stiffness = 0.6, 50.0
        elif k == 4:
            a.mass = 1.5
        elif k == 5:
            b.center_of_gravity = (0.01, 0.0)
        elif k == 6:
            space.gravity = (0.0, -5.0)
        elif k == 7:
            space.add(late, pymunk.Circle(late, 0.1))
        elif k == 8:
            rotary.rest_angle, rotary.stiffness = -0.2, 8.0
        elif k == 9:
            spring.force_func = lambda s, d: 0.0  # its energy unknown from here
        elif k == 10:
            late.body_type = pymunk.Body.KINEMATIC

    want = {n: [] for n in ("K_trans", "K_rot", "U_g", "U_spring", "E")}

    def keep():
        e = spaces.energy(space)
        for n, values in want.items():
            values.append(getattr(e, n))

    with spaces.Recorder(space, tmp_path / "a.gif", reference="space") as rec:
        keep()
        for k in range(12):
            change(k)
            spaces.step(space, 1 / 25, substeps=5)
            rec.capture()
            keep()
    got = rec.recording().energy
    for n, values in want.items():
        assert got[n] == pytest.approx(values, rel=1e-14, abs=1e-14), n
    assert got["U_spring"][10] != got["U_spring"][9]  # the custom spring left U_spring


def _record_adding_a_wall(space, path, frames, **kw):
    """A recording of ``frames`` frames of ``space`` at 1/25 s (10 sub-steps each), a static
    segment added before the fourth."""
    with spaces.Recorder(space, path, **kw) as rec:
        for k in range(frames):
            if k == 3:
                space.add(pymunk.Segment(space.static_body, (-1, 0.5), (-0.5, 0.7), 0.02))
            spaces.step(space, 1 / 25, substeps=10)
            rec.capture()
    return rec


def test_a_frame_drawn_in_parts_is_the_frame_drawn_whole(tmp_path, monkeypatch):
    # From frame to frame the painter draws again only what changed (the moving layer's
    # boxes, the label, a bar, the cursor), on the previous picture. Drawing every frame
    # from nothing gives the same file, byte for byte: with and without the panel, a body
    # thrown out of the view, a static shape added at the fourth frame, springs and pins.
    from dumbbell.animation import recording

    whole = recording.Painter.frame

    def from_nothing(self, k):
        self._canvas = None
        return whole(self, k)

    for kw in ({}, {"energy": False}):
        space = _space()
        thrown = pymunk.Body(0.2, pymunk.moment_for_circle(0.2, 0, 0.03))
        thrown.position, thrown.velocity = (0.0, 0.3), (6.0, 4.0)
        space.add(thrown, pymunk.Circle(thrown, 0.03))
        rec = _record_adding_a_wall(space, tmp_path / "a.gif", 30, **kw)
        with monkeypatch.context() as m:
            m.setattr(recording.Painter, "frame", from_nothing)
            recording.write(tmp_path / "b.gif", rec.recording())
        assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


def _boxes_space(n: int) -> pymunk.Space:
    """``n`` boxes 8 px wide falling side by side onto a floor, in pixels (y down)."""
    space = pymunk.Space()
    space.gravity = (0.0, 900.0)
    space.add(pymunk.Segment(space.static_body, (0, 400), (1200, 400), 2))
    for i in range(n):
        body = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (8, 8)))
        body.position = (10 + 10 * (i % 110), 380 - 12 * (i // 110))
        body.angular_velocity = 0.3
        space.add(body, pymunk.Poly.create_box(body, (8, 8)))
    return space


@pytest.mark.parametrize("n, flat", [(99, False), (100, True)])
def test_many_small_bodies_are_drawn_flat(tmp_path, n, flat):
    # The rule (pens.FLAT_MANY, FLAT_PX): 100 moving shapes or more, each drawn within
    # 20 px, are drawn flat: the bodies' pixels are their fill or outline exactly, no blend
    # of an ink with white in between (the static floor stays smooth). 99 are drawn smooth:
    # blends at their edges.
    from dumbbell.animation.palette import blend
    from dumbbell.animation.pens import BODY_INKS, FLAT_MANY, FLAT_PX

    assert (FLAT_MANY, FLAT_PX) == (100, 20)
    space = _boxes_space(n)
    with spaces.Recorder(space, tmp_path / "a.gif", energy=False, units="px") as rec:
        for _ in range(5):
            spaces.step(space, 1 / 25, substeps=4)
            rec.capture()
    edges = {blend(ink, level / 15) for ink in BODY_INKS for level in (1, 2, 3, 4)}
    fills = {blend(ink, 0.33) for ink in BODY_INKS}
    for k in (0, -1):
        scene = _frames(tmp_path / "a.gif")[k][40:, :]
        colours = {tuple(c) for c in np.unique(scene.reshape(-1, 3), axis=0).tolist()}
        assert colours & fills  # the bodies are there
        assert bool(colours & edges) is not flat


def test_a_reference_you_set(tmp_path):
    space, _ = _ball(y=2.0)
    with spaces.Recorder(space, tmp_path / "a.gif", reference={"U_g": -5.0}) as rec:
        rec.capture()
    r = rec.recording()
    # U_g = m g y = 1 * 9.81 * 2 = 19.62 J, shown from -5 J: 24.62 J.
    assert r.energy["U_g"][0] == pytest.approx(9.81 * 2.0 + 5.0)
    assert r.energy["E"][0] == pytest.approx(9.81 * 2.0 + 5.0)
    for bad in ("zero", {"K_trans": 1.0}, {}, {"U_g": float("nan")}):
        with pytest.raises(UsageError, match="^reference"):
            spaces.Recorder(space, tmp_path / "b.gif", reference=bad)


# --- the path, checked when the recorder is made (issue 24) ------------------------------------


def _refused(path, match, **kw):
    with pytest.raises(DumbbellError, match=match) as info:
        spaces.Recorder(_space(), path, **kw)
    assert "\n" not in str(info.value) and str(info.value).startswith("path")
    return str(info.value)


def test_a_folder_a_system_folder_a_file_as_folder_and_nul_are_refused_up_front(tmp_path):
    (tmp_path / "d.gif").mkdir()
    (tmp_path / "file").write_text("x")
    assert "is a folder" in _refused(tmp_path / "d.gif", "d.gif")
    assert "/proc" in _refused("/proc/x.gif", "x.gif")
    assert "is a file" in _refused(tmp_path / "file" / "x.gif", "file")
    assert "NUL" in _refused(str(tmp_path / "a\0b.gif"), "NUL")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.gif", "file"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in read-only folders")
def test_a_read_only_folder_is_refused_up_front(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        _refused(folder / "x.gif", "ro")
    finally:
        folder.chmod(0o755)


def test_mp4_without_the_extra_is_refused_up_front(tmp_path, monkeypatch):
    from dumbbell.animation import writer

    monkeypatch.setattr(writer, "mp4_problem", lambda: "MP4 needs the optional extra")
    assert "optional extra" in _refused(tmp_path / "a.mp4", "optional extra")
    assert list(tmp_path.iterdir()) == []


def test_render_gif_and_gif_save_refuse_a_folder(tmp_path):
    import dumbbell

    (tmp_path / "d.gif").mkdir()
    with pytest.raises(UsageError, match="is a folder"):
        dumbbell.Gif(b"GIF89a").save(tmp_path / "d.gif")
    scene = Path(__file__).resolve().parent.parent / "scenes" / "textbook-1d.toml"
    traj = dumbbell.simulate(scene, solver="exact", t_end=0.05)
    with pytest.raises(UsageError, match="is a folder"):
        dumbbell.render_gif(traj, tmp_path / "d.gif")


SIGTERM_SCRIPT = """
import os, signal, sys
import pymunk
from dumbbell import spaces
from dumbbell.animation import recording

space = pymunk.Space()
body = pymunk.Body(1, 1)
space.add(body, pymunk.Circle(body, 0.1))
frame = recording.Painter.frame

def frame_then_term(self, k):
    if k == 5:
        os.kill(os.getpid(), signal.SIGTERM)  # the user's kill, while the GIF is written
    return frame(self, k)

recording.Painter.frame = frame_then_term
with spaces.Recorder(space, sys.argv[1]) as rec:
    for _ in range(20):
        space.step(0.04)
        rec.capture()
print("not reached")
"""


def test_sigterm_while_writing_leaves_no_part_file(tmp_path):
    import signal
    import subprocess
    import sys

    script = tmp_path / "script.py"
    script.write_text(SIGTERM_SCRIPT)
    out = tmp_path / "out"
    out.mkdir()
    done = subprocess.run([sys.executable, str(script), str(out / "rec.gif")],
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == -signal.SIGTERM  # ended as SIGTERM ends a script ...
    assert "not reached" not in done.stdout and list(out.iterdir()) == []  # ... cleanly


def test_the_gif_encoder_call_gives_the_bytes_of_a_one_frame_gif():
    # animation/gif.py calls Pillow's LZW encoder as Pillow's GIF writer does, without
    # writing a whole one-frame GIF per frame: the same bytes (render_gif's GIFs stay
    # byte-identical), on random, few-colour, flat and odd-sized frames.
    from dumbbell.animation import gif

    rng = np.random.default_rng(1)
    for shape in [(1, 1), (3, 5), (360, 640), (17, 255)]:
        for frame in (rng.integers(0, 256, shape), rng.integers(0, 4, shape), np.zeros(shape)):
            pixels = frame.astype(np.uint8)
            im = Image.frombuffer("L", (shape[1], shape[0]), np.ascontiguousarray(pixels),
                                  "raw", "L", 0, 1)
            assert gif._lzw(pixels) == gif._lzw_of_a_gif(im)


@pytest.mark.parametrize("kw", [{}, {"energy": False}, {"camera": "follow"}])
def test_comparing_only_where_a_frame_drew_gives_the_same_file(tmp_path, monkeypatch, kw):
    # The painter tells the GIF writer where each frame drew (moving layer, time, bars,
    # cursor); comparing frames only there must find every change: the same bytes as
    # comparing whole frames. A static shape comes at the fourth frame.
    from dumbbell.animation import recording

    space = _space()
    if kw.get("camera") == "follow":
        kw = {"camera": next(b for b in space.bodies if b.body_type == pymunk.Body.DYNAMIC)}
    rec = _record_adding_a_wall(space, tmp_path / "a.gif", 12, **kw)
    monkeypatch.setattr(recording.Painter, "region", lambda self, k: None)
    recording.write(tmp_path / "b.gif", rec.recording())
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


def test_a_recording_imports_neither_the_figures_nor_matplotlib(tmp_path):
    # The recorder draws with Pillow alone: a script that records a space (energy panel on)
    # loads neither dumbbell.plot (and the analyses it draws) nor matplotlib, nor numba's
    # solvers, nor the scene reader and the trajectory's renderer.
    import subprocess
    import sys

    code = (
        "import sys, pymunk\n"
        "from dumbbell import spaces\n"
        "s = pymunk.Space(); s.gravity = (0, -9.8)\n"
        "b = pymunk.Body(1, 1); b.position = (0, 1); s.add(b, pymunk.Circle(b, 0.1))\n"
        f"with spaces.Recorder(s, {str(tmp_path / 'a.gif')!r}) as rec:\n"
        "    for _ in range(3):\n"
        "        s.step(0.04); rec.capture()\n"
        "print(' '.join(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib'\n"
        "      or m.startswith(('dumbbell.plot', 'dumbbell.analysis', 'dumbbell.solvers',\n"
        "                        'dumbbell.model.scene', 'dumbbell.animation.render')))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert (tmp_path / "a.gif").stat().st_size > 0
    assert out.stdout.split() == []


@pytest.mark.parametrize("g, units, unit, power", [
    # K at the end of 1 s of free fall: m (g t)^2 / 2, and U_g goes down as much.
    (900.0, "px", "kg px²/s²", 3),          # 8.1e5 kg px²/s²: ticks in 1e5
    (9e4, ("cm", "g", "s"), "g cm²/s²", 9),  # 8.1e9 g cm²/s²
    (9.8, "m", "J", 0),                      # 96 J: the labels as they are
    (9.8e-5, "m", "J", -9),                  # 9.6e-9 J
])
def test_the_strip_names_its_unit_and_its_tick_labels_fit_beside_it(tmp_path, g, units, unit,
                                                                     power):
    """A recorded space's strip: the energy unit above its axis (with the power of ten the
    tick labels are divided by), at least two ticks, and no tick label reaching the line
    between the picture and the energy panel."""
    from dumbbell.animation import recording as R
    from dumbbell.animation.painter import SS
    from dumbbell.animation.strip import LABEL_GAP, WHOLE_ENERGY_TICKS, tick_power

    space = pymunk.Space()
    space.gravity = (0.0, -g)
    ball = pymunk.Body(2.0, pymunk.moment_for_circle(2.0, 0, 10))
    ball.position = (0.0, 0.0)
    space.add(ball, pymunk.Circle(ball, 10))
    with spaces.Recorder(space, tmp_path / "a.gif", units=units) as rec:
        for _ in range(25):
            space.step(1 / 25)
            rec.capture()
    painter = R.painter_of(rec.recording())
    strip = painter.strip
    ticks = strip.scale.ticks(WHOLE_ENERGY_TICKS, least=2)
    assert strip.energy_axis == unit and len(ticks) >= 2
    assert tick_power(ticks) == power
    assert 10 ** power <= max(abs(v) for v in ticks) < 10 ** (power + 4)
    base = np.asarray(painter.base.reduce(SS).convert("L"))
    sx0, sy0, _, sy1 = strip.box
    # Ink above the strip's top left corner (the unit), and none in the gutter's left part
    # (the tick labels end LABEL_GAP from the strip and stay right of the separating line).
    above = base[sy0 - round(LABEL_GAP * strip.u) - 12:sy0 - 1, sx0:sx0 + 40]
    assert (above < 200).any()
    gutter = base[sy0:sy1, painter.scene_w + 2:painter.scene_w + 6]
    assert (gutter > 250).all()
    # The interactive player's page draws the same ticks and names the same axis.
    from dumbbell.animation.space_player import space_document

    labels, axis = strip.energy_ticks()
    assert axis.endswith(unit) and (axis.startswith("×10") == (power != 0))
    page = space_document(painter)["strip"]
    assert page["axis"] == axis and page["ticks"] == [list(t) for t in labels]
    assert [v for v, _ in labels] == ticks


@pytest.mark.parametrize("how", ["space.copy", "pickle", "copy.copy"])
@pytest.mark.parametrize("setting", ["plain", "energy", "follow"])
def test_a_recorder_kept_on_its_space_copies_and_pickles_frozen(tmp_path, how, setting):
    # A program keeps its recorder on the space (space.rec = ...): space.copy() and pickling
    # the space worked with a Ledger or a HeatCounter there, and failed with a Recorder
    # (pymunk's draw options hold C memory). The copy is what was captured so far: it does
    # not capture, and writes those frames; the original records on as if never copied.
    import copy
    import pickle

    def recorder(space, name):
        kw = {"energy": setting == "energy"}
        if setting == "follow":
            kw["camera"] = list(space.bodies)[-1]  # the ball
        return spaces.Recorder(space, tmp_path / name, fps=10, **kw)

    space, twin = _space(), _space()
    space.rec = recorder(space, "a.gif")
    alone = recorder(twin, "b.gif")

    def frame():
        for s in (space, twin):
            s.step(0.1)
        space.rec.capture()
        alone.capture()

    for _ in range(3):
        frame()
    other = {"space.copy": lambda: space.copy().rec,
             "pickle": lambda: pickle.loads(pickle.dumps(space)).rec,
             "copy.copy": lambda: copy.copy(space.rec)}[how]()
    assert other.frames == 4 and other.times == space.rec.times
    with pytest.raises(DumbbellError, match=r"a\.gif: this recorder is a copy"):
        other.capture()
    for _ in range(2):
        frame()
    space.rec.write()
    alone.write()
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()
    # The copy writes the four frames it holds: what the original wrote of them.
    other.path = tmp_path / "copy.gif"
    other.write()
    short = recorder(_space(), "short.gif")
    for _ in range(3):
        short.space.step(0.1)
        short.capture()
    short.write()
    assert other.frames == 4
    assert (tmp_path / "copy.gif").read_bytes() == (tmp_path / "short.gif").read_bytes()


@pytest.mark.parametrize("every", [1, 2, 3])
def test_the_note_names_every_body_drawn_larger_than_to_scale(tmp_path, every):
    # 14 balls 1,000 px apart in a row (y down, no gravity): at 640 px across, a ball of
    # 1 px radius is 0.09 px, one of 400 px is 36 px. Every ``every``-th ball is small and
    # drawn 4 px across: the note names each of them, however many (the names once stopped
    # at 8 and "3 more").
    space = pymunk.Space()
    small = []
    for i in range(14):
        body = pymunk.Body(1.0, 10.0)
        body.position = (1000.0 * i, 0.0)
        tiny = i % every == 0
        space.add(body, pymunk.Circle(body, 1.0 if tiny else 400.0))
        if tiny:
            small.append(i)
    with spaces.Recorder(space, tmp_path / "row.gif", fps=5, y_up=False) as rec:
        space.step(0.1)
        rec.capture()
    grown = rec.note.splitlines()[1]
    named = grown.split("across: ", 1)[1].split(" (", 1)[0]
    listed = set()
    for part in named.split(", "):
        if part.startswith("bodies "):
            a, b = map(int, part[len("bodies "):].split("-"))
            listed.update(range(a, b + 1))
        else:
            listed.add(int(part.removeprefix("body ")))
    assert listed == set(small)
    assert f"({len(small)} of 14 moving bodies;" in grown and "more" not in grown


@pytest.mark.parametrize("energy", [False, True])
def test_a_long_title_is_cut_short_beside_the_time_label(tmp_path, energy):
    # A title of 10,000 characters was drawn over the time label (overlap from about 45 on
    # 640x360). It is cut short with an ellipsis where the label's box ends: the label's
    # pixels are those of a recording without a title, and any title too long is cut at
    # the same place.
    def first_frame(title, name):
        space = _space()
        with spaces.Recorder(space, tmp_path / name, fps=10, title=title,
                             energy=energy) as rec:
            space.step(0.1)
            rec.capture()
        gif = Image.open(tmp_path / name)
        gif.seek(0)
        return np.asarray(gif.convert("RGB"))

    plain = first_frame("", "plain.gif")
    longest = first_frame("W" * 10_000, "long.gif")
    long = first_frame("W" * 200, "200.gif")
    assert np.array_equal(longest, long)  # cut at the same place
    assert not np.array_equal(longest, plain)  # and drawn
    label = (slice(0, 24), slice(0, 160))  # the time label's box at 640x360
    assert np.array_equal(longest[label], plain[label])


@pytest.mark.parametrize("title", ["two\nlines", "a\ttab", "bell\a"])
def test_a_title_of_more_than_one_line_is_refused(tmp_path, title):
    # A newline reached Pillow ("anchor not supported for multiline text") when the block
    # ended, as a traceback from inside the writer.
    with pytest.raises(UsageError, match=r"^title = .*: must be one line \(no newline"):
        spaces.Recorder(_space(), tmp_path / "t.gif", title=title)


def test_a_heat_counter_or_a_camera_of_another_space_is_refused(tmp_path):
    # The bars showed another space's heat (46,656 against 0), and the camera followed a
    # body no frame held.
    space, other = _space(), _space()
    with pytest.raises(UsageError, match=r"^heat: a HeatCounter of another space"):
        spaces.Recorder(space, tmp_path / "h.gif", energy=True, heat=spaces.HeatCounter(other))
    with pytest.raises(UsageError, match=r"^camera: the body to follow is not in the space"):
        spaces.Recorder(space, tmp_path / "c.gif", camera=list(other.bodies)[-1])
    with pytest.raises(UsageError, match=r"^camera: the body to follow is not in the space"):
        spaces.Recorder(space, tmp_path / "c.gif", camera=pymunk.Body(1.0, 1.0))
