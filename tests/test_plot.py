"""dumbbell.plot: every figure draws on the axes it is given (or its own), returns the axes,
never picks a matplotlib backend and never writes a file."""

from __future__ import annotations

import matplotlib
import matplotlib.figure
import pytest

from dumbbell import load_scene, plot, simulate
from dumbbell.analysis.bench import BenchOptions, run_bench
from dumbbell.analysis.compare import CompareOptions, compare
from dumbbell.analysis.rotation import series
from dumbbell.analysis.sweep import SweepOptions, parse_axis, run_sweep
from tests.conftest import SCENES

plt = pytest.importorskip("matplotlib.pyplot")


@pytest.fixture(autouse=True)
def no_side_effects(monkeypatch):
    """Plotting must neither switch the backend (a notebook's) nor save anything."""

    def refuse(*args, **kwargs):
        raise AssertionError("a plot function must not do this")

    monkeypatch.setattr(matplotlib, "use", refuse)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", refuse)
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def results():
    one_d = load_scene(SCENES / "textbook-1d.toml")
    two_d = load_scene(SCENES / "tilted-2d.toml")
    return {
        "traj1": simulate(one_d, "euler-cromer", t_end=0.5, every=10),
        "traj2": simulate(two_d, "verlet", t_end=0.5, dt=1e-4, every=10),
        "compare": compare(one_d, CompareOptions(["euler-cromer", "verlet"], dts=[1e-4],
                                                 t_end=0.5, window=0.3)),
        "bench": run_bench(one_d, BenchOptions(solvers=["euler-cromer", "verlet"],
                                               dts=[1e-3, 1e-4], window=0.3, t_end=0.3,
                                               repeat=1)),
        "sweep": run_sweep(one_d, [parse_axis("k=log:100:1000:2"),
                                   parse_axis("dt=lin:1e-4:2e-4:2")],
                           SweepOptions("euler-cromer", 0.2, workers=1, processes=False)),
        "rotation": series(two_d, solver="verlet", dt=1e-4, t_end=0.3),
    }


CASES = [("positions", "traj1"), ("kinetic", "traj1"), ("potential", "traj1"),
         ("energy", "traj1"), ("positions", "traj2"), ("kinetic", "traj2"),
         ("energy", "traj2"), ("compare", "compare"), ("compare_positions", "compare"),
         ("compare_energy", "compare"), ("work_precision", "bench"), ("convergence", "bench"),
         ("sweep_map", "sweep"), ("rotation", "rotation")]


@pytest.mark.parametrize("name,data", CASES, ids=[f"{n}-{d}" for n, d in CASES])
def test_draws_on_the_given_axes_and_returns_them(results, name, data):
    fig, ax = plt.subplots()
    assert getattr(plot, name)(results[data], ax=ax) is ax
    assert ax.has_data() and ax.figure is fig and len(fig.axes) >= 1


@pytest.mark.parametrize("name,data", CASES, ids=[f"{n}-{d}" for n, d in CASES])
def test_without_axes_makes_its_own_figure(results, name, data):
    before = set(plt.get_fignums())
    ax = getattr(plot, name)(results[data])
    assert ax.has_data() and ax.figure.number not in before
