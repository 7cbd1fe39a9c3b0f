"""Every result type shows itself: ``repr`` one line of at most 200 characters (a summary,
never the data, however large the result), and ``_repr_html_`` that line above a table for
notebooks. ``traj.to_csv(path)`` writes what ``dumbbell simulate -o`` writes."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import shutil

import numpy as np
import pytest

import dumbbell
from dumbbell._display import MAX_REPR, MAX_ROWS, one_line
from tests.conftest import SCENES

#: Records that are parts of a result (a row, an impact, a fit), shown by the result that
#: holds them, and the inputs of an analysis.
PARTS = {"Impact", "Verdict", "Point", "Fit", "PointResult", "StabilityRow", "Prediction",
         "Axis", "Timing", "Contact",
         # the analyses' options records: what a run is asked, not what it gives
         "CompareOptions", "BenchOptions", "SweepOptions", "StabilityOptions"}


def public_dataclasses() -> set[str]:
    """The public dataclasses of the model's trajectory module and of every analysis module."""
    names = set()
    modules = ["dumbbell.model.trajectory", *(f"dumbbell.analysis.{m}"
                                              for m in dumbbell.analysis.__all__)]
    for name in modules:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", []):
            obj = getattr(module, attr)
            if inspect.isclass(obj) and dataclasses.is_dataclass(obj):
                names.add(obj.__name__)
    return names


@pytest.fixture(scope="module")
def results(textbook, tmp_path_factory):
    """One of each result type, from small runs."""
    from dumbbell.analysis.contact import about_contact
    from dumbbell.analysis.restitution import bounce, restitution, tilted
    from dumbbell.analysis.rotation import series
    from dumbbell.analysis.topple import closed_form, measure

    tilted_2d = dumbbell.load_scene(SCENES / "tilted-2d.toml")
    topple = dumbbell.load_scene(SCENES / "topple-2d.toml")
    rigid = dumbbell.load_scene(SCENES / "rigid-2d.toml")
    traj = dumbbell.simulate(textbook, t_end=1.0, every=100)
    cases = tmp_path_factory.mktemp("cases")
    shutil.copy(SCENES / "extreme" / "stiff-wdt-2.1.toml", cases)
    rigid_run = dumbbell.simulate(rigid, "exact", dt=1e-4, t_end=0.6)
    drop = dumbbell.simulate(tilted(rigid, 30.0), "exact", dt=1e-4, t_end=0.6)
    comparison = dumbbell.compare(textbook, solvers=["euler-cromer"], dts=1e-3, t_end=1.0,
                                  window=1.0)
    return {
        "Trajectory": traj,
        "Gif": dumbbell.render_gif(traj, fps=5, size="160x90", t_end=0.4),
        "Comparison": comparison,
        "Row": comparison.rows[0],
        "BenchResult": dumbbell.bench(textbook, solvers=["euler-cromer"], dts=[1e-3, 1e-4],
                                      repeat=1, t_end=1.0, window=1.0),
        "SweepResult": dumbbell.sweep(textbook, {"k": [1e2, 1e6], "dt": [1e-3]}, t_end=0.5),
        "StabilityResult": dumbbell.stability(cases, solvers=["euler-cromer"], workers=1),
        "RestitutionResult": restitution(tilted_2d, [0.0, 30.0], (2e3,), 1e-4),
        "Bounce": bounce(drop),
        "ToppleClosedForm": closed_form(topple),
        "ToppleMeasure": measure(dumbbell.simulate(topple, "pymunk", dt=1e-4, t_end=0.6)),
        "ContactMomentum": about_contact(rigid_run),
        "Series": series(tilted_2d, dt=1e-4, t_end=0.2),
    }


def test_every_result_type_is_covered(results):
    assert public_dataclasses() - PARTS == set(results) - {"Gif"}


@pytest.mark.parametrize("name", ["Trajectory", "Gif", "Comparison", "Row", "BenchResult",
                                  "SweepResult", "StabilityResult", "RestitutionResult",
                                  "Bounce", "ToppleClosedForm", "ToppleMeasure",
                                  "ContactMomentum", "Series"])
def test_repr_is_one_short_line_and_html_a_table(results, name):
    result = results[name]
    text = repr(result)
    assert "\n" not in text and len(text) <= MAX_REPR, text
    assert text.startswith("<") and text.endswith(">") and type(result).__name__ in text
    html = result._repr_html_()
    assert isinstance(html, str) and html.startswith("<")
    if name != "Gif":
        assert "<table>" in html and html.count("<tr>") >= 2


