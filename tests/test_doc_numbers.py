"""Numbers with provenance: the physics numbers the README and docs quote, each recomputed by
a fresh run (or the closed form it names) and compared at the precision the page quotes.

Each :data:`CLAIMS` row is (page, the sentence or table cell as the page writes it, the
number in it, how to compute it). The page must still contain the text, and the number
computed now must print as the page prints it. Only cheap runs are here (under a second
each); the speed figures live in benchmarks, and the stability catalogue's table is the
goldens'."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest

import dumbbell
from tests.conftest import ROOT, SCENES, rotation_table

G = 9.8


@cache
def scene(name: str):
    return dumbbell.load_scene(SCENES / f"{name}.toml")


@cache
def run(name: str, solver: str | None = None, **options):
    return dumbbell.simulate(scene(name), solver, **options)


@cache
def truth(dt: float = 1e-3):
    """The exact textbook run, a sample every ``dt`` s over 10 s."""
    return run("textbook-1d", "exact", dt=dt, every=1)


def window_error(solver: str, dt: float) -> float:
    from dumbbell.analysis.metrics import position_error

    every = max(1, round(1e-3 / dt))
    return position_error(run("textbook-1d", solver, dt=dt, every=every), truth(), 2.0)


def energy_error(solver: str, dt: float) -> float:
    from dumbbell.analysis.metrics import energy_error

    every = max(1, round(1e-3 / dt))
    return energy_error(run("textbook-1d", solver, dt=dt, every=every), truth())


def truth_e_eff(theta: float, e: float) -> float:
    from dumbbell.solvers.exact_rigid import first_impact_state

    before, after = first_impact_state(tilt=theta, elasticity=e)
    return -after.VY / before.VY


@cache
def topple():
    from dumbbell.analysis.topple import closed_form, measure

    cf = closed_form(scene("topple-2d"))
    # The scene's run, to just after the landing (0.41 s) instead of its 1 s: the same samples
    # up to there, without 0.55 s of lying on the floor.
    return cf, measure(run("topple-2d", t_end=0.45))


@cache
def contact(solver: str):
    from dumbbell.analysis.contact import about_contact

    return about_contact(run("rigid-2d", solver, t_end=0.6,
                             **({"every": 1} if solver == "pymunk" else {"dt": 1e-4})))


def k_rot_between(k: float) -> float:
    s = scene("tilted-2d").with_values({"spring.stiffness": k, "run.t_end": 0.6})
    traj = dumbbell.simulate(s, solver="reference", dt=1e-5)
    between = (traj.t > traj.first_impact("B").t) & (traj.t < traj.first_impact("A").t)
    return float(traj["K_rot"][between].mean())


def frame_energies() -> tuple[float, float, float]:
    """The textbook GIF's frames at 0.44 and 0.48 s: K_cm at each, and the largest K_int
    between them (the pale bar)."""
    traj = run("textbook-1d")
    i, j = (int(np.argmin(abs(traj.t - t))) for t in (0.44, 0.48))
    return float(traj["K_cm"][i]), float(traj["K_cm"][j]), float(traj["K_int"][i:j + 1].max())


def _ec_error(window: float) -> float:
    """Euler-Cromer at the textbook's dt against exact: the largest position error over
    [0, window] s."""
    from dumbbell.analysis.metrics import position_error

    return position_error(run("textbook-1d", "euler-cromer", dt=1e-5, every=100), truth(),
                          window)


@dataclass(frozen=True)
class Claim:
    page: str
    text: str
    number: str
    compute: Callable[[], float]


def _rigid_first_k_rot() -> float:
    from dumbbell.solvers.exact_rigid import first_impact_state

    _, after = first_impact_state(tilt=30.0, elasticity=1.0)
    inertia = 0.05 * 0.2**2  # I = mu L^2, mu = 0.1 * 0.1 / 0.2 kg, L = 0.2 m
    return 0.5 * inertia * after.omega**2


CLAIMS = [
    # README
    Claim("README.md", "M g X = 0.2 × 9.8 × 1.1 = 2.156 J", "2.156",
          lambda: run("textbook-1d", t_end=0.01)["E"][0]),
    Claim("README.md", "t = √(2 h0/g) = 0.4518 s", "0.4518",
          lambda: truth().events[0].t),
    Claim("README.md", "Impact(t=0.4517539514526256, body='B'", "0.4517539514526256",
          lambda: run("textbook-1d", "exact", dt=1e-5, t_end=2.0, every=100).events[0].t),
    Claim("README.md", "v_before=-4.427...", "-4.427",
          lambda: truth().events[0].v_before),
    # docs/rotation.md
    Claim("docs/rotation.md", "| 80° | 0.0153076 | 0.0153076 |", "0.0153076",
          lambda: truth_e_eff(80.0, 1.0)),
    Claim("docs/rotation.md", "| 80° | −0.238519 | −0.238519 |", "−0.238519",
          lambda: truth_e_eff(80.0, 0.5)),
    Claim("docs/rotation.md", "| fall time | 0.406387 s | 0.406392 s |", "0.406392",
          lambda: topple()[1].fall_time),
    Claim("docs/rotation.md", "| top particle's landing speed | 1.97613 m/s", "1.97613",
          lambda: topple()[0].landing_speeds()[1]),
    Claim("docs/rotation.md", "| `exact` | 3e-18 → −0.07083502 | −0.04427189", "−0.07083502",
          lambda: contact("exact").L_cm_after),
    Claim("docs/rotation.md", "| `exact` | 3e-18 → −0.07083502 | −0.04427189", "−0.04427189",
          lambda: contact("exact").before),
    Claim("docs/rotation.md", "| pymunk, dt = 1e-5 s | 0 → −0.07083518", "−0.07083518",
          lambda: contact("pymunk").L_cm_after),
    Claim("docs/rotation.md", "−0.07083518 | −0.04427248", "−0.04427248",
          lambda: contact("pymunk").before),
    Claim("docs/rotation.md", "with ω = −35.4175 rad/s", "−35.4175",
          lambda: __import__("dumbbell.solvers.exact_rigid", fromlist=["x"])
          .first_impact_state(30.0, 1.0)[1].omega),
    # docs/physics.md
    Claim("docs/physics.md", "(for the textbook values ω = 63.25 rad/s, a period of 0.0993 s)",
          "63.25", lambda: scene("textbook-1d").system.omega),
    Claim("docs/physics.md", "(for the textbook values ω = 63.25 rad/s, a period of 0.0993 s)",
          "0.0993", lambda: 2 * math.pi / scene("textbook-1d").system.omega),
    Claim("docs/physics.md", "The textbook scene has about 22 impacts in 10 s.", "22",
          lambda: len(truth().events)),
    *[Claim("docs/physics.md", "at most 3e-5 m off up to 0.5 s, 1e-4 m up to 1 s,\n2e-3 m up to "
            "2 s and 0.3 m by 3 s", quoted, fn) for quoted, fn in [
                ("3e-5", lambda: _ec_error(0.5)), ("1e-4", lambda: _ec_error(1.0)),
                ("2e-3", lambda: _ec_error(2.0)), ("0.3", lambda: _ec_error(3.0))]],
    Claim("docs/physics.md", "J = 2v / (1/M + r_x²/I) (1.254 J)", "1.254", _rigid_first_k_rot),
    Claim("docs/physics.md", "# J: 0.4976, 0.4939, 0.4903", "0.4976",
          lambda: k_rot_between(1e4)),
    Claim("docs/physics.md", "# J: 0.4976, 0.4939, 0.4903", "0.4939",
          lambda: k_rot_between(2e4)),
    Claim("docs/physics.md", "# J: 0.4976, 0.4939, 0.4903", "0.4903",
          lambda: k_rot_between(1e5)),
    # docs/rendering.md
    Claim("docs/rendering.md", "`K_cm` drops from 1.86 J to 0.01 J", "1.86",
          lambda: frame_energies()[0]),
    Claim("docs/rendering.md", "`K_cm` drops from 1.86 J to 0.01 J", "0.01",
          lambda: frame_energies()[1]),
    Claim("docs/rendering.md", "the pale `K_int` bar jumps to 1.96 J", "1.96",
          lambda: frame_energies()[2]),
    # docs/measurements.md: the accuracy columns (the run times are the benchmarks')
    *[Claim("docs/measurements.md", f"| {s} | {dt} | {e} | {en} |", num, fn)
      for s, dt, e, en, num, fn in [
          ("pymunk", "1e-4", "9.27e-3", "2.93e-3", "9.27e-3", lambda: window_error("pymunk", 1e-4)),
          ("pymunk", "1e-4", "9.27e-3", "2.93e-3", "2.93e-3", lambda: energy_error("pymunk", 1e-4)),
          ("euler-cromer", "1e-4", "1.99e-2", "1.27e-2", "1.99e-2",
           lambda: window_error("euler-cromer", 1e-4)),
          ("euler-cromer", "1e-4", "1.99e-2", "1.27e-2", "1.27e-2",
           lambda: energy_error("euler-cromer", 1e-4))]],
    Claim("docs/measurements.md", "| 2.65e-1 | 1.28e-1 | 8.53e-3 |", "2.65e-1",
          lambda: window_error("euler-cromer", 1e-3)),
    Claim("docs/measurements.md", "| 2.65e-1 | 1.28e-1 | 8.53e-3 |", "1.28e-1",
          lambda: energy_error("euler-cromer", 1e-3)),
    Claim("docs/measurements.md", "| 5.69e-5 | 9.68e-6 | 6.09e-7 |", "5.69e-5",
          lambda: window_error("verlet", 1e-4)),
    Claim("docs/measurements.md", "| 5.69e-5 | 9.68e-6 | 6.09e-7 |", "9.68e-6",
          lambda: energy_error("verlet", 1e-4)),
    Claim("docs/measurements.md", "| 1.34e-2 | 3.00e-2 | 1.25e-3 |", "1.34e-2",
          lambda: window_error("pymunk", 1e-3)),
    # docs/stability.md
    Claim("docs/stability.md", "rest expected at 4.07 s", "4.07",
          lambda: math.sqrt(2 * 1.0 / G) * (1 + 0.8) / (1 - 0.8)),
    Claim("docs/stability.md", "| 2.1e-3 | 2.1 | **unstable** at 0.0063 s |", "0.0063",
          lambda: dumbbell.simulate(dumbbell.load_scene(
              SCENES / "extreme" / "stiff-wdt-2.1.toml"), "euler-cromer").verdict.t),
]


def _printed(value: float, quoted: str) -> str:
    """``value`` written the way ``quoted`` is: the same decimals, or the same mantissa
    digits in e-notation, with the page's minus sign. A value that is not zero never prints
    as zero: rounded to nothing, it is written in e-notation (7.4e-17 as 7e-17, not 0), as
    the commands print it, so a page cannot say 0 where a command prints 7.40149e-17."""
    minus = "−" if quoted.startswith("−") else "-"
    plain = quoted.replace("−", "-")
    if "e" in plain:
        mantissa = plain.split("e")[0]
        digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
        text = _e_notation(value, digits)
    else:
        decimals = len(plain.split(".")[1]) if "." in plain else 0
        text = f"{value:.{decimals}f}"
        if float(text) == 0 and value != 0:
            text = _e_notation(value, 0)
    if text.startswith("-") and float(text.replace("e", "E")) == 0:
        text = text[1:]  # -0.00 prints as 0.00
    return text.replace("-", minus, 1) if text.startswith("-") else text


def _e_notation(value: float, digits: int) -> str:
    """``value`` as 7.4e-17 (``digits`` after the point; no '+', no leading zeros)."""
    m, exp = f"{value:.{digits}e}".split("e")
    return f"{m}e{int(exp)}"


def _table(page: str, first_line: str) -> list[list[str]]:
    """The cells of the Markdown table of ``page`` whose header row starts with
    ``first_line``, header included, separator left out."""
    lines = (ROOT / page).read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(first_line))
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        if not line.startswith("|---"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


def _cell_matches(cell: str, value: float) -> bool:
    return _printed(value, cell) == cell


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_the_rotation_page_s_tables_are_the_command_s_every_cell(e):
    """docs/rotation.md's tables, every cell: formula, truth, pymunk, and each spring's
    e_eff with the impacts of its first cluster ('0.988 (2)')."""
    text = (ROOT / "docs/rotation.md").read_text(encoding="utf-8")
    marker = f"e = {e:g}:\n\n"
    assert marker in text
    # The table after this e's marker (both tables share their header row).
    start = text.index(marker) + len(marker)
    rows = [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in text[start:].splitlines()
            if line.startswith("|") and not line.startswith("|---")][:6]
    assert rows[0][:4] == ["θ", "formula", "truth", "pymunk"]
    result = rotation_table(e)  # the command's analysis, shared with test_rotation_chapter
    springs = [result.springs[k] for k in (200.0, 2e3, 2e4)]
    for i, (theta, formula, truth, pymunk, *spring_cells) in enumerate(rows[1:]):
        assert float(theta.rstrip("°")) == result.theta[i]
        for cell, value in ((formula, result.formula[i]), (truth, result.truth[i]),
                            (pymunk, result.pymunk[i])):
            assert _cell_matches(cell, float(value)), (theta, cell, float(value))
        for cell, spring in zip(spring_cells, springs, strict=True):
            value, impacts = cell.split()
            assert _cell_matches(value, float(spring["e_eff"][i])), (theta, cell)
            assert impacts == f"({int(spring['impacts'][i])})", (theta, cell)


@pytest.mark.parametrize("claim", CLAIMS, ids=[f"{c.page}:{c.number}" for c in CLAIMS])
def test_a_quoted_number_comes_back_from_a_fresh_run(claim):
    page = (ROOT / claim.page).read_text(encoding="utf-8")
    assert claim.text in page, f"{claim.page} no longer says {claim.text!r}"
    assert claim.number in claim.text
    assert _printed(claim.compute(), claim.number) == claim.number


def test_the_table_sees_a_wrong_number():
    assert _printed(0.4517539514526256, "0.4518") == "0.4518"
    assert _printed(-7.4e-6, "−7.4e-6") == "−7.4e-6"
    assert _printed(-7.46e-6, "−7.4e-6") != "−7.4e-6"
    assert _printed(0.0153075, "0.0153076") != "0.0153076"
    assert re.fullmatch(r"2\.156", _printed(2.156000000001, "2.156"))
