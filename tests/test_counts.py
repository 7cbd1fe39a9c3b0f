"""A count printed beside its noun agrees with it: '1 run', '3 runs' (issue 29: ``bench``
printed "at least 1 runs"). Every message, table and figure label builds such a pair with
``dumbbell._display.counted``; this test reads the source for a count written before a fixed
plural, which reads wrong when the count is 1."""

from __future__ import annotations

import re

from dumbbell._display import counted, significant
from tests.conftest import ROOT

#: A formatted value followed by a plural noun: '{n} runs', '{len(x):,} points'.
FIXED_PLURAL = re.compile(
    r"\{[^{}]*\} (runs|points|impacts|cases|solvers|samples|frames|files|tilts|bodies|"
    r"springs|contacts|steps|calls|panels|particles|shapes|constraints|terms|rows)\b")
#: Counts that cannot be 1 where they are printed: the budgets (a limit, or a count past
#: one), a constant, a float's format (a count of steps like 3.2e+08), and a count known to be
#: 2 or more.
ALLOWED = re.compile(r"budget|MAX_|\{[A-Z_]+(:,)?\}|more than|at most|:\.[0-9]g\}|count >= 2|"
                     r"\{steppers\} stepping|\{len\(dts\)\} steps|\{len\(options\.dts\)\} "
                     r"steps|\{len\(solvers\)\} solvers x|\{len\(paths\)\} cases x|"
                     r"\{n\} tilts x|\{m\} springs|\{runs:,\} runs of|\{product\} is")


def test_counted_agrees_with_its_count():
    assert counted(1, "run") == "1 run" and counted(3, "run") == "3 runs"
    assert counted(0, "impact") == "0 impacts" and counted(12_000, "point") == "12000 points"
    assert counted(12_000, "point", grouped=True) == "12,000 points"
    assert counted(1, "body", "bodies") == "1 body" and counted(2, "body", "bodies") == "2 bodies"


def test_significant_keeps_its_digits():
    assert significant(0.03) == "0.0300" and significant(0.0192) == "0.0192"
    assert significant(154.0) == "154" and significant(1300.0) == "1.30e+03"
    assert significant(1.3) == "1.30" and significant(float("inf")) == "inf"


def test_no_count_is_printed_before_a_fixed_plural():
    found = []
    for path in sorted((ROOT / "src" / "dumbbell").rglob("*.py")):
        lines = path.read_text(encoding="utf-8").splitlines()
        for number, line in enumerate(lines, 1):
            code = line.split("#", 1)[0] if not line.lstrip().startswith("#") else ""
            window = " ".join(lines[max(0, number - 4):number + 1])
            if FIXED_PLURAL.search(code) and not ALLOWED.search(window):
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert found == [], "\n".join(found)
