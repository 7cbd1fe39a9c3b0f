"""The dumbbell's pymunk solver takes its energy columns from spaces' general accounting, and
dumbbell stability reports the step-size guard on its runs."""

from __future__ import annotations

import numpy as np
import pytest

from dumbbell.analysis.stability import guard_lines
from dumbbell.model.energy import energy_columns, energy_scale, partition
from dumbbell.model.scene import load_scene, scenes_dir
from dumbbell.solvers import METHODS, simulate

SCENES = sorted(p.name for p in scenes_dir().glob("*.toml")) + [
    f"extreme/{n}" for n in ("high-drop.toml", "zero-gravity.toml", "mass-ratio-100.toml",
                             "inelastic-floor.toml", "zero-rest-length.toml")]


@pytest.mark.parametrize("name", SCENES)
def test_pymunk_energy_columns_equal_the_partition(name):
    scene = load_scene(scenes_dir() / name)
    traj = simulate(scene, "pymunk", t_end=min(scene.run.t_end, 0.5))
    general = traj.energy           # from dumbbell.spaces.accounting on pymunk's own bodies
    own = partition(traj.scene, traj.t, traj.state, traj.events)  # model/energy.py's formulas
    assert list(general) == list(own) == energy_columns(scene)
    scale = energy_scale(float(own["E"][0]),
                         {k: float(v[0]) for k, v in own.items() if k not in ("E", "E_lost")})
    for column in own:
        assert np.max(np.abs(general[column] - own[column])) <= 1e-12 * scale, column


@pytest.mark.parametrize("spin", [False, True])
def test_variants_rigid_and_spinning(spin):
    for name in ("tilted-2d.toml", "rigid-2d.toml"):
        scene = load_scene(scenes_dir() / name).with_values({"pymunk.spin": spin})
        traj = simulate(scene, "pymunk", t_end=0.3)
        own = partition(traj.scene, traj.t, traj.state, traj.events)
        scale = abs(float(own["E"][0]))
        for column in own:
            assert np.max(np.abs(traj.energy[column] - own[column])) <= 1e-12 * scale


def test_soft_spring_pymunk_conserves_its_own_spring_energy():
    # Once A passes B, pymunk's spring acts on the distance |xA - xB| - b; the 1D scene's on
    # the signed stretch. The accounting measures the spring pymunk has: its E holds.
    scene = load_scene(scenes_dir() / "extreme" / "soft-spring.toml")
    traj = simulate(scene, "pymunk", every=10)
    assert np.min(traj["xA"] - traj["xB"]) < -0.1  # A did pass B
    E, E_1d = traj["E"], partition(traj.scene, traj.t, traj.state, traj.events)["E"]
    assert np.ptp(E) / E[0] < 1e-3
    assert np.ptp(E_1d) / E_1d[0] > 0.1


def test_stability_reports_the_guard_on_pymunk_runs():
    extreme = scenes_dir() / "extreme"
    runs = [(str(extreme / n), METHODS[s]) for n in ("high-drop.toml", "stiff-wdt-2.1.toml",
                                                     "zero-gravity.toml")
            for s in ("pymunk", "exact")]
    lines = guard_lines(runs)
    assert len(lines) == 3
    drop, stiff, zero = lines
    assert "high-drop" in drop and "tunnelling" in drop and "sub-steps" in drop
    assert "stiff-wdt-2.1" in stiff and "spring DampedSpring 0 2.1 > 2" in stiff
    assert zero.endswith("nothing to fix")
