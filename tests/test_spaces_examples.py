"""The examples run with one command each, write a GIF and print the guard's report; their
physics against closed forms."""

from __future__ import annotations

import math

import pytest
from PIL import Image

from dumbbell.examples import newtons_cradle, pendulum, slope


@pytest.mark.parametrize("module, seconds", [(newtons_cradle, 1.2), (pendulum, 1.2),
                                             (slope, 0.8)])
def test_example_writes_a_gif_and_prints_the_guard(tmp_path, capsys, module, seconds):
    out = tmp_path / "out.gif"
    assert module.main(["--out", str(out), "--seconds", str(seconds)]) == 0
    text = capsys.readouterr().out
    assert "step-size guard at dt = 0.04 s" in text and "step-size guard at dt = 0.001 s" in text
    assert f"wrote {out}" in text
    with Image.open(out) as im:
        assert im.n_frames == round(seconds * 25) + 1


def test_pendulum_period_matches_the_small_angle_formula():
    m = pendulum.measure(1e-3, 6.0)
    assert m["periods"] >= 4
    assert m["period"] == pytest.approx(pendulum.small_angle_period(), rel=2e-4)
    # The first finite-amplitude correction accounts for what is left.
    assert m["period"] == pytest.approx(pendulum.amplitude_corrected_period(), rel=2e-6)


def test_cradle_passes_momentum_and_keeps_energy_to_first_order():
    coarse = newtons_cradle.measure(1e-3, 2.0)
    fine = newtons_cradle.measure(1e-4, 2.0)
    assert fine["energy_drift_max"] < 0.2 * coarse["energy_drift_max"]
    assert fine["energy_drift_max"] < 5e-3
    assert fine["momentum_change_max"] < 0.05


def test_slope_heat_closes_the_balance_to_first_order():
    coarse, fine = slope.measure(1e-3, 1.0), slope.measure(1e-4, 1.0)
    for m in (coarse, fine):
        assert m["heat"] > 3.0 and m["distance"] > 0.5
    left = [abs(m["E0"] - m["E"] - m["heat"]) / m["heat"] for m in (coarse, fine)]
    assert left[1] < 2e-4 and 5 < left[0] / left[1] < 20
    assert not math.isnan(left[0])
