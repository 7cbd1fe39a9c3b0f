"""``dumbbell compare`` on a chaotic run (issue 29, items 9 and 10).

The runs part by chaos at the truth's last impact before the position error first passes
1 % of the dumbbell's length (2 mm for its 0.2 m): each impact turns a small difference in
when it happens into a larger one, and after that impact the error measures the chaos, not
the method. The comparison reports the position error up to there (or the window's end when
sooner), the time the runs part, and why; and every column says the span it covers: the
position error [0, error_until], the energy error and the impacts the whole run."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import dumbbell
from dumbbell.analysis.compare import PART_FRACTION, CompareOptions, compare, parting
from dumbbell.io.compare import SUMMARY_COLUMNS, summary_csv, text
from dumbbell.solvers import METHODS
from tests.conftest import SCENES


@pytest.fixture(scope="module")
def tilted():
    """tilted-2d, Euler-Cromer 2D against the reference over 3 s (window 2 s)."""
    return compare(dumbbell.load_scene(SCENES / "tilted-2d.toml"),
                   CompareOptions(solvers=(METHODS["euler-cromer-2d"],), t_end=3.0))


def test_the_runs_part_at_the_impact_that_amplified_the_difference(tilted):
    row, truth = tilted.rows[0], tilted.truth
    part = row.parted
    assert part is not None and part.impact == 3
    assert part.t == truth.events[2].t == pytest.approx(1.059453, abs=1e-6)
    assert part.distance == pytest.approx(PART_FRACTION * 0.2)
    # The criterion: the error passes 2 mm after impact 3 and before impact 4, and not before.
    over = np.flatnonzero(row.error > part.distance)
    assert truth.t[over[0]] == part.passed and truth.events[2].t < part.passed
    assert part.passed < truth.events[3].t
    # Why: the impact-time differences, growing per impact.
    assert len(part.differences) == 4 and abs(part.differences[-1]) > 1e-4
    assert all(abs(b) > abs(a) for a, b in zip(part.differences, part.differences[1:]))
    assert 2 < part.growth < 10


def test_the_error_is_reported_up_to_the_parting_not_over_the_window(tilted):
    """Over [0, 2] s the largest error is the chaos's (0.46 m); up to the parting it is the
    method's (4.1e-4 m)."""
    row = tilted.rows[0]
    upto = tilted.truth.t <= row.parted.t
    assert row.error_until == row.parted.t
    assert row.window_error == pytest.approx(float(row.error[upto].max()), rel=1e-12)
    assert row.window_error < 5e-4
    assert float(row.error[tilted.truth.t <= 2.0].max()) > 0.3
    note = next(n for n in tilted.notes if "by chaos" in n)
    assert note.startswith("euler-cromer-2d parts from the truth (reference) at 1.059 s "
                           "(the truth's impact 3), by chaos")
    assert "0.002 m (1% of the dumbbell's length) at 1.099 s" in note


def test_every_column_names_its_span(tilted):
    rows = list(csv.DictReader(summary_csv(tilted).splitlines()))
    assert tuple(rows[0]) == SUMMARY_COLUMNS
    ec = rows[1]
    assert float(ec["error_until_s"]) == pytest.approx(1.059453, abs=1e-6)
    assert float(ec["parted_at_s"]) == float(ec["error_until_s"]) and ec["window_s"] == "2.0"
    assert float(ec["run_until_s"]) == pytest.approx(3.0)  # energy error and impacts
    assert int(ec["impacts"]) == len(tilted.rows[0].traj.events)
    printed = text(tilted)
    header = next(line for line in printed.splitlines() if line.startswith("solver"))
    assert header.count("over [s]") == 2 and "parts at" in header
    line = next(line for line in printed.splitlines() if line.startswith("euler-cromer-2d"))
    assert "0-1.06" in line.split() and "1.06 s" in line and line.split()[-2] == "0-3"
    assert "E error and impacts: over the whole run" in printed
    df = tilted.to_pandas()
    assert df.attrs["units"]["error_until"] == "s" and df.attrs["units"]["run_until"] == "s"
    assert df.loc["euler-cromer-2d", "parted_at"] == pytest.approx(1.059453, abs=1e-6)


def _with_error(truth, error_at):
    """An error series over the truth's samples: ``error_at(t)``."""
    return np.array([error_at(float(t)) for t in truth.t])


def test_the_criterion_on_made_up_errors(tilted):
    """Passing the distance after impacts parts the runs at the last impact before it;
    passing it before any impact is the method's own error, not a parting; never passing it
    is no parting."""
    truth, run = tilted.truth, tilted.rows[0].traj
    first, second = truth.events[0].t, truth.events[1].t
    late = _with_error(truth, lambda t: 1e-5 if t < second + 0.01 else 1.0)
    part = parting(run, truth, late)
    assert part is not None and part.impact == 2 and part.t == second
    early = _with_error(truth, lambda t: 0.0 if t < first / 2 else 1.0)
    assert parting(run, truth, early) is None
    assert parting(run, truth, _with_error(truth, lambda t: 1e-3)) is None


def test_the_textbook_s_euler_cromer_parts_inside_the_window():
    """The textbook scene: Euler-Cromer at its dt parts from the exact run at its impact 4
    (1.43 s), where a 0.045 ms timing difference turns into 0.47 ms at the next."""
    result = compare(dumbbell.load_scene(SCENES / "textbook-1d.toml"),
                     CompareOptions(solvers=(METHODS["euler-cromer"],), t_end=3.0))
    row = result.rows[0]
    assert row.parted.impact == 4 and row.parted.t == pytest.approx(1.429525, abs=1e-6)
    assert row.window_error < 3e-4 and row.error_until == row.parted.t


def test_a_window_that_ends_before_the_parting_is_the_span():
    """With a 1 s window the runs part after it (1.059 s): the error covers [0, 1] s, the
    parting time is still reported, and no note explains a parting inside the window."""
    result = compare(dumbbell.load_scene(SCENES / "tilted-2d.toml"),
                     CompareOptions(solvers=(METHODS["euler-cromer-2d"],), t_end=2.0,
                                    window=1.0))
    row = result.rows[0]
    assert row.error_until == 1.0 and row.parted.t == pytest.approx(1.059453, abs=1e-6)
    assert row.window_error == pytest.approx(float(row.error[result.truth.t <= 1.0].max()))
    assert not any("by chaos" in n for n in result.notes)
