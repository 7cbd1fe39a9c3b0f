"""GIF animations: timing read back from the file, pixels that follow the trajectory, bars
proportional to the energies, reproducible bytes, atomic writes and refused frame rates."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from PIL import Image, ImageSequence

from dumbbell.animation.painter import Painter
from dumbbell.animation.palette import INK, TERM_RGB
from dumbbell.animation.picture import describe
from dumbbell.animation.render import delays_cs, render_gif, sample_every
from dumbbell.animation.world import scene_painter
from dumbbell.cli import main
from dumbbell.model.scene import scene_from_dict
from dumbbell.model.trajectory import Trajectory
from dumbbell.solvers import simulate
from tests.conftest import SCENES, TEXTBOOK

SCENE = str(SCENES / "textbook-1d.toml")


@pytest.fixture(scope="module")
def short(textbook):
    """The textbook run to 1 s, sampled on the frame times of 25 fps."""
    return simulate(textbook, t_end=1.0, every=sample_every(textbook.run.dt, 25, 1.0))


@pytest.fixture(scope="module")
def frames(short, tmp_path_factory):
    """The textbook's first second as a 640x360 GIF, read back as RGB arrays."""
    path = tmp_path_factory.mktemp("gif") / "t.gif"
    render_gif(short, path, quiet=True, fps=25, size="640x360", t_end=1.0)
    with Image.open(path) as im:
        info = [(f.info.get("duration"), im.info.get("loop")) for f in ImageSequence.Iterator(im)]
        im.seek(0)
        arrays = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(im)]
    return path, info, arrays


def _mask(frame: np.ndarray, rgb: tuple[int, int, int]) -> np.ndarray:
    return np.all(frame == np.array(rgb, dtype=np.uint8), axis=2)


def test_frame_count_duration_and_loop_read_back(frames):
    _, info, arrays = frames
    assert len(arrays) == 25                      # 1 s at 25 fps: t = 0, 0.04, ..., 0.96
    assert all(d == 40 for d, _ in info)          # 1000/25 ms, exactly
    assert info[0][1] == 0                        # loop forever
    assert arrays[0].shape == (360, 640, 3)


def test_delays_keep_real_time_when_fps_does_not_divide_100():
    assert delays_cs(5, 25) == [4] * 5
    d = delays_cs(30, 30)
    assert set(d) == {3, 4}
    starts = np.cumsum([0, *d])
    assert np.all(np.abs(starts * 10 - np.arange(31) * 1000 / 30) <= 5)   # within 5 ms


def test_particle_height_follows_the_trajectory(frames, short):
    """B's drawn centre moves linearly with its height, and the floor's surface is one
    particle radius below height 0 (issue 29: the balls were drawn half inside the floor)."""
    _, _, arrays = frames
    t = np.arange(len(arrays)) / 25
    xB = np.interp(t, short.t, short["xB"])
    left = arrays[0].shape[1] * 3 // 10            # the scene panel (the red K_int bar is right)
    ys = []
    for frame in arrays:
        rows, _ = np.nonzero(_mask(frame[:, :left], TERM_RGB["B"]))
        ys.append(rows.mean())
    slope, intercept = np.polyfit(xB, ys, 1)
    assert slope < -100                             # up in metres is up on screen
    assert np.max(np.abs(np.polyval([slope, intercept], xB) - ys)) < 1.0   # px
    # The floor line (dark grey across the scene panel, clear of the dumbbell): the model's
    # floor is where the particle centres meet it (height 0), so its surface, the line's top
    # edge, is drawn one particle radius below: a particle that touches it sits on it.
    from dumbbell.animation.world import FLOOR_LINE

    darkness = 255.0 - arrays[0][:, left - 50:left - 10, 0].mean(axis=1)
    line = darkness > 60
    floor_y = (np.flatnonzero(line) * darkness[line]).sum() / darkness[line].sum()
    radius = short.scene.system.B.radius * -slope
    surface = intercept + radius
    assert abs(floor_y - (surface + FLOOR_LINE / 2)) < 1.0
    # No frame draws B inside the floor (its lowest drawn row at most the surface's).
    lowest = max(np.nonzero(_mask(f[:, :left], TERM_RGB["B"]))[0].max() for f in arrays)
    assert lowest <= surface + 0.5
    # Falling then bouncing: lowest drawn position right at the first impact (t = 0.4518 s).
    assert abs(t[int(np.argmax(ys))] - math.sqrt(2 / 9.8)) <= 0.04


