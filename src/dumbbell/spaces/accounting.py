"""Energy and momentum of any pymunk space, from the per-body formulas of :mod:`dumbbell.model.energy`.

What counts: the space's DYNAMIC bodies. Each has a translational kinetic energy 1/2 m |v|^2
(v the velocity of its centre of gravity), a rotational one 1/2 I omega^2, a gravity potential
-m g.r (r its centre of gravity, zero at y = 0 along ``space.gravity``), a momentum m v and an
angular momentum. Springs add 1/2 k (d - rest)^2 (``DampedSpring``, d between the anchors in
world coordinates) and 1/2 k (a_a - a_b - rest)^2 (``DampedRotarySpring``, angles in rad).

What is reported instead of guessed:

- static and kinematic bodies (the user moves them; their energy is not the system's) are
  listed in ``skipped``; springs fixed to them still count, with the anchor where it is now;
- a body of infinite moment cannot turn (its spin is the user's to set), so its rotational
  energy is left out and the body listed in ``skipped`` if it spins;
- a spring with a custom force (or torque) function, a ``SimpleMotor`` and any constraint class
  not known here go to ``unknown``: their energy is not in ``E``. Joints that do no work
  (pivots, pins, slides, grooves, gears, limits, ratchets) hold no energy and are not listed;
- what takes energy out without a contact (``space.damping`` < 1, spring damping) is named in
  ``notes``.

The vectorized core (:func:`._what_counts.inventory`, :func:`._evaluation.evaluate`) also
serves the dumbbell's ``pymunk`` solver, which evaluates it over all its samples at once.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._evaluation import evaluate, read_state
from ._refusals import refuse_bad_state, refuse_overflow, refuse_settings
from ._what_counts import Skipped, inventory
from .units import UNNAMED, shown

__all__ = ["BodyEnergy", "Skipped", "SpaceEnergy", "SpringEnergy", "energy"]


@dataclass(frozen=True, repr=False)
class BodyEnergy:
    """One dynamic body: its label, mass (kg), moment (kg m^2), K_trans, K_rot, U_g (J),
    momentum (kg m/s) and angular momentum about the point asked for (kg m^2/s); in the
    space's ``units`` (length, mass, time), as :func:`energy` was told (not named when not).

    Parameters
    ----------
    subject : str
        Its label ('body 0').
    mass, moment : float
        kg and kg m².
    K_trans, K_rot, U_g : float
        Its energies (J).
    momentum : tuple of float
        (px, py) (kg m/s).
    L_about : float
        Angular momentum about the point asked for (kg m²/s).
    units : tuple of str, default ('units', 'mass units', 's')
        (length, mass, time), as :func:`energy` was told.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                    # a wheel moving at 3 m/s, spinning at 4 rad/s
    >>> wheel = pymunk.Body(2.0, 0.5)             # kg, kg m^2
    >>> wheel.velocity, wheel.angular_velocity = (3.0, 0.0), 4.0
    >>> space.add(wheel)
    >>> b = spaces.energy(space, units="m").bodies[0]
    >>> b.K_trans, b.K_rot, b.momentum           # 1/2 m v^2, 1/2 I w^2 (J), m v (kg m/s)
    (9.0, 4.0, (6.0, 0.0))
    """

    subject: str
    mass: float
    moment: float
    K_trans: float
    K_rot: float
    U_g: float
    momentum: tuple[float, float]
    L_about: float
    units: tuple[str, str, str] = UNNAMED

    __repr__ = shown


@dataclass(frozen=True, repr=False)
class SpringEnergy:
    """One spring: its label, kind and potential energy U (J; in the space's ``units``).

    Parameters
    ----------
    subject : str
        Its label ('DampedSpring 0').
    kind : str
        Its pymunk class.
    U : float
        Its potential energy (J).
    units : tuple of str, default ('units', 'mass units', 's')
        (length, mass, time), as for :class:`BodyEnergy`.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a rod twisted half a radian on a rotary spring
    >>> rod = pymunk.Body(1.0, pymunk.moment_for_segment(1.0, (-0.5, 0), (0.5, 0), 0.01))
    >>> rod.angle = 0.5                           # rad, twisted from its rest angle 0
    >>> space.add(rod, pymunk.DampedRotarySpring(space.static_body, rod, 0.0, 8.0, 0.0))
    >>> spaces.energy(space, units="m").springs[0]   # 1/2 k theta^2 = 1/2 8 0.5^2
    SpringEnergy('DampedRotarySpring 0', DampedRotarySpring: U = 1 J)
    """

    subject: str
    kind: str
    U: float
    units: tuple[str, str, str] = UNNAMED

    __repr__ = shown


@dataclass(frozen=True, repr=False)
class SpaceEnergy:
    """Energy and momentum of a space's dynamic bodies (in the ``units``
    :func:`energy` was given: (length, mass, time)).

    K_trans, K_rot, K_cm, K_int (= K_trans + K_rot - K_cm), U_g, U_spring and E = K_trans +
    K_rot + U_g + U_spring in J; ``momentum`` (px, py) in kg m/s; ``L_cm`` and ``L_about`` in
    kg m^2/s about the centre of mass ``cm`` (m) and about ``about`` (m). ``bodies`` and
    ``springs`` hold the parts; ``skipped``, ``unknown`` and ``notes`` what was left out.

    Parameters
    ----------
    K_trans, K_rot, K_cm, K_int, U_g, U_spring, E : float
        The energies (J).
    momentum : tuple of float
        (px, py) (kg m/s).
    L_cm, L_about : float
        Angular momentum (kg m²/s) about the centre of mass and about ``about``.
    about, cm : tuple of float
        The point asked for and the centre of mass (m).
    bodies : tuple of BodyEnergy
        One per dynamic body.
    springs : tuple of SpringEnergy
        One per spring.
    skipped, unknown : tuple of Skipped
        What was left out: bodies or constraints not counted, and constraints of a kind the
        accounting does not know.
    notes : tuple of str
        What else to know.
    units : tuple of str, default ('units', 'mass units', 's')
        As :func:`energy` was told (see :class:`BodyEnergy`).

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                  # a dumbbell: two 1 kg balls on a 1 m rod
    >>> a, b = pymunk.Body(1.0, 1e-3), pymunk.Body(1.0, 1e-3)
    >>> b.position = (1.0, 0.0)
    >>> a.velocity, b.velocity = (2.0, 1.0), (2.0, -1.0)     # m/s: flying and spinning
    >>> space.add(a, b, pymunk.PinJoint(a, b))
    >>> e = spaces.energy(space, units="m")
    >>> e.K_trans, e.K_cm, e.K_int              # J: the centre of mass's share, the rest
    (5.0, 4.0, 1.0)
    >>> e.momentum, e.L_cm, e.cm                # kg m/s, kg m^2/s about cm (m)
    ((4.0, 0.0), -1.0, (0.5, 0.0))
    """

    K_trans: float
    K_rot: float
    K_cm: float
    K_int: float
    U_g: float
    U_spring: float
    E: float
    momentum: tuple[float, float]
    L_cm: float
    L_about: float
    about: tuple[float, float]
    cm: tuple[float, float]
    bodies: tuple[BodyEnergy, ...]
    springs: tuple[SpringEnergy, ...]
    skipped: tuple[Skipped, ...]
    unknown: tuple[Skipped, ...]
    notes: tuple[str, ...]
    units: tuple[str, str, str] = UNNAMED

    @property
    def complete(self) -> bool:
        """True when nothing holding energy was left out (no unknown constraints)."""
        return not self.unknown

    __repr__ = shown

def energy(space: Any, about: tuple[float, float] = (0.0, 0.0),
           units: Any = None) -> SpaceEnergy:
    """Energy and momentum of ``space`` now; angular momentum also about ``about``.
    ``units`` names the space's units as the recorder takes them (the length unit alone,
    'px' or 'm', or (length, mass, time); None: not named, and the reprs say "energy units",
    never J for what may be pixels): the values are the same, their reprs carry them. See
    the module docstring for what is counted.

    Parameters
    ----------
    space : pymunk.Space
        Any space.
    about : tuple of float, default (0.0, 0.0)
        The point (length units) the angular momentum ``L_about`` is taken about.
    units : str or tuple of str or None, default None
        The space's units as the recorder takes them: the length unit alone ('px' or 'm'),
        or (length, mass, time); None: not named (reprs say "energy units", never J).

    Returns
    -------
    SpaceEnergy
        The energies, momenta and parts, frozen.

    Raises
    ------
    UsageError
        A ``space`` that is not a pymunk Space, or ``about`` or ``units`` not allowed.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball on a spring, SI units
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(0.1, pymunk.moment_for_circle(0.1, 0, 0.02))
    >>> ball.position = (0.3, 1.0)
    >>> spring = pymunk.DampedSpring(space.static_body, ball, (0.0, 1.5), (0.0, 0.0), 0.4,
    ...                              200.0, 0.0)
    >>> space.add(ball, pymunk.Circle(ball, 0.02), spring)
    >>> e = spaces.energy(space, units="m")
    >>> e
    SpaceEnergy(E = 4.33238484 J: K_trans = 0, K_rot = 0, U_g = 0.98, U_spring = 3.35238484 J; momentum = (0, 0) kg m/s, L_cm = 0 kg m²/s; 1 body, 1 spring, complete = True)
    >>> spaces.energy(space).E          # units not named: the same number, no J in its repr
    4.33238484...
    """
    from ..model import args
    from .units import check_units

    args.space(space)
    units = check_units(units)
    ox, oy = args.pair(about, "about", units[0])
    inv = inventory(space)
    st = read_state(inv)
    n = inv.dynamic
    refuse_bad_state(list(inv.labels[:n]), st, inv.mass, inv.moment)
    refuse_settings(space, inv)
    with np.errstate(over="ignore", invalid="ignore"):
        terms = evaluate(inv, st, (ox, oy))
    refuse_overflow(list(inv.labels[:n]), terms, st)

    def f(name: str) -> float:
        return float(terms[name][0])

    columns = (inv.labels[:n], inv.mass[:n].tolist(), inv.moment[:n].tolist(),
               terms["body_K_trans"][0].tolist(), terms["body_K_rot"][0].tolist(),
               terms["body_U_g"][0].tolist(), (inv.mass[:n] * st.vx[0, :n]).tolist(),
               (inv.mass[:n] * st.vy[0, :n]).tolist(), terms["body_L_about"][0].tolist())
    bodies = tuple(BodyEnergy(label, m, i, kt, kr, ug, (px, py), lo, units)
                   for label, m, i, kt, kr, ug, px, py, lo in zip(*columns, strict=True))
    springs = tuple(SpringEnergy(s.subject, s.kind, float(terms["spring_U"][0, j]), units)
                    for j, s in enumerate(inv.springs))
    return SpaceEnergy(
        K_trans=f("K_trans"), K_rot=f("K_rot"), K_cm=f("K_cm"), K_int=f("K_int"), U_g=f("U_g"),
        U_spring=f("U_spring"), E=f("E"), momentum=(f("px"), f("py")), L_cm=f("L_cm"),
        L_about=f("L_about"), about=(ox, oy), cm=(f("X"), f("Y")), bodies=bodies,
        springs=springs, skipped=inv.skipped, unknown=inv.unknown, notes=inv.notes,
        units=units,
    )
