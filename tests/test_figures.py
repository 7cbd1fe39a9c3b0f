"""Every figure the commands draw is fit for a lecture: the figure checker (tests/figcheck.py)
finds no text on text, legends or lines, and every axis names its unit. The notebooks' figures
are checked as they run (tests/test_notebook.py).

Each figure is drawn by the same code and at the same size as its command draws it
(``dumbbell run``'s own figure function, and the plot functions ``compare``, ``bench``,
``stability``, ``sweep`` and ``restitution`` call), from scenes the commands are run on. To keep
the suite fast the inputs are lighter than the shipped renders' (pymunk at dt = 1e-4 s, fewer
grid points and tilts, shorter runs): the layouts do not depend on them, since legends sit
outside the axes and notes outside the data. ``DUMBBELL_FIGCHECK=shipped pytest
tests/test_figures.py`` draws them from exactly the shipped commands' inputs instead (7 minutes
on 2 busy cores, most of it the full bench).
"""

from __future__ import annotations

import os

import pytest

from dumbbell import load_scene, simulate
from tests.conftest import SCENES
from tests.figcheck import problems

plt = pytest.importorskip("matplotlib.pyplot")

SHIPPED = os.environ.get("DUMBBELL_FIGCHECK") == "shipped"
#: What each figure of ``dumbbell run`` shows of the run (s): the energy figures show the
#: textbook's 2 s window; the topple ends at the landing (0.41 s).
SHOWN = {"topple": 0.5}


@pytest.fixture(autouse=True)
def close_all():
    yield
    plt.close("all")


def assert_fit(fig) -> None:
    found = problems(fig)
    assert found == [], "\n".join(found)


def _run_cases() -> list[tuple[str, str]]:
    """(scene, figure) for every figure a shipped scene's [outputs] asks for."""
    return [(path.stem, name) for path in sorted(SCENES.glob("*.toml"))
            for name in load_scene(path).outputs.figures]


@pytest.fixture(scope="module")
def runs():
    cache = {}

    def get(name: str, t_end: float):
        if (name, t_end) not in cache:
            scene = load_scene(SCENES / f"{name}.toml")
            light = not SHIPPED and scene.run.solver == "pymunk"
            cache[name, t_end] = simulate(scene, t_end=min(t_end, scene.run.t_end),
                                          dt=1e-4 if light else None)
        return cache[name, t_end]
    return get


def test_every_shipped_figure_is_checked():
    cases = _run_cases()
    assert {name for _, name in cases} >= {"positions", "kinetic", "potential", "energy",
                                          "rotation", "contact", "topple"}


@pytest.mark.parametrize("scene,name", _run_cases(), ids=[f"{s}-{n}" for s, n in _run_cases()])
def test_run_figures(runs, scene, name):
    from dumbbell.cli.run import _figure

    ax = _figure(name, runs(scene, SHOWN.get(name, 2.0)))
    assert_fit(ax.figure)


@pytest.mark.parametrize("scene", ["textbook-1d", "tilted-2d", "rigid-2d", "topple-2d"] if SHIPPED
                         else ["textbook-1d", "tilted-2d"])
def test_compare_figures(scene):
    from dumbbell import compare, plot

    s = load_scene(SCENES / f"{scene}.toml")
    result = (compare(s) if SHIPPED
              else compare(s, dts=[1e-4], t_end=min(3.0, s.run.t_end)))
    for draw in (plot.compare_positions, plot.compare, plot.compare_energy):
        assert_fit(draw(result).figure)


def test_bench_figures(textbook):
    from dumbbell import bench
    from dumbbell.plot.bench import convergence, work_precision

    result = (bench(textbook) if SHIPPED
              else bench(textbook, solvers=["euler-cromer", "verlet", "pymunk", "exact"],
                         dts=[1e-3, 3.2e-4, 1e-4], window=1.0, t_end=1.0, repeat=1))
    assert_fit(work_precision(result).figure)
    assert_fit(convergence(result).figure)


def test_stability_map():
    from dumbbell.analysis.stability import map_rows, map_solvers
    from dumbbell.plot.maps import stability_map

    # pymunk's panel is drawn as the others are; it is the slow one to compute.
    names = map_solvers(None) if SHIPPED else ["euler-cromer", "verlet"]
    maps = {name: map_rows(name, workers=1) for name in names}
    assert_fit(stability_map(maps)[0].figure)


@pytest.mark.parametrize("grid", [("k=log:1e2:1e7:50", "dt=log:1e-6:1e-2:50"),
                                  ("dt=log:1e-5:1e-2:8",)], ids=["map", "line"])
def test_sweep_figures(textbook, grid):
    from dumbbell import sweep
    from dumbbell.plot.maps import sweep_map

    if not SHIPPED:
        grid = tuple(g.replace(":50", ":8") for g in grid)
    result = sweep(textbook, list(grid), solver="euler-cromer", t_end=1.0 if SHIPPED else 0.2,
                   workers=1, processes=False)
    assert_fit(sweep_map(result).figure)


@pytest.mark.parametrize("elasticity", [1.0, 0.5])
def test_restitution_figure(elasticity):
    from dumbbell.analysis.restitution import restitution
    from dumbbell.plot.rotation_chapter import restitution as draw

    scene = load_scene(SCENES / "tilted-2d.toml").with_values(
        {"floor.elasticity": elasticity})
    thetas = [0, 30, 45, 60, 80] if SHIPPED else [0, 60]
    result = restitution(scene, thetas, (200.0, 2e3, 2e4), 1e-5 if SHIPPED else 1e-4)
    assert_fit(draw(result)[0].figure)


def test_the_energy_figure_of_a_1d_scene(runs):
    """Not in a shipped scene's [outputs], but asked for by name in any scene's."""
    from dumbbell import plot

    assert_fit(plot.energy(runs("textbook-1d", 2.0)).figure)


def test_the_rotation_preview_keeps_every_curve_inside_its_panel():
    """The panels share one energy scale; over the notebook's 1 s window the rigid panel's K_cm
    (1.96 J just before the first impact: M g times the centre of mass's 1 m drop) peaks above
    every run's internal energy, and the scale must still hold it (it was cut off at 1.88 J)."""
    import numpy as np

    from dumbbell import plot
    from dumbbell.analysis.rotation import series

    preview = series(load_scene(SCENES / "tilted-2d.toml"), solver="verlet", t_end=1.0)
    fig = plot.rotation(preview).figure
    energy_panels = [ax for ax in fig.axes if ax.get_ylabel() == "E [J]"]
    assert len(energy_panels) == len(preview.runs)
    for ax in energy_panels:
        bottom, top = ax.get_ylim()
        for line in ax.get_lines():
            y = np.asarray(line.get_ydata(), float)
            assert bottom <= y.min() and y.max() <= top, (ax.get_title(), line.get_label())
    rigid = preview.runs["rigid"]
    # M g h: 0.2 kg x 9.8 m/s² x 1 m of free fall before the first impact, to within what one
    # sample (0.2 ms) before it misses: M g v dt_sample = 0.2 x 9.8 x 4.43 x 2e-4 = 1.7e-3 J.
    assert abs(float(np.max(rigid["K_cm"])) - 0.2 * 9.8 * 1.0) < 2e-3
    assert_fit(fig)
