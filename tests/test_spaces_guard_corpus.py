"""The step-size guard on pymunk's own example programs (tests/guard_corpus.py): its reach
estimates stay above the real peak speeds where they claim to bound them, come within 3x of
them on the constraints demo and the pyramid, and its advice, applied, changes nothing where
the guard finds nothing and reduces what it names where it finds something. Each case's row
of the table in docs/spaces-reference.md is what this run measures."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from .guard_corpus import CASES, HEAD, SPRINGS, advice, peaks, row
from .pymunk_corpus import run_example

pytest.importorskip("pygame")

DOCS = Path(__file__).resolve().parent.parent / "docs" / "spaces-reference.md"
#: Issue 20's targets: the largest estimate within 3x of the largest real peak.
WITHIN_3X = ("constraints", "box2d_pyramid")
#: Cases with a body alone among fixed shapes, whose estimate claims to bound its speed.
BOUNDED = ("contact_with_friction", "bouncing_balls")


def _docs_rows() -> dict[str, str]:
    """The rows of the guard's table in docs/spaces-reference.md (the table under its header line)."""
    lines = DOCS.read_text(encoding="utf-8").splitlines()
    start = lines.index(HEAD) + 2
    rows = {}
    for line in lines[start:]:
        match = re.match(r"\| ([\w/]+) \|", line)
        if not match:
            break
        rows[match.group(1)] = line
    return rows


def test_the_docs_table_has_a_row_for_every_case():
    assert list(_docs_rows()) == list(CASES)


@pytest.mark.parametrize("case", CASES)
def test_the_guard_on_a_pymunk_example(case):
    p = peaks(case)
    a = advice(case)
    # Bounds hold: every estimate that claims to bound a body's speed does, while it stands.
    assert p.broken == []
    if case in BOUNDED:
        assert p.claims > 50
    if case in WITHIN_3X:
        assert p.peak <= p.estimated <= 3 * p.peak
    if not a.failing:
        # Called fine: the step brings no shapes together deeper than the pass-through limit.
        assert a.substeps == 1 and a.before == a.after < 1
    elif a.measure.startswith("joint drift"):
        # A joint past the tolerance (1 % of the energy scale a second) comes under it with
        # the sub-steps the guard works out from its drift at dt/2.
        assert a.before > 0.01 > a.after and a.substeps > 1
    elif a.substeps > 1 or a.settings:
        # What it names shrinks when its advice is applied (or there was nothing to shrink:
        # a spring at rest in this run).
        assert a.after <= a.before
        if a.before > 0:
            assert a.after < a.before / 2
        if a.measure == "energy error":
            assert any(k in SPRINGS for k in a.failing)
    assert _docs_rows()[case] == row(case, p, a), "python tests/guard_corpus.py > table"


def test_asking_the_guard_changes_nothing_in_the_run():
    # The guard only reads: a program asked about at every step runs bit for bit the same.
    from dumbbell import spaces

    def ask(space, dt):
        spaces.report(space, dt)
        spaces.reach(space, dt)

    quiet = run_example("box2d_vertical_stack", 60).space
    asked = run_example("box2d_vertical_stack", 60, on_step=ask).space
    state = [(tuple(b.position), tuple(b.velocity), b.angle) for b in quiet.bodies]
    assert state == [(tuple(b.position), tuple(b.velocity), b.angle) for b in asked.bodies]
    assert math.isfinite(sum(x for s in state for x in s[0]))