def _bar_lengths(frame: np.ndarray, left: int, bottom: int) -> dict[str, int]:
    """Longest horizontal run (px) of each energy colour in the energy panel."""
    out = {}
    for name in ("K_cm", "K_int", "U_g", "U_spring"):
        m = _mask(frame[:bottom, left:], TERM_RGB[name])
        best = 0
        for row in m:
            if row.any():
                # longest run of consecutive True
                edges = np.diff(np.r_[0, row.view(np.int8), 0])
                starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
                best = max(best, int((stops - starts).max()))
        out[name] = best
    return out


def test_energy_bars_are_proportional_to_the_energies(frames, short):
    _, _, arrays = frames
    left = arrays[0].shape[1] * 3 // 10 + 20       # right of the scene panel and separator
    bottom = arrays[0].shape[0] // 2                # above the strip
    idx = np.searchsorted(short.t, np.arange(len(arrays)) / 25 - 1e-9)
    ratios = []
    for k in (0, 5, 11, 12, 14, 20):
        lengths = _bar_lengths(arrays[k], left, bottom)
        for name, px in lengths.items():
            value = float(short[name][idx[k]])
            if value > 0.3:                         # J; long enough to measure to 1 px
                ratios.append(px / value)
    assert len(ratios) >= 8
    # One fixed scale (px per J) for every bar in every frame, to the pixel.
    assert max(ratios) / min(ratios) < 1 + 3 / (0.3 * min(ratios))


def test_first_impact_moves_energy_from_k_cm_to_internal(frames, short):
    """Frame 11 (t = 0.44 s) is just before the first impact, frame 12 (0.48 s) just after:
    the K_cm bar collapses and the pale range of K_int since the last frame reaches ~E."""
    _, _, arrays = frames
    left, bottom = arrays[0].shape[1] * 3 // 10 + 20, arrays[0].shape[0] // 2
    before, after = _bar_lengths(arrays[11], left, bottom), _bar_lengths(arrays[12], left, bottom)
    assert before["K_cm"] > 100 and after["K_cm"] < 10
    pale = tuple(round(255 + (v - 255) * 5 / 15) for v in TERM_RGB["K_int"])
    before_pale = _mask(arrays[11][:bottom, left:], pale).sum()
    after_pale = _mask(arrays[12][:bottom, left:], pale).sum()
    assert before_pale == 0 and after_pale > 1000


def test_identical_inputs_give_identical_bytes(short, tmp_path):
    a, b = tmp_path / "a.gif", tmp_path / "b.gif"
    for path in (a, b):
        render_gif(short, path, quiet=True, fps=10, size="200x120", t_end=0.5)
    assert a.read_bytes() == b.read_bytes()


def test_failed_render_leaves_no_file(short, tmp_path, monkeypatch):
    calls = {"n": 0}
    original = Painter.frame

    def failing(self, k):
        calls["n"] += 1
        if calls["n"] > 3:
            raise RuntimeError("disk on fire")
        return original(self, k)

    monkeypatch.setattr(Painter, "frame", failing)
    with pytest.raises(RuntimeError):
        render_gif(short, tmp_path / "x.gif", quiet=True, fps=25, size="200x120", t_end=1.0)
    assert list(tmp_path.iterdir()) == []


