"""A step-size guard for any pymunk space: which dt is too large, by how much, why, and the fix.

Checks (each a :class:`Finding` with the number, its limit, the relation a good value keeps,
the fix and the reason for it):

- ``spring``: a ``DampedSpring``'s step is explicit (symplectic Euler: positions first, then
  the spring's impulse), so its energy is not kept but swings about a value the step does
  keep (its modified energy). For an undamped spring of angular frequency w the swing, the
  largest relative change of energy from any start, is ``2 w dt / (2 - w dt)`` (see
  :func:`energy_swing`): 2 % at w dt = 0.02, 100 % at 0.67, without bound from w dt = 2
  (unstable). The check keeps the swing under ``tolerance`` (1 % unless set); ``tolerance =
  math.inf`` asks for stability only. w = sqrt(k / m_eff), m_eff the mass the spring moves
  along its axis, 1 / (1/m_a + 1/m_b + (r_a x n)^2 / I_a + (r_b x n)^2 / I_b): the reduced
  mass for anchors at the centres of gravity, the other body's mass when one end is fixed;
- ``rotary-spring``: the same for a ``DampedRotarySpring``, w = sqrt(k (1/I_a + 1/I_b));
- ``spring-network``: a body held by two or more springs, against an upper bound of its
  fastest vibration (see :mod:`._springs_dt`);
- ``tunnelling``: pymunk finds a contact only once shapes overlap (no swept collisions), so a
  body moving farther in one step than half the thinnest shape it can hit plus half its own
  size can pass through it. The closing speed is the larger of the speed now (its fastest
  point plus the fastest thing it can hit) and its reach estimate (:mod:`.estimates`: its own
  energy and fall, what holds it, what others can pass on);
- ``slop``: ``space.collision_slop`` is the overlap pymunk leaves between touching shapes;
- ``bias``: with ``space.collision_bias`` < 1 pymunk pushes overlapping shapes apart, which
  adds energy at elastic contacts (flagged where any contact is elastic);
- ``threads``: a space made with ``pymunk.Space(threaded=True)`` and ``space.threads = 2``
  runs the solver on two threads that apply impulses to the same bodies at once, without
  locks: impulses can be lost (energy no source explains; runs that do not repeat);
- ``joint``: every constraint that is not a spring, its energy drift per second at this
  step against ``tolerance`` of the energy scale a second, measured on a copy of the space
  (:mod:`._probe`; a row past it is measured again at dt/2, to say which step clears it, or
  that no step changes it); a motor's work is reported, not judged, and what the probe
  cannot separate is a row "not checked" naming why;
- ``state``: a body whose position or velocity is not a finite number, or a dynamic body
  without a valid mass or moment: no step fixes it.

Lengths are in the space's own unit: pymunk has none. ``units`` names it in the messages
('m', 'px'); without it they say 'units'. Times are in seconds.

:func:`suggest_dt` returns a step (dt divided into whole sub-steps) that clears every finding
a step can clear; slop, bias and threads are settings, not steps. :class:`Driver` steps a
space at a fixed frame step in sub-steps (:mod:`.stepping`). Each check reads the space
once (:mod:`._scan`), so the guard costs time linear in bodies and shapes.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ._finding import _FAILS, Finding
from ._refusals import settings_problem
from ._scan import Scan, _shapes, best_other, hittable_in, scan
from ._springs_dt import _networks, _springs, energy_swing, spring_omega
from ._threaded import hazard
from .estimates import Estimates, estimate, length_unit, percent, state_problem, step_dt

__all__ = ["Finding", "check", "energy_swing", "report", "shape_size", "spring_omega",
           "substeps", "suggest_dt", "survey"]

#: Default largest energy swing of a spring's step (a fraction: 0.01 = 1 %).
TOLERANCE = 0.01
#: Largest slop, as a fraction of the smallest shape's size.
SLOP_FRACTION = 0.1
#: Most sub-steps of one step, and most steps one call of :func:`~.stepping.step` or
#: :meth:`~.stepping.Driver.step` takes: past it a loop would run for hours, so it is refused
#: at once.
MAX_STEPS = 10**9
#: Slop suggested, as a fraction of the smallest shape's size.
SLOP_SUGGESTED = 0.01
#: Rows of one kind a report lists before it sums up the rest.
SHOWN = 6

#: What ``speeds`` may be: the present speeds, the reach estimates, or the larger.
SPEEDS = ("state", "energy", "both")


def _tolerance(value: Any) -> float:
    """``tolerance``: a number > 0 (a fraction), math.inf for stability only."""
    if (isinstance(value, bool) or not isinstance(value, numbers.Real)
            or not float(value) > 0):
        raise UsageError(f"tolerance = {args.show(value)}: must be a number > 0 (the largest "
                         "energy swing of a spring's step, a fraction: 0.01 = 1 %; math.inf "
                         "for stability only)", param="tolerance")
    return float(value)


def _check(space: Any, dt: Any, speeds: Any = "both", tolerance: Any = TOLERANCE,
           units: Any = None) -> tuple[Any, float, str, float, str]:
    """The guard's arguments checked at the border (UsageError naming the one that is not
    valid): a pymunk.Space, a step > 0 (s), one of :data:`SPEEDS`, a tolerance and a unit."""
    return (args.space(space), step_dt(dt), args.choice(speeds, "speeds", SPEEDS),
            _tolerance(tolerance), length_unit(units))


def shape_size(shape: Any) -> float:
    """The thinnest extent of a shape (length units): a circle's diameter, a segment's
    thickness (2 x radius), a polygon's least width across an edge plus 2 x radius.

    Parameters
    ----------
    shape : pymunk.Shape
        A circle, segment or polygon.

    Returns
    -------
    float
        The thinnest extent (length units).

    Raises
    ------
    UsageError
        Anything but a pymunk shape.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> spaces.shape_size(pymunk.Circle(None, 0.02))
    0.04
    """
    args.pymunk_object(shape, "shape", ("Shape",))
    return float(_shapes([shape], np.zeros(1, dtype=int), np.zeros((1, 2)))[1][0])


def _tunnelling(sc: Scan, est: Estimates, dt: float, speeds: str, unit: str) -> list[Finding]:
    """Each dynamic body that can hit something: how far it may move in one step against
    half the thinnest shape it can hit plus half its own smallest one."""
    idx = est.idx
    if len(idx) == 0:
        return []
    everything = np.ones(len(sc.shapes), dtype=bool)
    thinnest, _ = best_other(sc, sc.size, everything, idx, "min")
    shape_speed = (np.hypot(sc.v[sc.owner, 0], sc.v[sc.owner, 1])
                   + np.abs(sc.w[sc.owner]) * sc.reach)
    fastest, _ = best_other(sc, shape_speed, everything, idx, "max")
    own_size = np.full(len(sc.bodies), np.inf)
    solid = ~sc.sensor
    np.minimum.at(own_size, sc.owner[solid], sc.size[solid])
    rows = []
    for k, i in enumerate(idx):
        if not np.isnan(est.region[k]).any():
            # A held body meets only what lies within its joint's reach.
            near = hittable_in(sc, int(i), est.region[k])
            thinnest[k] = sc.size[near].min() if len(near) else np.nan
            fastest[k] = shape_speed[near].max() if len(near) else 0.0
        if math.isnan(thinnest[k]):
            continue
        limit = 0.5 * thinnest[k] + 0.5 * own_size[int(i)]
        v_state = float(est.now[k] + fastest[k])
        v_energy = float(est.points[k])
        v = {"state": v_state, "energy": v_energy, "both": max(v_state, v_energy)}[speeds]
        if v == 0.0 or limit == 0.0:
            continue
        if speeds == "state" or (speeds == "both" and v_state >= v_energy):
            why = "its speed now plus the fastest thing it can hit"
        else:
            why = est.source[k]
        dt_max = limit / v
        fix = (f"closes at up to {v:.4g} {unit}/s ({why}): {v * dt:.3g} {unit} per step "
               f"against half the thinnest shape it can hit plus half its own, "
               f"{limit:.3g} {unit}; dt < {dt_max:.4g} s")
        rows.append(Finding("tunnelling", sc.label(int(i)), v * dt, float(limit), fix,
                            dt_max, "<", unit))
    return rows


def _contact_settings(sc: Scan, dt: float, unit: str) -> list[Finding]:
    """The collision slop against the smallest shape, and the collision bias where elastic
    shapes can touch. Slop and bias act only where shapes can touch."""
    idx = sc.dynamic
    everything = np.ones(len(sc.shapes), dtype=bool)
    if len(idx) == 0 or np.isnan(best_other(sc, sc.size, everything, idx, "min")[0]).all():
        return []
    space = sc.space
    solid = ~sc.sensor & (sc.size > 0)
    rows: list[Finding] = []
    if solid.any():
        smallest = float(sc.size[solid].min())
        limit = SLOP_FRACTION * smallest
        fix = (f"slop is the overlap pymunk leaves between touching shapes: more than a "
               f"tenth of the smallest shape ({smallest:.3g} {unit}) lets resting shapes sink "
               f"visibly into each other; set space.collision_slop = "
               f"{SLOP_SUGGESTED * smallest:.3g} {unit}, a hundredth of it: the sinking is "
               f"then too small to see, and a slop above 0 keeps resting contacts from "
               f"breaking and re-forming every step")
        rows.append(Finding("slop", "space.collision_slop", float(space.collision_slop),
                            limit, fix, None, "<=", unit))
    e_body = np.zeros(len(sc.bodies))
    np.maximum.at(e_body, sc.owner[~sc.sensor], sc.elasticity[~sc.sensor])
    elastic_shapes = sc.elasticity > 0
    hit, _ = best_other(sc, sc.elasticity, elastic_shapes, idx, "max")
    if ((e_body[idx] > 0) & ~np.isnan(hit)).any():
        bias = float(space.collision_bias)
        per_step = 1.0 - bias**dt if 0 <= bias <= 1 else math.nan
        fix = (f"pymunk pushes overlapping shapes apart, a fraction 1 - bias^dt of the overlap "
               f"each step ({per_step:.3g} at this dt); the push adds energy at elastic "
               "contacts: set space.collision_bias = 1.0 (no push) if energy matters; shapes "
               "that overlap then stay overlapped")
        rows.append(Finding("bias", "space.collision_bias", bias, 1.0, fix, None, ">="))
    return rows


def _threads(space: Any) -> list[Finding]:
    """A space made with ``pymunk.Space(threaded=True)``: its ``threads`` (pymunk's public
    property), 1 keeping each step as the serial solver's."""
    if not getattr(space, "threaded", False):
        return []
    n = int(space.threads)
    fix = (f"{hazard(n)}: energy then changes by what no source explains; set "
           "space.threads = 1 (pymunk's default) when the numbers matter" if n > 1 else
           f"keep space.threads = 1 (pymunk's default): at 2, {hazard(2)}")
    return [Finding("threads", "space.threads", float(n), 1.0, fix, None, "<=")]


