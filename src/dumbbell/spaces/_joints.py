"""The step guard's rows for constraints that are not springs (kind ``joint``): each one's
energy drift per second at the step, measured by the probe (:mod:`._probe`) on a copy of the
space, against ``tolerance`` of the energy scale a second; a row past it measured again at
dt/2, to give the step that clears it or to say that no step changes it. See
:mod:`.guard`."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ._finding import Finding
from .estimates import energy_units, percent

#: A drift that falls by less than this factor at half the step does not shrink with it.
SHRINKS = 0.75
#: Constraint kinds whose work is what they are for: a motor's drive.
DRIVES = ("SimpleMotor",)


def joint_rows(space: Any, dt: float, tolerance: float, unit: str
               ) -> tuple[list[Finding], str]:
    """A row for each constraint that is not a spring, from the probe (:mod:`._probe`): its
    energy drift per second at ``dt`` against ``tolerance`` of the energy scale a second;
    and what the probe cost, in words ('' when no constraint needed it)."""
    import pymunk

    from ._probe import probe

    constraints = list(space.constraints)
    wanted = [j for j, c in enumerate(constraints)
              if not isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
    if not wanted:
        return [], ""
    energy, power = energy_units(unit)
    found = probe(space, dt, wanted)
    if found.problem or not found.steps:
        why = f"not checked: {found.problem}; spaces.Ledger measures it on your own run"
        return [Finding("joint", f"{type(constraints[j]).__name__} {j}", math.nan, math.nan,
                        why, None, "unchecked") for j in wanted], ""
    limit = tolerance * found.scale
    rows: dict[int, Finding] = {}
    rates: dict[int, float] = {}
    for j, d in found.drifts.items():
        if d.work is None:
            rows[j] = Finding("joint", d.label, math.nan, math.nan,
                              f"not checked: {d.why}; spaces.Ledger measures it on your own "
                              "run",
                              None, "unchecked")
            continue
        rates[j] = rate = d.work / found.seconds
        verb = "puts in" if rate > 0 else "takes out"
        share = (f"{percent(abs(rate) / found.scale)}/s of the energy scale, "
                 f"{found.scale:.4g} {energy}" if found.scale > 0 else "")
        note = (f"{verb} {share}" if share and rate != 0 else
                "no energy in or out" if share else "nothing moved in the probe")
        if type(constraints[j]).__name__ in DRIVES:
            rows[j] = Finding("joint", d.label, abs(rate), math.nan,
                              f"{verb} {abs(rate):.4g} {power}: a motor's work is its drive, "
                              "not the step's error", None, "measured", power,
                              f"{note}: a motor's drive, not the step's error")
            continue
        fix = f"{note}, at this step: more than {percent(tolerance)}/s"
        rows[j] = Finding("joint", d.label, abs(rate), limit, fix, None, "<=", power, note)
    failing = [j for j, f in rows.items() if f.relation == "<=" and not f.ok]
    bodies = len(space.bodies)
    cost = (f"  joints measured on a copy of the space over {found.seconds:.4g} s: "
            f"{found.steps:,} steps of this dt ({bodies:,} bod{'y' if bodies == 1 else 'ies'})")
    if failing:
        half = probe(space, dt / 2, failing, steps=2 * found.steps)   # the same time
        if not half.problem:
            cost += f", and the failing over {half.seconds:.4g} s at dt/2 ({half.steps:,} steps)"
        for j in failing:
            rows[j] = _at_half(rows[j], rates[j], half, j, dt)
    return [rows[j] for j in wanted], cost


def _at_half(row: Finding, rate: float, half: Any, j: int, dt: float) -> Finding:
    """A failing joint row judged again from its drift at ``dt / 2`` (``half``, a probe):
    the step that clears it when the drift shrinks with the step (as dt^p, p measured), a
    measured row (no step changes it) when it does not."""
    d = half.drifts.get(j)
    if half.problem or d is None or d.work is None or not half.steps:
        dt_max = dt * row.limit / row.value
        fix = (f"{row.fix}; dt < {dt_max:.4g} s keeps it under (if it shrinks in proportion "
               "to dt, as a joint's error does; not measured at dt/2 here)")
        return replace(row, fix=fix, dt_max=dt_max)
    slower = abs(d.work / half.seconds)
    ratio = slower / row.value
    if ratio > SHRINKS:
        note = (f"{row.note}; about as much at dt/2, {slower:.4g} {row.unit}: the joint's "
                "own loss (a stop, a snap, a slip), which no step changes")
        return replace(row, relation="measured", limit=math.nan, note=note,
                       fix=f"{row.fix}; at dt/2, {slower:.4g} {row.unit}: no step changes it")
    order = min(3.0, max(0.5, math.log2(1.0 / ratio))) if ratio > 0 else 3.0
    dt_max = dt * (row.limit / row.value) ** (1.0 / order)
    fix = (f"{row.fix}; at dt/2, {slower:.4g} {row.unit} (it goes as dt^{order:.2g}): "
           f"dt < {dt_max:.4g} s keeps it under")
    return replace(row, fix=fix, dt_max=dt_max)