def test_reprs_say_what_was_measured(results):
    # The numbers in the summaries are the results' own.
    comparison = results["Comparison"]
    assert f"euler-cromer {comparison.rows[0].window_error:.3g} m" in repr(comparison)
    stability = results["StabilityResult"]
    assert repr(stability).startswith("<StabilityResult: 1 run of 1 case, 1 agree")
    sweep = results["SweepResult"]
    assert "2 points over spring.stiffness (2) x run.dt (1)" in repr(sweep)
    assert "1 ok, 1 unstable" in repr(sweep)  # w*dt = 0.45 and 4.5 at k = 1e2, 1e6
    topple = results["ToppleMeasure"]
    assert f"lands at {topple.fall_time:.6g} s" in repr(topple)


def test_a_ten_thousand_point_sweep_shows_one_line(results):
    from dumbbell.analysis.sweep import PointResult, SweepResult, parse_axis

    axes = [parse_axis("k=log:1e2:1e7:100"), parse_axis("dt=log:1e-6:1e-2:100")]
    rows = [PointResult((("spring.stiffness", k), ("run.dt", dt)), 0.1, "ok" if i % 7 else
                        "unstable", None if i % 7 else 0.5, 1e-3, "a reason " * 30)
            for i, (k, dt) in enumerate((k, dt) for k in axes[0].values for dt in axes[1].values)]
    sweep = SweepResult(results["SweepResult"].scene, axes, "euler-cromer", 1.0, rows, 12.5,
                        "process pool of 2")
    assert len(rows) == 10_000
    text = repr(sweep)
    assert len(text) <= MAX_REPR and "\n" not in text and "10,000 points" in text
    assert "1,429 unstable" in text and "8,571 ok" in text
    html = sweep._repr_html_()
    assert html.count("<tr>") == 1 + MAX_ROWS + 1 and "1,399 more rows" in html


def test_one_line_cuts_long_text_and_keeps_it_closed():
    assert one_line("<A\n b>") == "<A b>"
    cut = one_line("<" + "x" * 500 + ">")
    assert len(cut) == MAX_REPR and cut.endswith("...>")


def test_to_csv_writes_what_simulate_writes(textbook, tmp_path):
    from dumbbell.cli import main

    traj = dumbbell.simulate(textbook, t_end=0.5, every=100)
    assert traj.to_csv(tmp_path / "api.csv") == tmp_path / "api.csv"
    assert main(["simulate", str(SCENES / "textbook-1d.toml"), "--t-end", "0.5", "--every",
                 "100", "-o", str(tmp_path / "cli.csv"), "-q"]) == 0
    assert (tmp_path / "api.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    rows = np.loadtxt(tmp_path / "api.csv", delimiter=",", skiprows=1)
    # E0 = (mA + mB) g x_cm + 0 (at rest, spring at rest length) = 0.2 * 9.8 * 1.1 = 2.156 J
    assert rows.shape == (501, 10) and math.isclose(rows[0, -1], 0.2 * 9.8 * 1.1, rel_tol=1e-15)


def test_the_spaces_objects_say_what_they_hold_in_a_line(tmp_path):
    # A notebook shows a counter, a driver, a recorder or a ledger by its repr: one line of
    # at most 200 characters with what it holds now, never the default '<... object at 0x>'.
    import pymunk

    from dumbbell import spaces

    s = pymunk.Space()
    s.gravity = (0.0, -9.81)
    b = pymunk.Body(2.0, 1.0)
    b.position, b.velocity = (0.0, 1.0), (3.0, 0.0)
    s.add(b, pymunk.Circle(b, 0.1))
    heat, ledger = spaces.HeatCounter(s), spaces.Ledger(s)
    driver = spaces.Driver(s, 1 / 50, substeps=2)
    folder = tmp_path / ("x" * 120) / ("y" * 120)
    folder.mkdir(parents=True)
    rec = spaces.Recorder(s, folder / "a.gif")
    driver.step(5)
    rec.capture()
    shown = {o: repr(o) for o in (heat, ledger, driver, rec)}
    for text in shown.values():
        assert "object at 0x" not in text and "\n" not in text and len(text) <= 200, text
    assert shown[driver] == "Driver(dt=0.02 s, substeps=2, frames=5, t=0.1 s)"
    # E0 = 1/2 m v^2 + m g y = 9 + 19.62 J, and E after 0.1 s of free flight is the same
    # but for the step's error (pymunk's symplectic Euler: g dt^2 terms).
    e0 = 0.5 * 2.0 * 9.0 + 2.0 * 9.81 * 1.0
    assert f"E0={e0:.6g}" in shown[ledger] and "steps=10" in shown[ledger]
    assert shown[heat] == "HeatCounter(attached, total=0 energy units)"
    assert "frames=2" in shown[rec] and "..." in shown[rec]
    heat.detach()
    assert repr(heat).startswith("HeatCounter(detached")