@dataclass(frozen=True)
class _Advice:
    rows: list[Finding]
    dt: float
    substeps: int | None
    tightest: Finding | None
    tolerance: float
    swing: float | None
    unit: str
    probe: str = ""


def _advise(space: Any, dt: float, speeds: str, tolerance: float, unit: str) -> _Advice:
    """Every check at ``dt`` and the sub-steps that clear the ones a step can clear."""
    sc = scan(space)
    problem = settings_problem(space) or state_problem(sc, unit)
    if problem is not None:
        who, what, value = problem
        return _Advice([Finding("state", who, value, math.nan, what, None, "finite")], dt, 1,
                       None, tolerance, None, unit)
    est = estimate(sc, dt, unit)
    from ._joints import joint_rows

    rows_of_joints, probed = joint_rows(space, dt, tolerance, unit)
    joints = rows_of_joints
    rows = (_springs(space, dt, tolerance) + _networks(space, sc, dt, tolerance) + joints
            + _tunnelling(sc, est, dt, speeds, unit) + _contact_settings(sc, dt, unit)
            + _threads(space))
    failing = [f for f in rows if not f.ok and f.dt_max is not None]
    tightest = min(failing, key=lambda f: f.dt_max) if failing else None
    n: int | None = 1
    if tightest is not None:
        ratio = dt / tightest.dt_max if tightest.dt_max > 0 else math.inf
        n = math.floor(ratio) + 1 if ratio < MAX_STEPS else None
    ws = [f.value / dt for f in rows if f.kind in ("spring", "rotary-spring", "spring-network")]
    swing = (energy_swing(max(ws) * dt / n) if ws and n is not None and math.isfinite(max(ws))
             else None)
    return _Advice(rows, dt, n, tightest, tolerance, swing, unit, probed)


