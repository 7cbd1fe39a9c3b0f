"""The tables the commands print are io's (analysis computes only): what ``dumbbell compare``
and ``dumbbell restitution`` print says the result's own numbers, row by row."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from dumbbell import compare
from dumbbell.analysis.restitution import restitution
from dumbbell.io.compare import text
from dumbbell.io.restitution import markdown
from dumbbell.model.scene import load_scene

SCENES = Path(__file__).parent.parent / "scenes"


def test_the_compare_text_holds_every_run_and_every_impact_in_the_window():
    result = compare(SCENES / "textbook-1d.toml", solvers=["euler-cromer", "verlet"],
                     dts=[1e-4], window=0.8, t_end=1.0)
    lines = text(result).splitlines()
    rule = next(i for i, line in enumerate(lines) if set(line) == {"-"})
    table = lines[rule + 1: rule + 2 + len(result.rows)]
    assert table[0].split()[0] == result.truth.solver and "(truth)" in table[0]
    for line, row in zip(table[1:], result.rows, strict=True):
        assert line.startswith(row.label) and f"{row.window_error:.3g}" in line.split()
    start = lines.index("impacts in [0, 0.8] s: time, and difference from the truth")
    inside = [e for e in result.truth.events if e.t <= 0.8]
    assert inside, "the window must hold an impact for the check to mean anything"
    impact_lines = lines[start + 2: start + 2 + len(inside)]
    for n, (line, event) in enumerate(zip(impact_lines, inside, strict=True), start=1):
        cells = line.split()
        assert (int(cells[0]), cells[1]) == (n, event.body)
        assert float(cells[2]) == pytest.approx(event.t, abs=5e-7)
        for k, row in enumerate(result.rows):
            diff_ms = float(cells[4 + 3 * k].lstrip("("))
            assert diff_ms == pytest.approx((row.traj.events[n - 1].t - event.t) * 1e3,
                                            abs=5e-4)


def test_the_restitution_markdown_holds_every_column_at_six_digits():
    result = restitution(load_scene(SCENES / "rigid-2d.toml"), [10.0, 35.0], stiffnesses=(),
                         dt=1e-3)
    head, rule, *rows = markdown(result).splitlines()
    columns = result.columns()
    assert [c.strip() for c in head.strip("|").split("|")] == list(columns)
    assert rule == "|" + "---|" * len(columns)
    assert len(rows) == len(result.theta)
    for i, line in enumerate(rows):
        cells = [float(c) for c in line.strip("|").split("|")]
        for cell, values in zip(cells, columns.values(), strict=True):
            assert math.isclose(cell, float(values[i]), rel_tol=5e-6, abs_tol=1e-300)
