"""spaces.Recorder: frames, timing and loop read back from the GIF; MP4 frame count; same bytes
for the same captures; nothing written when the block fails."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pymunk
import pytest
from PIL import Image

from dumbbell import spaces


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
    with pytest.raises(UsageError, match=r"\.gif or \.mp4"):
        spaces.Recorder(_space(), tmp_path / "a.png")
    with pytest.raises(DumbbellError, match="no frames"), spaces.Recorder(_space(),
                                                                         tmp_path / "a.gif"):
        pass
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