def _refuse(advice: _Advice) -> int:
    """The sub-steps, or a DumbbellError when no step can be suggested: a state no step
    fixes (naming the body and the value), or more than :data:`MAX_STEPS` sub-steps."""
    for f in advice.rows:
        if f.kind == "state":
            raise UsageError(f"space: {f.subject}: {f.fix}", param="space")
    if advice.substeps is None:
        t = advice.tightest
        raise UsageError(f"dt = {advice.dt:g}: clearing the guard's findings would take more "
                         f"than {MAX_STEPS:,} sub-steps of it ({t.kind} of {t.subject}: needs "
                         f"dt < {t.dt_max:.3g} s); take a smaller dt or change what makes it "
                         "so fast or stiff", param="dt")
    return advice.substeps


def survey(space: Any, dt: float, speeds: str = "both", tolerance: float = TOLERANCE,
           units: str | None = None) -> list[tuple[Finding, bool]]:
    """Every check at step ``dt`` (s) as (finding, ok) pairs, passed ones included.

    Parameters
    ----------
    space : pymunk.Space
        Any space.
    dt : float
        The step (the space's time unit, s in SI).
    speeds : {'both', 'state', 'energy'}, default 'both'
        The speeds checked: 'state' the present ones, 'energy' the reach estimates
        (:func:`reach`), 'both' the larger.
    tolerance : float, default 0.01
        The largest energy swing of a spring's step (a fraction; math.inf for stability only).
    units : str or None, default None
        The space's length unit, for the messages.

    Returns
    -------
    list of (Finding, bool)
        Every check, and whether it passes.

    Raises
    ------
    UsageError
        ``space`` not a pymunk Space, ``dt`` not a number > 0, ``speeds`` not one of the
        three, ``tolerance`` not > 0, or ``units`` not None, a length unit or three names;
        the message names which.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a box at rest on a floor, SI units
    >>> space.gravity = (0.0, -9.8)
    >>> box = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.1)))
    >>> box.position = (0.0, 0.05)
    >>> floor = pymunk.Segment(space.static_body, (-2.0, 0.0), (2.0, 0.0), 0.0)
    >>> space.add(box, pymunk.Poly.create_box(box, (0.2, 0.1)), floor)
    >>> [(f.kind, ok) for f, ok in spaces.survey(space, 1 / 60)]    # passed rows too
    [('tunnelling', True), ('slop', False)]
    """
    space, dt, speeds, tolerance, unit = _check(space, dt, speeds, tolerance, units)
    return [(f, f.ok) for f in _advise(space, dt, speeds, tolerance, unit).rows]


