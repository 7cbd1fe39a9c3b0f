"""The typed records the ledger's parts pass each other (arrays are (3, rows): x, y, angle
or their rates, rows as :class:`._inventory.Table` orders the bodies).

- :class:`Snapshot`: the state between steps, which the next step starts from;
- :class:`Energy`: E and its parts at a snapshot;
- :class:`Move`: pymunk's move at the start of a step, as the ledger reconstructs it;
- :class:`Potentials`: the springs' and declared fields' potentials over that move;
- :class:`Before`: what the hook read before the solver, for the hook after it;
- :class:`Step`: one step as the sources' work reads it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Snapshot(NamedTuple):
    """The bodies' state (positions, velocities, the bias velocities the next move adds,
    and which dynamic rows sleep), the springs' and fields' potentials there, and whether
    any body sleeps and any bias velocity is not 0 (found once, read by every step)."""

    pos: np.ndarray
    vel: np.ndarray
    bias: np.ndarray
    sleeping: np.ndarray
    us: list[np.ndarray]
    ud: np.ndarray
    asleep: bool
    biased: bool


class Energy(NamedTuple):
    """E and its parts at a snapshot (energy units): the totals, and per dynamic row the
    body's own energy (K + U_g + declared fields), U_g and the fields' part."""

    E: float
    K: float
    Ug: float
    Us: float
    Ud: float
    body: np.ndarray
    Ugb: np.ndarray
    Udb: np.ndarray


class Move(NamedTuple):
    """pymunk's move at the start of a step: positions after it and velocities (3, rows),
    where each body started, and how long each moved (s; one dt for all, or per row)."""

    pos: np.ndarray
    vel: np.ndarray
    start: np.ndarray
    step: np.ndarray | float


class Potentials(NamedTuple):
    """The springs' and declared fields' potentials over a move: each spring group's
    change (less the position correction's part) and end value, the fields' change per
    dynamic row (None without springs or fields) and end value."""

    spring_int: list[np.ndarray]
    u_end: list[np.ndarray]
    d_int: np.ndarray | None
    d_end: np.ndarray


class Before(NamedTuple):
    """What the hook before the solver hands to the hook after it: the step (``dt``, and
    ``coef`` = dt / previous dt, how much of the carried impulses pymunk applies), the
    move, the applied forces (None when none), which dynamic rows are awake (None: all),
    gravity's potential change over the move (total, and per row when custom velocity
    functions need it), the potentials, each constraint group's accumulators as they came
    in, whether contacts were read, and the energy counted so far in the step."""

    dt: float
    coef: float
    move: Move
    force: np.ndarray | None
    awake: np.ndarray | None
    g_int: float
    g_rows: np.ndarray | None
    potentials: Potentials
    initial: list[np.ndarray]
    contacts: bool
    total: float


class Step(NamedTuple):
    """One step as the sources' work reads it: ``dt`` (s), ``coef``, the positions after
    the move and the velocities before and after the solver (3, rows), ``u`` their mean,
    which the sources act on; ``imp`` collects the impulses applied to each row (3, rows),
    ``kick`` the springs' elastic ones (None unless ``space.damping`` needs them) and
    ``spring_int`` is each spring group's potential change over the move."""

    dt: float
    coef: float
    pos: np.ndarray
    vel0: np.ndarray
    vel1: np.ndarray
    u: np.ndarray
    work: np.ndarray
    kick: np.ndarray | None
    spring_int: list[np.ndarray]
