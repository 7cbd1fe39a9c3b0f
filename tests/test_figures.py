"""Every figure the commands draw is fit for a lecture: the figure checker (tests/figcheck.py)
finds no text on text, legends, lines or other data, no text cut at the figure's edge, no axes
squeezed by its legend, and every axis names its unit. The notebooks' figures are checked as
they run (tests/test_notebook.py).

Issue 29: each figure fits its canvas for any number of panels and any length of text (the
stability map of 1, 2 and 5 solvers; comparisons and benchmarks of 1, 2 and 5 solvers; a scene
title of 200 characters), and every figure drawn on the user's axes stays inside them (each of
a 1x2 grid, laid out by hand, by ``tight_layout`` and by constrained layout).

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
from tests.figcheck import outside_axes, problems

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


#: A scene title as long as a teacher's might be (200 characters).
LONG_TITLE = ("The bouncing dumbbell of section 13.5.1 with a spring ten times stiffer, dropped "
              "from a little higher than the book's, to show the class how the impacts feed "
              "the vibration")


@pytest.fixture(scope="module")
def map_rows_of():
    from dumbbell.analysis.stability import map_rows

    cache = {}

    def get(name: str):
        if name not in cache:
            cache[name] = map_rows(name, workers=1)
        return cache[name]
    return get


@pytest.mark.parametrize("count", [1, 2, 5])
def test_the_stability_map_fits_for_any_number_of_solvers(map_rows_of, count):
    """`dumbbell stability --solvers euler-cromer` drew one panel whose title was cut at both
    ends, whose y tick labels lost their first digit and whose colour bar's labels were cut.
    Five panels: the two solvers' rows again under longer names (the layout is what is
    tested)."""
    from dumbbell.plot.maps import stability_map

    names = ["euler-cromer", "verlet", "euler-cromer (its rows again, under a long name)",
             "verlet again", "euler-cromer once more"][:count]
    maps = {name: map_rows_of("verlet" if "verlet" in name else "euler-cromer")
            for name in names}
    panels = stability_map(maps)
    fig = panels[0].figure
    assert_fit(fig)
    # Every y tick label whole: 10^0 .. 10^4 on each panel, as drawn.
    for ax in panels:
        shown = [t.get_text() for t in ax.get_yticklabels()
                 if ax.get_ylim()[0] <= t.get_position()[1] <= ax.get_ylim()[1]]
        assert {"$\\mathdefault{10^{0}}$", "$\\mathdefault{10^{4}}$"} <= set(shown)


@pytest.mark.parametrize("solvers", [["euler-cromer"], ["euler-cromer", "pymunk"],
                                     ["euler-cromer", "verlet", "pymunk", "reference", "exact"]],
                         ids=["1", "2", "5"])
def test_compare_figures_of_any_number_of_solvers(textbook, solvers):
    from dumbbell import compare, plot

    result = compare(textbook.with_values({"title": LONG_TITLE}), solvers=solvers, dts=[1e-4],
                     t_end=0.6, window=0.3)
    for draw in (plot.compare_positions, plot.compare, plot.compare_energy):
        assert_fit(draw(result).figure)


@pytest.mark.parametrize("solvers", [["euler-cromer"], ["euler-cromer", "verlet"],
                                     ["euler-cromer", "verlet", "pymunk", "reference", "exact"]],
                         ids=["1", "2", "5"])
def test_bench_figures_of_any_number_of_solvers(textbook, solvers):
    from dumbbell import bench
    from dumbbell.plot.bench import convergence, work_precision

    result = bench(textbook, solvers=solvers, dts=[1e-3, 3.2e-4, 1e-4], window=0.3, t_end=0.3,
                   repeat=1)
    assert_fit(work_precision(result).figure)
    assert_fit(convergence(result).figure)


def test_a_long_scene_title_fits(textbook):
    from dumbbell import plot, simulate

    traj = simulate(textbook.with_values({"title": LONG_TITLE}), "exact", t_end=2.0, every=50)
    for draw in (plot.positions, plot.kinetic, plot.potential, plot.energy):
        fig = draw(traj).figure
        assert_fit(fig)
        assert "\n" in fig.get_suptitle()         # wrapped, not cut


@pytest.mark.parametrize("grid", ["k=log:1e2:1e7:8 dt=log:1e-6:1e-2:8",
                                  "k=log:1e2:1e7:10 dt=log:1e-6:1e-2:10",
                                  "dt=log:1e-6:1e-2:5 k=log:3e2:1e6:7"], ids=["8x8", "10x10", "5x7"])
def test_the_stability_line_of_a_sweep_map_is_straight(textbook, grid):
    """On log axes w*dt = 2 is the straight line dt = 2 sqrt(mu / k): drawn as such on any
    grid, out to the map's edges (the contour of the cell centres kinked at each decade and
    stopped half a cell short)."""
    import numpy as np

    from dumbbell import sweep
    from dumbbell.plot.maps import sweep_map

    result = sweep(textbook, grid.split(), solver="euler-cromer", t_end=0.05, workers=1,
                   processes=False)
    ax = sweep_map(result)
    fig = ax.figure
    fig.draw_without_rendering()
    red = [line for line in ax.get_lines() if line.get_color() == "red"]
    assert len(red) == 1
    x, y = red[0].get_xdata(), red[0].get_ydata()
    k_axis = 0 if grid.startswith("k") else 1
    k, dt = (x, y) if k_axis == 0 else (y, x)
    mu = 0.5 * textbook.system.A.mass * textbook.system.B.mass / (
        0.5 * (textbook.system.A.mass + textbook.system.B.mass))
    # Every vertex on the exact line (w = sqrt(k / mu)), and straight as drawn (px).
    assert np.allclose(np.sqrt(k / mu) * dt, 2.0, rtol=1e-9)
    px = ax.transData.transform(np.column_stack([x, y]))
    d = px[-1] - px[0]
    rel = px - px[0]
    off = np.abs(d[0] * rel[:, 1] - d[1] * rel[:, 0]) / np.hypot(*d)
    assert off.max() < 0.01
    # From edge to edge of the map: each end on the frame (or past its corner, clipped).
    frame = ax.get_window_extent()
    for end in (px[0], px[-1]):
        assert min(abs(end[0] - frame.x0), abs(end[0] - frame.x1), abs(end[1] - frame.y0),
                   abs(end[1] - frame.y1)) < 0.5
    assert_fit(fig)


@pytest.fixture(scope="module")
def user_inputs():
    from dumbbell import bench, compare, sweep
    from dumbbell.analysis.contact import about_contact
    from dumbbell.analysis.rotation import series

    one = load_scene(SCENES / "textbook-1d.toml")
    two = load_scene(SCENES / "tilted-2d.toml")
    rigid = load_scene(SCENES / "rigid-2d.toml")
    return {
        "traj1": simulate(one, "exact", t_end=2.0, every=50),
        "traj2": simulate(two, "verlet", t_end=2.0, dt=1e-4, every=10),
        "compare": compare(one, solvers=["euler-cromer", "verlet", "pymunk", "reference"],
                           dts=[1e-4], t_end=0.6, window=0.3),
        "bench": bench(one, solvers=["euler-cromer", "verlet", "pymunk"], dts=[1e-3, 1e-4],
                       window=0.3, t_end=0.3, repeat=1),
        "map": sweep(one, ["k=log:1e2:1e7:6", "dt=log:1e-6:1e-2:6"], solver="euler-cromer",
                     t_end=0.05, workers=1, processes=False),
        "line": sweep(one, ["dt=log:1e-5:1e-2:5"], solver="euler-cromer", t_end=0.05,
                      workers=1, processes=False),
        "rotation": series(two, solver="verlet", dt=1e-4, t_end=0.6),
        "contact": about_contact(simulate(rigid, t_end=0.6, dt=1e-4)),
    }


#: Pairs of figures drawn side by side on a 1x2 grid of the user's axes.
PAIRS = [("kinetic", "traj1", "potential", "traj1"), ("positions", "traj2", "energy", "traj2"),
         ("kinetic", "traj2", "energy", "traj1"), ("compare", "compare", "compare_positions",
                                                   "compare"),
         ("compare_energy", "compare", "work_precision", "bench"),
         ("convergence", "bench", "sweep_map", "line"), ("sweep_map", "map", "rotation",
                                                         "rotation"),
         ("contact_momentum", "contact", "kinetic", "traj1")]


@pytest.mark.parametrize("layout", ["by hand", "tight", "constrained"])
@pytest.mark.parametrize("pair", PAIRS, ids=[f"{a}-{b}-{c}-{d}" for a, b, c, d in PAIRS])
def test_figures_on_a_1x2_grid_of_the_users_axes_stay_inside_them(user_inputs, pair, layout):
    """Issue 29: kinetic beside potential on a 1x2 figure put each legend outside its axes
    and squeezed each plot to about a third of its width. On the user's axes a figure keeps
    its legend and texts inside its axes (a legend in a band above the data), whatever layout
    the user applies after."""
    from dumbbell import plot

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2),
                             layout="constrained" if layout == "constrained" else None)
    for ax, (name, data) in zip(axes, [pair[:2], pair[2:]], strict=True):
        assert getattr(plot, name)(user_inputs[data], ax=ax) is ax
    if layout == "tight":
        fig.tight_layout()
    assert_fit(fig)
    for ax in axes:
        outside = [str(f) for f in outside_axes(ax, draw=False)]
        assert outside == [], outside
        if ax.get_legend() is not None and pair[0] != "sweep_map":
            assert ax.get_legend().get_window_extent().y0 >= ax.get_window_extent().y0


def test_the_band_above_the_data_follows_the_users_layout(user_inputs):
    """The legend's band is fitted again to the size the axes is drawn at: a grid made much
    shorter after the figure was drawn keeps its curves out of the legend; limits the user
    sets themselves are kept."""
    from dumbbell import plot

    fig, axes = plt.subplots(1, 2, figsize=(11, 6))
    plot.kinetic(user_inputs["traj1"], ax=axes[0])
    plot.potential(user_inputs["traj1"], ax=axes[1])
    assert_fit(fig)
    fig.set_size_inches(11, 3.2)
    fig.tight_layout()
    assert_fit(fig)
    axes[1].set_ylim(-1, 5)
    fig.draw_without_rendering()
    assert axes[1].get_ylim() == (-1, 5)