def check(space: Any, dt: float, speeds: str = "both", tolerance: float = TOLERANCE,
          units: str | None = None) -> list[Finding]:
    """The checks that fail at step ``dt`` (s): each a :class:`Finding` with its fix (see
    :func:`survey` for the arguments; rows not checked are in :func:`survey` and
    :func:`report`, not here).

    Parameters
    ----------
    space, dt, speeds, tolerance, units
        As for :func:`survey`, whose failing rows these are.

    Returns
    -------
    list of Finding
        The checks that fail, each with its fix; [] when all pass.

    Raises
    ------
    UsageError
        An argument :func:`survey` refuses.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                  # a ball falling at 20 m/s onto a thin floor
    >>> ball = pymunk.Body(1.0, 1.0)
    >>> ball.position, ball.velocity = (0.0, 1.0), (0.0, -20.0)
    >>> floor = pymunk.Segment(space.static_body, (-1.0, 0.0), (1.0, 0.0), 0.01)
    >>> space.add(ball, pymunk.Circle(ball, 0.05), floor)
    >>> [(f.kind, f.subject) for f in spaces.check(space, 1 / 60)]
    [('tunnelling', 'body 0'), ('slop', 'space.collision_slop')]
    >>> space.collision_slop = 1e-4             # a setting: no step size fixes it
    >>> spaces.check(space, 1 / 600)            # 20 m/s * dt under 0.06 m, the half-widths
    []
    """
    return [f for f, ok in survey(space, dt, speeds, tolerance, units) if not ok and f.checked]


