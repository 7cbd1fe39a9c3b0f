"""A recording's energy bars keep off their names (issue 29: a negative ΔU_spring bar painted
over the "g" of its own label)."""

from __future__ import annotations

import numpy as np
import pymunk
import pytest
from PIL import Image, ImageSequence

from dumbbell import spaces
from dumbbell.animation.bars import SPACE_INKS as TERM_INKS


def _stretched_spring(path, reference="start", size="640x360"):
    """A ball on a stretched spring swinging under gravity: ΔU_spring and ΔU_g go well below
    zero, so the scale's low end is a negative bar reaching the bars' left end."""
    space = pymunk.Space()
    space.gravity = (0, -9.8)
    ball = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    ball.position = (0.8, 0)
    space.add(ball, pymunk.Circle(ball, 0.1))
    space.add(pymunk.DampedSpring(space.static_body, ball, (0, 0), (0, 0), 0.3, 50.0, 0.0))
    with spaces.Recorder(space, path, size=size, reference=reference) as rec:
        for _ in range(25):
            spaces.step(space, 1 / 25, substeps=20)
            rec.capture()
    return rec


@pytest.mark.parametrize("size", ["640x360", "320x180", "1280x720"])
def test_a_negative_bar_never_reaches_its_name(tmp_path, size):
    """In every frame, the bars' left end (where the most negative value of the whole
    recording reaches) lies right of every name's ink: ΔU_spring's and ΔU_g's bars, which
    reach it here, included."""
    path = tmp_path / "spring.gif"
    _stretched_spring(path, size=size)
    with Image.open(path) as im:
        frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(im)]
    W = frames[0].shape[1]
    x0 = round(0.56 * W)                            # the energy panel's left edge
    colours = {name: np.array(TERM_INKS[name]) for name in ("U_g", "U_spring")}
    starts: dict[str, list[int]] = {name: [] for name in colours}
    names_end = 0
    for frame in frames:
        part = frame[:, x0:]
        for name, rgb in colours.items():
            hits = np.all(part == rgb, axis=2)
            rows = np.flatnonzero(hits.sum(axis=1) > 0)
            run = rows[:np.flatnonzero(np.diff(rows) > 1)[0] + 1] if np.any(np.diff(rows) > 1) \
                else rows                               # the bar's row (the strip is below)
            band = slice(run[0], run[-1] + 1)
            cols = np.flatnonzero(hits[band].any(axis=0))
            swatch = cols[0]                          # the swatch: the row's first colour
            after = cols[cols > swatch + 20]
            if not len(after):
                continue
            starts[name].append(after[0])
            # The name's ink: dark pixels between the swatch and the bar.
            dark = np.flatnonzero((part[band].max(axis=2) < 140).any(axis=0))
            names_end = max(names_end, dark[(dark > swatch) & (dark < after[0])].max())
    low = min(min(v) for v in starts.values())  # the bars' left end: the lowest value's
    assert names_end < low, (size, names_end, low)
    # ... and a negative bar comes near the names (so the check above means something).
    assert low - names_end <= 0.03 * W, (size, names_end, low)