def test_refused_fps_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "r.gif"
    assert main(["render", SCENE, "-o", str(out), "--fps", "60", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fps" in err[0] and "50" in err[0]
    assert list(tmp_path.iterdir()) == []


def test_render_command_end_to_end(tmp_path):
    out = tmp_path / "r.gif"
    assert main(["render", SCENE, "-o", str(out), "--t-end", "0.2", "--size", "160x90",
                 "--fps", "20", "--no-strip", "-q"]) == 0
    with Image.open(out) as im:
        assert im.size == (160, 90) and im.n_frames == 4
        assert im.info["duration"] == 50


def _synthetic_2d() -> Trajectory:
    """A 2D dumbbell turning at 2 rad/s about a centre of mass at (0.3, 0.5) m, no floor."""
    raw = {**TEXTBOOK, "dimensions": 2}
    raw["bodies"] = {"A": {"mass": 0.1, "height": 0.6, "x": 0.3},
                     "B": {"mass": 0.1, "height": 0.4, "x": 0.3}}
    raw.pop("floor")
    scene = scene_from_dict(raw, source="synthetic-2d.toml")
    t = np.linspace(0.0, 2.0, 201)
    phi = 2.0 * t
    ux, uy = np.sin(phi), np.cos(phi)
    w = 0.1 * 2.0
    state = {"xA": 0.3 + 0.1 * ux, "yA": 0.5 + 0.1 * uy, "vxA": w * uy, "vyA": -w * ux,
             "xB": 0.3 - 0.1 * ux, "yB": 0.5 - 0.1 * uy, "vxB": -w * uy, "vyB": w * ux}
    return Trajectory(scene, "synthetic", t, state)


def test_2d_drawing_keeps_the_aspect_ratio_and_follows_both_coordinates(tmp_path):
    traj = _synthetic_2d()
    assert traj["K_rot"][0] == pytest.approx(0.5 * 0.05 * 0.2**2 * 2.0**2)
    path = tmp_path / "s.gif"
    render_gif(traj, path, quiet=True, fps=10, size="640x360", t_end=2.0)
    with Image.open(path) as im:
        arrays = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(im)]
    assert len(arrays) == 20
    k = np.arange(20) * 10                           # samples every 0.01 s, frames every 0.1 s
    px, py = [], []
    for frame in arrays:
        rows, cols = np.nonzero(_mask(frame[:, :350], TERM_RGB["A"]))
        px.append(cols.mean())
        py.append(rows.mean())
    sx, _ = np.polyfit(traj["xA"][k], px, 1)
    sy, _ = np.polyfit(traj["yA"][k], py, 1)
    assert sx > 50 and sy < 0
    assert abs(sx + sy) / sx < 0.03                  # 1 m is as long in x as in y


def test_range_since_previous_frame_matches_brute_force():
    from dumbbell.animation.render import since_previous

    v = np.random.default_rng(1).random(50)
    idx = np.array([0, 0, 3, 7, 7, 8, 20, 49])     # frames may share a sample
    for ufunc, reduce in ((np.maximum, np.max), (np.minimum, np.min)):
        expected = [v[0]] + [reduce(v[a:b + 1]) for a, b in itertools.pairwise(idx)]
        assert np.array_equal(since_previous(v, idx, ufunc), expected)


def test_drawing_never_uses_the_index_kept_for_unchanged_pixels(short):
    """Index 255 marks 'unchanged' (transparent) in the GIF: a drawn pixel with it would show
    the previous frame's colour instead."""
    from dumbbell.animation.palette import palette
    from dumbbell.animation.render import frames_of

    frames = frames_of(short, 25, 1.0)
    painter = scene_painter(describe(short.scene, (frames,), (320, 180), True))
    clear = palette()[1]
    assert all(clear not in np.asarray(painter.frame(k)) for k in range(len(frames.t)))


def test_strip_scrolls_with_the_cursor_and_shows_the_energy_at_its_time(textbook):
    """Over 2 s the strip shows a window of strip.WINDOW s: the cursor walks in, then stays
    put while the curves scroll under it, and in every frame the U_g curve just left of the
    cursor is drawn at U_g of that column's time (so the window's time axis is right)."""
    from dumbbell.animation.render import frames_of
    from dumbbell.animation.strip import AHEAD, WINDOW

    traj = simulate(textbook, t_end=2.0, every=sample_every(textbook.run.dt, 25, 2.0))
    frames = frames_of(traj, 25, 2.0)
    painter = scene_painter(describe(textbook, (frames,), (640, 360), True))
    strip = painter.strip
    assert strip.window == WINDOW < 2.0
    sx0, sy0, sx1, sy1 = strip.box
    ink, brown = np.array(INK), np.array(TERM_RGB["U_g"])
    cursors = []
    for k in range(0, len(frames.t), 3):
        rgb = np.asarray(painter.frame(k).convert("RGB"))
        box = rgb[sy0 + 1:sy1, sx0 + 1:sx1]
        cols = np.flatnonzero(np.all(box == ink, axis=2).sum(axis=0) > 0.8 * box.shape[0])
        assert len(cols) > 0
        cursor = sx0 + 1 + int(cols.min())
        cursors.append((float(frames.t[k]), cursor))
        # The column 6 px left of the cursor shows the time 6 px earlier.
        x = cursor - 6
        t = float(frames.t[k]) - (cursor - x) / strip.px_per_s
        if t < 0.05:
            continue
        rows = np.flatnonzero(np.all(rgb[sy0 + 1:sy1, x] == brown, axis=1)) + sy0 + 1
        assert len(rows) > 0
        expected = strip.y(float(np.interp(t, traj.t, traj["U_g"])))
        assert abs(rows.mean() + 0.5 - expected) < 2.0, (t, rows, expected)
    walk = [(t, c) for t, c in cursors if t <= 0.7]
    still = {c for t, c in cursors if t >= 0.8 and t <= 2.0 - AHEAD - 0.05}
    slope = np.polyfit(*zip(*walk), 1)[0]
    assert abs(slope - strip.px_per_s) < 0.02 * strip.px_per_s   # walks at the strip's scale
    assert len(still) == 1                                             # then stays put


def test_printed_values_that_round_to_zero_have_no_minus_sign():
    from dumbbell.animation.bars import fixed

    assert fixed(-1e-17, 3) == "0.000" and fixed(-4e-4, 3) == "0.000"
    assert fixed(-1e-17, 4, "+") == "+0.0000" and fixed(-6e-5, 4, "+") == "-0.0001"
    # Everywhere else the text is Python's own fixed-point rounding of the value.
    rng = np.random.default_rng(7)
    for value in rng.normal(0.0, 1.0, 2000) * 10.0 ** rng.integers(-6, 3, 2000):
        for d in (0, 2, 3, 4):
            want = f"{value:.{d}f}".replace("-", "") if float(f"{value:.{d}f}") == 0 \
                else f"{value:.{d}f}"
            assert fixed(value, d) == want


def test_strip_marks_a_lasting_contact_along_its_foot_and_impacts_across_it(short):
    """A contact is a bar in the particle's colour at the strip's foot over its time span;
    an impact a faint line across the strip (and the contact none)."""
    import dataclasses

    from dumbbell.animation.render import frames_of
    from dumbbell.animation.strip import IMPACT
    from dumbbell.model.trajectory import Contact

    traj = dataclasses.replace(short, contacts=(Contact(0.2, 0.6, "B"), Contact(0.7, 1.0, "A")))
    frames = frames_of(traj, 25, 1.0)
    painter = scene_painter(describe(traj.scene, (frames,), (640, 360), True))
    strip = painter.strip
    last = len(frames.t) - 1
    rgb = np.asarray(painter.frame(last).convert("RGB"))  # the cursor at t = 0.96 s
    sx0, _, sx1, sy1 = strip.box
    cols = np.arange(sx0 + 2, sx1 - 1)
    t = (cols - strip.inner_x) / strip.px_per_s         # the window shows [0, 1] s

    def where(row: int, rgb_colour: tuple[int, int, int]) -> np.ndarray:
        return np.all(rgb[row, cols] == np.array(rgb_colour), axis=1)

    red, blue = where(sy1 - 1, TERM_RGB["B"]), where(sy1 - 2, TERM_RGB["A"])
    assert red[(t > 0.21) & (t < 0.59)].all() and not red[(t < 0.19) | (t > 0.61)].any()
    assert blue[(t > 0.71) & (t < 0.95)].all() and not blue[t < 0.69].any()
    # The impacts (the textbook's first two, before 0.6 s) cross the strip; B's bar does not.
    lines = t[where(strip.box[1] + 2, IMPACT)]           # above the curves (PAD)
    assert len(lines) and all(min(abs(x - e.t) for e in short.events) < 0.01 for x in lines)


def test_the_strip_draws_what_has_not_happened_yet_faded(short):
    """Issue 29: at t = 0 the strip showed the impact spike of 0.45 s in full colour. What
    lies after the cursor is drawn at opacity strip.FUTURE over white: at each frame no
    column after the cursor holds a term's full colour, every column before it is as drawn,
    and the curves ahead are still there, faded."""
    from dumbbell.animation.palette import blend
    from dumbbell.animation.render import frames_of
    from dumbbell.animation.strip import FUTURE

    frames = frames_of(short, 25, 1.0)
    painter = scene_painter(describe(short.scene, (frames,), (640, 360), True))
    strip = painter.strip
    sx0, sy0, sx1, sy1 = strip.box
    full = [np.array(TERM_RGB[n]) for n in ("K_cm", "K_int", "U_g", "U_spring")]
    faded = [np.array(blend(TERM_RGB[n], FUTURE)) for n in ("K_cm", "U_g")]
    for k in (0, 5, 11, 20):
        rgb = np.asarray(painter.frame(k).convert("RGB"))[sy0 + 1:sy1, sx0 + 1:sx1]
        cursor = round(float(frames.t[k]) * strip.px_per_s)     # the window starts at 0 s
        ahead, behind = rgb[:, cursor + 3:], rgb[:, :max(0, cursor - 2)]
        assert not any(np.all(ahead == c, axis=2).any() for c in full), k
        assert all(np.all(ahead == c, axis=2).any() for c in faded), k
        if k >= 11:  # past 0.44 s: K_cm's and U_g's curves drawn in full behind the cursor
            assert all(np.all(behind == c, axis=2).any() for c in full[::2]), k


def test_contact_checks_its_fields():
    from dumbbell.errors import UsageError
    from dumbbell.model.trajectory import Contact

    assert Contact(0.1, 0.4, "A").duration == pytest.approx(0.3)
    with pytest.raises(UsageError, match="body"):
        Contact(0.1, 0.4, "C")
    with pytest.raises(UsageError, match="t_end"):
        Contact(0.4, 0.1, "B")
    with pytest.raises(UsageError, match="t_start"):
        Contact(float("nan"), 0.1, "B")


@pytest.mark.parametrize("radius", [3.5, 8.0, 22.0])
def test_a_2d_particle_letter_stays_off_both_particles_and_above_the_floor(radius):
    """A dumbbell standing on the floor at every tilt from upright to lying (pixel rows grow
    downwards): each letter's box keeps off both discs and stays above the floor. Before, B's
    letter was pushed up from under the floor straight onto B when B was larger than the gap
    (the toppling dumbbell: r = 22 px at 640x360)."""
    from dumbbell.animation.world import letter_at

    floor_y, length, half, u = 300.0, 200.0, (4.0, 4.5), 1.0
    for deg in range(0, 91, 3):
        th = math.radians(deg)
        pb = (100.0, floor_y - radius)                       # B resting on the floor
        pa = (pb[0] + length * math.sin(th), pb[1] - length * math.cos(th))
        pc = ((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2)
        e = ((pa[0] - pb[0]) / length, (pa[1] - pb[1]) / length)
        for p, other, sign in ((pa, pb, 1), (pb, pa, -1)):
            x, y = letter_at(p, radius, other, (pc, (sign * e[0], sign * e[1])),
                             (floor_y, half, u))
            assert y + half[1] < floor_y, (deg, sign, y)
            for centre in (pa, pb):
                dx = max(abs(x - centre[0]) - half[0], 0.0)
                dy = max(abs(y - centre[1]) - half[1], 0.0)
                assert math.hypot(dx, dy) >= radius, (deg, sign, (x, y), centre)