def substeps(space: Any, dt: float, speeds: str = "both", tolerance: float = TOLERANCE,
             units: str | None = None) -> int:
    """The fewest whole sub-steps of ``dt`` (s) that clear every finding a step can clear (see
    :func:`survey` for the arguments). A space in a state no step fixes (a NaN, a body without
    a mass) is refused.

    Parameters
    ----------
    space, dt, speeds, tolerance, units
        As for :func:`survey`; the springs' energy swing at the sub-step stays under
        ``tolerance``.

    Returns
    -------
    int
        Sub-steps per step, at least 1.

    Raises
    ------
    UsageError
        An argument :func:`survey` refuses; a space in a state no step fixes (naming the
        body and the value), or a ``dt`` that would need more than 10**9 sub-steps.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a wheel on a stiff rotary spring
    >>> wheel = pymunk.Body(1.0, 0.1)               # kg, kg m^2
    >>> space.add(wheel, pymunk.DampedRotarySpring(space.static_body, wheel, 0.0, 1000.0, 0.0))
    >>> spaces.substeps(space, 1 / 60)    # w = sqrt(1000 / 0.1) = 100 rad/s; w dt < 0.00995
    168
    """
    space, dt, speeds, tolerance, unit = _check(space, dt, speeds, tolerance, units)
    return _refuse(_advise(space, dt, speeds, tolerance, unit))


def suggest_dt(space: Any, dt: float, speeds: str = "both", tolerance: float = TOLERANCE,
               units: str | None = None) -> float:
    """A step (s) that clears every finding a step can clear: ``dt`` divided into the fewest
    whole sub-steps (so frames at ``dt`` stay whole); ``dt`` itself when nothing fails. The
    springs' energy swing at it is at most ``tolerance``; :func:`report` says what it is.

    Parameters
    ----------
    space, dt, speeds, tolerance, units
        As for :func:`substeps`.

    Returns
    -------
    float
        The sub-step (the space's time unit).

    Raises
    ------
    UsageError
        As for :func:`substeps`.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a bob on a spring, no gravity
    >>> bob = pymunk.Body(0.1, 1e-4)                # 0.1 kg on a 200 N/m spring: w = 44.7 rad/s
    >>> space.add(bob, pymunk.DampedSpring(bob, space.static_body, (0, 0), (0, 0), 0, 200, 0))
    >>> dt = spaces.suggest_dt(space, 1 / 60)       # 1/60 s in 75 whole sub-steps
    >>> round(dt, 10), dt == 1 / 60 / spaces.substeps(space, 1 / 60)
    (0.0002222222, True)
    """
    space, dt, speeds, tolerance, unit = _check(space, dt, speeds, tolerance, units)
    return dt / _refuse(_advise(space, dt, speeds, tolerance, unit))


def _line(f: Finding) -> str:
    mark = "ok  " if f.ok else ("FAIL" if f.checked else "--  ")
    shown = f.comparison()
    if not f.checked:
        return f"  {mark} {f.kind:14s} {f.subject:22s} {f.fix}"
    fix = "" if f.ok else (f"; {f.fix}" if shown else f.fix)
    note = f" ({f.note})" if f.ok and f.note else ""
    return f"  {mark} {f.kind:14s} {f.subject:22s} {shown}{note}{fix}"


def _summary(kind: str, rows: list[Finding], ok: bool) -> str:
    """One line for the rows of ``kind`` beyond the ones listed."""
    mark = "ok  " if ok else "FAIL"
    judged = [f for f in rows if f.relation in _FAILS] or rows

    def closeness(f: Finding) -> float:
        ratio = f.value / f.limit if f.limit else math.inf
        return ratio if not math.isnan(ratio) else -math.inf

    worst = max(judged, key=closeness)
    what = "passed; the closest to its limit" if ok else "failed; the farthest past it"
    return f"  {mark} {kind:14s} {len(rows)} more {what}: {worst.subject}, {worst.comparison()}"


def report(space: Any, dt: float, speeds: str = "both", tolerance: float = TOLERANCE,
           units: str | None = None) -> str:
    """The guard's report as text: every check with ok or its fix (a kind with many rows
    lists the first few and sums up the rest), the suggestion and its reason, and the springs'
    energy swing at the suggested step.

    Parameters
    ----------
    space, dt, speeds, tolerance, units
        As for :func:`survey`; ``units`` names the lengths in the lines (else they say
        'units').

    Returns
    -------
    str
        The report, one line per check.

    Raises
    ------
    UsageError
        An argument :func:`survey` refuses (a state no step fixes is reported, not
        refused).

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a pendulum: a bob on a 0.6 m pin
    >>> space.gravity = (0.0, -9.8)
    >>> bob = pymunk.Body(0.5, pymunk.moment_for_circle(0.5, 0, 0.05))
    >>> bob.position = (0.6, 0.0)
    >>> space.add(bob, pymunk.Circle(bob, 0.05), pymunk.PinJoint(space.static_body, bob))
    >>> print(spaces.report(space, 1 / 60, units="m"))
    step-size guard at dt = 0.0166667 s (lengths in m; energy swing of springs under 1 %, ...
      FAIL joint          PinJoint 0             0.1416 W > 0.03026 W; takes out 4.68 %/s ...
      joints measured on a copy of the space over 2 s: 120 steps of this dt (1 body), ...
      suggested: 6 sub-steps of each step, of 0.002778 s, for joint of PinJoint 0 ...
    """
    space, dt, speeds, tolerance, unit = _check(space, dt, speeds, tolerance, units)
    advice = _advise(space, dt, speeds, tolerance, unit)
    named = (f"lengths in {unit}" if units is not None
             else "lengths in the space's own units: pass units='m' or 'px' to name them")
    joints = any(f.kind == "joint" for f in advice.rows)
    tol = ("stability only" if math.isinf(tolerance)
           else f"energy swing of springs under {percent(tolerance)}"
                + (f", joints' drift under {percent(tolerance)}/s of the energy scale"
                   if joints else ""))
    lines = [f"step-size guard at dt = {dt:g} s ({named}; {tol}):"]
    kinds: dict[str, list[Finding]] = {}
    for f in advice.rows:
        kinds.setdefault(f.kind, []).append(f)
    for kind, rows in kinds.items():
        for ok in (False, True):
            these = [f for f in rows if f.ok == ok and f.checked]
            lines += [_line(f) for f in these[:SHOWN]]
            if len(these) > SHOWN:
                lines.append(_summary(kind, these[SHOWN:], ok))
        unchecked = [f for f in rows if not f.checked]
        lines += [_line(f) for f in unchecked[:SHOWN]]
        if len(unchecked) > SHOWN:
            rest = unchecked[SHOWN:]
            lines.append(f"  --   {kind:14s} {len(rest)} more not checked: "
                         f"{_listed([f.subject for f in rest])}")
        if kind == "joint" and advice.probe:
            lines.append(advice.probe)
    lines.append(_suggestion(advice, dt))
    return "\n".join(lines)


def _suggestion(advice: Any, dt: float) -> str:
    """The report's last line: the sub-steps suggested and why, or why none."""
    unchecked = [f.subject for f in advice.rows if not f.checked]
    n = advice.substeps
    swing = ("" if advice.swing is None else
             f"; the springs' energy swing at it: at most {percent(advice.swing)}")
    if any(f.kind == "state" for f in advice.rows):
        return "  no step is suggested: fix the state first"
    if n is None:
        t = advice.tightest
        return (f"  no step is suggested: {t.kind} of {t.subject} needs dt < "
                f"{t.dt_max:.3g} s, more than {MAX_STEPS:,} sub-steps of a step")
    if n > 1:
        t = advice.tightest
        return (f"  suggested: {n} sub-steps of each step, of {dt / n:.4g} s, for {t.kind} of "
                f"{t.subject} (needs dt < {t.dt_max:.4g} s){swing}")
    if any(not f.ok and f.checked for f in advice.rows):
        return f"  the step is fine; the failures are settings{swing}"
    if unchecked:
        return f"  nothing to fix in what was checked{swing}; not checked: {_listed(unchecked)}"
    return f"  nothing to fix{swing}"


def _listed(names: list[str]) -> str:
    """``names`` in a line: the first few and how many more."""
    shown = ", ".join(names[:SHOWN])
    return shown + (f" and {len(names) - SHOWN} more" if len(names) > SHOWN else "")
