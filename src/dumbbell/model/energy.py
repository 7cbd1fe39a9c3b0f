"""The energy partition: the one module that holds the energy formulas.

1D (textbook section 13.5.1), M = mA + mB, X and V the centre-of-mass position and velocity:

- ``K_cm = 1/2 M V^2``, ``K_int = 1/2 mA (vA - V)^2 + 1/2 mB (vB - V)^2``
- ``U_g = M g X``, ``U_spring = 1/2 k (xA - xB - b)^2``, ``E`` their sum (J)

2D, with d = rA - rB, L = |d|, u = d/L, w = vA - vB and mu the reduced mass:

- ``K_cm = 1/2 M |V|^2``, ``K_vib = 1/2 mu (w.u)^2``, ``K_rot = 1/2 mu |w x u|^2``
- ``K_spin = sum 1/2 I_i omega_i^2`` (only where particles may spin)
- ``U_g = M g R_y``, ``U_spring = 1/2 k (L - b)^2`` (only with a spring)

Where energy can leave the system, ``E_lost = E(0) - E(t)`` so that ``E + E_lost`` stays at E(0).
It is split in two: ``E_heat``, what the contacts dissipated (summed impact by impact from the
velocity jumps, ``1/2 m_eff (v_before^2 - v_after^2)`` at the contact point, or counted step by
step from pymunk's contact impulses, friction included), and ``E_err = E_lost - E_heat``, the
method's own energy error. ``E + E_heat + E_err`` stays at E(0).

2D trajectories also carry ``L_cm``, the angular momentum about the centre of mass
(kg m^2/s, counter-clockwise positive): ``sum m_i (r_i - R) x v_i = mu (d x w)`` for the two
particles (``I omega`` with ``I = mu L^2`` when they form a rigid body), plus each disc's spin
``1/2 m r^2 omega_i`` where particles may spin.
"""

from __future__ import annotations

import functools
import numbers
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import UsageError
from . import args

if TYPE_CHECKING:
    from .scene import Scene, System

#: Impacts with the floor (:class:`dumbbell.model.trajectory.Impact`: t, body, v_before,
#: v_after, heat), which this module reads by their fields.
Impacts = Iterable[Any]

#: State columns by name (m, m/s, rad/s), one value per sample.
Columns = Mapping[str, np.ndarray]

#: The public functions; the elementwise formulas below them (translational_ke, ...) are
#: building blocks that take numbers or arrays as they come, unchecked.
__all__ = ["angular_momentum_cm", "heat", "partition"]


def _number(value: Any, name: str, unit: str) -> float:
    """``value`` as a float, NaN and inf allowed (a run that blows up passes them through,
    and its verdict says so); UsageError naming ``name`` if it is not a number."""
    if type(value) is float:
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise UsageError(f"{name} = {args.show(value)}: must be a number ({unit})", param=name)
    return float(value)


def _length(column: Any) -> int:
    """How many samples a column holds (-1 for what is not a column: refused next)."""
    return len(column) if isinstance(column, np.ndarray | list | tuple) and np.ndim(column) else -1


def _state(scene: Scene, state: Any, n: int | None = None, name: str = "state"
           ) -> dict[str, np.ndarray]:
    """``state`` checked to be a dict of 1-d columns holding every state column of ``scene``
    (and the spins where the particles spin), all as long as the first (or ``n``)."""
    args.mapping(state, name, "a dict of state columns by name")
    needed = state_columns(scene) + ([f"omega{p}" for p in "AB"] if scene.system.discs
                                      else [])
    missing = [c for c in needed if c not in state]
    if missing:
        raise UsageError(f"{name} has no column {missing[0]!r}: needs {', '.join(needed)}",
                         param=name)
    if n is None:
        n = _length(state[needed[0]])
    return args.columns({c: state[c] for c in [*needed, *(["heat"] if "heat" in state else [])]},
                        n, name)


def _scene(scene: Any) -> Scene:
    """``scene`` as a Scene: a Scene passes as it is (it was checked when it was made),
    anything else is checked (a path is loaded)."""
    from .scene import Scene

    return scene if isinstance(scene, Scene) else args.scene(scene)


def state_columns(scene: Scene) -> list[str]:
    """Position and velocity columns of a scene (m, m/s), in CSV order."""
    if _scene(scene).system.dimensions == 1:
        return ["xA", "vA", "xB", "vB"]
    return ["xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB"]


def column_unit(name: str) -> str:
    """The SI unit of a CSV column: s, m, m/s, rad/s or J (ColumnError for another name)."""
    from ..errors import ColumnError

    if not isinstance(name, str):
        raise ColumnError(f"name = {args.show(name)}: must be a column name (str)", param="name")
    if name == "t":
        return "s"
    if name.startswith(("K_", "U_", "E")):
        return "J"
    if name == "L_cm":
        return "kg m^2/s"
    if name.startswith("omega"):
        return "rad/s"
    if name.startswith("v"):
        return "m/s"
    if name.startswith(("x", "y")):
        return "m"
    raise ColumnError(f"name = {args.show(name)}: no such column", param="name")


def spins(scene: Scene) -> bool:
    """True when the particles are spinning discs (:attr:`System.discs
    <dumbbell.model.system.System.discs>`, 2D only)."""
    return _scene(scene).system.discs


def energy_columns(scene: Scene) -> list[str]:
    """The energy terms (J) a scene can have, in CSV order; those it cannot have are left out."""
    scene = _scene(scene)
    if scene.system.dimensions == 1:
        cols = ["K_cm", "K_int", "U_g", "U_spring", "E"]
    else:
        cols = ["K_cm", "K_rot", "K_vib"]
        if scene.system.discs:
            cols.append("K_spin")
        cols.append("U_g")
        if scene.system.spring is not None:
            cols.append("U_spring")
        cols.append("E")
    if scene.system.dissipative:
        cols += ["E_lost", "E_heat", "E_err"]
    return cols


#: Energy columns that are bookkeeping of E, not parts of it.
BOOKKEEPING = ("E", "E_lost", "E_heat", "E_err")


def momentum_columns(scene: Scene) -> list[str]:
    """The angular-momentum columns (kg m^2/s) of a scene, after the energy terms in the CSV:
    ``L_cm`` in 2D, none in 1D."""
    return ["L_cm"] if _scene(scene).system.dimensions == 2 else []


def partition_1d(system: System, xA: np.ndarray, vA: np.ndarray, xB: np.ndarray,
                 vB: np.ndarray) -> dict[str, np.ndarray]:
    """1D partition of ``system`` (its masses in kg, spring in N/m and m, gravity in m/s^2)
    from positions and velocities (m, m/s). Returns K_cm, K_int, U_g, U_spring, E in J.

    >>> partition_1d(scene.system, *np.array([[1.2], [0.0], [1.0], [0.0]]))["E"]  # doctest: +SKIP
    array([2.156])
    """
    arrays = [np.ascontiguousarray(np.atleast_1d(a), dtype=np.float64) for a in (xA, vA, xB, vB)]
    constants = (float(system.A.mass), float(system.B.mass), float(system.k), float(system.b),
                 float(system.g))
    out = _loop_1d()(constants, *arrays)
    return dict(zip(("K_cm", "K_int", "U_g", "U_spring", "E"), out, strict=True))


@functools.cache
def _loop_1d():
    """The 1D partition as one compiled pass: a million rows cost milliseconds, not the tenths
    of a second that two dozen numpy temporaries do. Compiled on first use only."""
    from .._install import njit

    @njit(cache=True, nogil=True)
    def loop(constants, xA, vA, xB, vB):  # pragma: no cover
        mA, mB, k, b, g = constants
        M = mA + mB
        out = np.empty((5, xA.size))
        for i in range(xA.size):
            X = (mA * xA[i] + mB * xB[i]) / M
            V = (mA * vA[i] + mB * vB[i]) / M
            K_cm = 0.5 * M * V * V
            K_int = 0.5 * mA * (vA[i] - V) ** 2 + 0.5 * mB * (vB[i] - V) ** 2
            U_g = M * g * X
            stretch = xA[i] - xB[i] - b
            U_spring = 0.5 * k * stretch * stretch
            out[0, i] = K_cm
            out[1, i] = K_int
            out[2, i] = U_g
            out[3, i] = U_spring
            out[4, i] = K_cm + K_int + U_g + U_spring
        return out

    return loop


def partition_2d(system: System, rA: np.ndarray, vA: np.ndarray, rB: np.ndarray,
                 vB: np.ndarray) -> dict[str, np.ndarray]:
    """2D partition of ``system``; positions and velocities are (n, 2) arrays (m, m/s), y
    vertical. Returns K_cm, K_rot, K_vib, U_g, U_spring, E in J (K_spin is added by
    :func:`partition`)."""
    mA, mB, k, b, g = system.A.mass, system.B.mass, system.k, system.b, system.g
    M = mA + mB
    mu = mA * mB / M
    V = (mA * vA + mB * vB) / M
    Ry = (mA * rA[:, 1] + mB * rB[:, 1]) / M
    d = rA - rB
    L = np.hypot(d[:, 0], d[:, 1])
    w = vA - vB
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / L[:, None]
    # A zero-length axis has no direction: all relative motion then counts as vibration.
    degenerate = ~(L > 0)
    along = np.where(degenerate, np.hypot(w[:, 0], w[:, 1]), w[:, 0] * u[:, 0] + w[:, 1] * u[:, 1])
    across = np.where(degenerate, 0.0, w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0])
    K_cm = translational_ke(M, V[:, 0], V[:, 1])
    K_vib = 0.5 * mu * along**2
    K_rot = 0.5 * mu * across**2
    U_g = gravity_potential(M, 0.0, -g, 0.0, Ry)
    U_spring = spring_potential(k, L, b)
    return {"K_cm": K_cm, "K_rot": K_rot, "K_vib": K_vib, "U_g": U_g, "U_spring": U_spring,
            "E": K_cm + K_rot + K_vib + U_g + U_spring}


def translational_ke(mass: Any, vx: Any, vy: Any) -> Any:
    """Kinetic energy of a mass (kg) moving at (vx, vy) (m/s): 1/2 m |v|^2 (J).
    Works elementwise on numpy arrays."""
    return 0.5 * mass * (vx**2 + vy**2)


def rotational_ke(moment: Any, omega: Any) -> Any:
    """Kinetic energy of spin: 1/2 I omega^2 (J), moment I in kg m^2, omega in rad/s."""
    return 0.5 * moment * omega**2


def spring_potential(stiffness: Any, extent: Any, rest: Any) -> Any:
    """Potential of a linear spring, 1/2 k (x - rest)^2 (J): k in N/m with x, rest in m, or a
    rotary spring with k in N m/rad and x, rest in rad."""
    return 0.5 * stiffness * (extent - rest) ** 2


def gravity_potential(mass: Any, gx: float, gy: float, x: Any, y: Any) -> Any:
    """Potential of a mass (kg) at (x, y) (m) in uniform gravity (gx, gy) (m/s^2), zero at the
    origin: -m g.r (J). For a system, pass the total mass and the centre of mass."""
    return -(mass * gx) * x - (mass * gy) * y


def angular_momentum(
    mass: Any, x: Any, y: Any, vx: Any, vy: Any, ox: float = 0.0, oy: float = 0.0,
) -> Any:
    """Angular momentum (kg m^2/s, counter-clockwise positive) of a mass (kg) at (x, y) (m)
    moving at (vx, vy) (m/s) about the point (ox, oy) (m): m (r - o) x v. A body's own spin
    adds I omega."""
    return mass * ((x - ox) * vy - (y - oy) * vx)


def impact_heat(mass: float, v_before: float, v_after: float) -> float:
    """Energy (J) an impact dissipates: 1/2 m (v_before^2 - v_after^2), with ``mass`` (kg) the
    effective mass at the contact point (the particle's own for a free particle; for a rigid
    body 1 / (1/M + r_x^2 / I)) and the contact point's normal velocities (m/s)."""
    mass = _number(mass, "mass", "kg")
    v_before = _number(v_before, "v_before", "m/s")
    v_after = _number(v_after, "v_after", "m/s")
    return 0.5 * mass * (v_before * v_before - v_after * v_after)


def heat(scene: Scene, t: np.ndarray, state: Columns, events: Impacts) -> np.ndarray:
    """Energy the contacts dissipated up to each sample time: counted by the solver where the
    state has a ``heat`` column (pymunk), else summed over the impacts up to each sample (an
    impact's own ``heat``, or :func:`impact_heat` with the particle's mass).

    Parameters
    ----------
    scene : Scene
        The scene that was run (its masses, kg).
    t : numpy.ndarray
        Sample times (s).
    state : mapping of str to numpy.ndarray
        The state columns, each as long as ``t``.
    events : sequence of Impact
        The impacts.

    Returns
    -------
    numpy.ndarray
        The dissipated energy (J) at each time of ``t``: the trajectory's ``E_heat``.

    Raises
    ------
    UsageError
        Arguments of the wrong kind or columns of another length.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.energy import heat
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "friction-2d.toml")
    >>> traj = dumbbell.simulate(scene, t_end=1.0)
    >>> e_heat = heat(scene, traj.t, traj.state, traj.events)
    >>> bool(e_heat[-1] == traj["E_heat"][-1]), round(float(e_heat[-1]), 4)
    (True, 0.1629)
    """
    scene = args.scene(scene)
    t = np.asarray(args.array(t, "t", "s"))
    return _heat(scene, t, _state(scene, state, t.size), args.impacts(events))


def _heat(scene: Scene, t: np.ndarray, state: Columns, events: Impacts) -> np.ndarray:
    if "heat" in state:
        return np.asarray(state["heat"], dtype=float)
    mass = {"A": scene.system.A.mass, "B": scene.system.B.mass}
    times = np.array([e.t for e in events])
    amounts = np.array([e.heat if e.heat is not None
                        else impact_heat(mass[e.body], e.v_before, e.v_after)
                        for e in events])
    total = np.concatenate([[0.0], np.cumsum(amounts)])
    return total[np.searchsorted(times, t, side="right")] if len(times) else np.zeros(len(t))


def disc_inertia(mass: float, radius: float) -> float:
    """Moment of inertia of a uniform disc about its centre, 1/2 m r^2 (kg m^2)."""
    return _disc(args.real(mass, "mass", "kg"), args.real(radius, "radius", "m", lo=0.0))


def _disc(mass: float, radius: float) -> float:
    return 0.5 * mass * radius**2


def rigid_moment(scene: Scene) -> float:
    """Moment of inertia of a rigid dumbbell about its centre of mass (kg m^2): mu L^2 for the
    two point masses, plus each disc's own 1/2 m r^2 where the particles may spin."""
    scene = _scene(scene)
    if scene.system.rigid is None:
        raise UsageError(f"scene = {scene.name}: must be a rigid dumbbell (a [rigid] table)",
                         param="scene")
    system = scene.system
    moment = system.mu * system.rigid.length**2
    if system.discs:
        moment += _disc(system.A.mass, system.A.radius) + _disc(system.B.mass, system.B.radius)
    return moment


def _positions_velocities(state: Columns) -> tuple[np.ndarray, ...]:
    """rA, vA, rB, vB of a 2D state as (n, 2) arrays (m, m/s)."""
    return tuple(np.column_stack([state[f"{x}{body}"], state[f"{y}{body}"]])
                 for body in "AB" for x, y in (("x", "y"), ("vx", "vy")))


def _disc_spin(scene: Scene, state: Columns) -> np.ndarray:
    """K_spin, the discs' own 1/2 I omega^2 summed (J)."""
    return sum(rotational_ke(_disc(p.mass, p.radius), state[f"omega{p.name}"])
               for p in (scene.system.A, scene.system.B))


def partition(
    scene: Scene, t: np.ndarray, state: Columns, events: Impacts = (),
) -> dict[str, np.ndarray]:
    """All energy columns of a run, from its state: what a trajectory's energy columns are
    when its solver did not count them itself.

    Parameters
    ----------
    scene : Scene
        The scene that was run (masses in kg, spring in N/m and m, ``g`` in m/s²).
    t : numpy.ndarray
        Sample times (s), 1-d.
    state : mapping of str to numpy.ndarray
        The state columns (m, m/s, rad/s), each as long as ``t``.
    events : sequence of Impact, default ()
        The impacts (needed for ``E_heat`` on dissipative scenes).

    Returns
    -------
    dict of str to numpy.ndarray
        Each energy column (J) in ``energy_columns`` order: 1D ``K_cm``, ``K_int``,
        ``U_g``, ``U_spring``, ``E``; 2D ``K_rot``, ``K_vib`` (and ``K_spin``) in place of
        ``K_int``; ``E_lost``, ``E_heat``, ``E_err`` where energy can leave.

    Raises
    ------
    UsageError
        Arguments of the wrong kind, ``t`` not 1-d, or columns of another length.

    Examples
    --------
    The textbook's energy terms at the first three samples:

    >>> import dumbbell
    >>> from dumbbell.model.energy import partition
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=1.0, dt=1e-3)
    >>> parts = partition(scene, traj.t, traj.state, traj.events)
    >>> list(parts), parts["E"][:3]            # M g X = 0.2 x 9.8 x 1.1 J
    (['K_cm', 'K_int', 'U_g', 'U_spring', 'E'], array([2.156, 2.156, 2.156]))
    """
    scene = args.scene(scene)
    t = args.array(t, "t", "s")
    if t.ndim != 1:
        raise UsageError(f"t = {args.show(t)}: must be a 1-d array of times (s)", param="t")
    return _partition(scene, t, _state(scene, state, t.size), args.impacts(events))


def _partition(scene: Scene, t: np.ndarray, state: Columns, events: Impacts = (),
               ) -> dict[str, np.ndarray]:
    if scene.system.dimensions == 1:
        parts = partition_1d(scene.system, state["xA"], state["vA"], state["xB"], state["vB"])
    else:
        parts = partition_2d(scene.system, *_positions_velocities(state))
        if scene.system.discs:
            parts["K_spin"] = _disc_spin(scene, state)
            parts["E"] = parts["E"] + parts["K_spin"]
    return _with_losses(scene, t, state, events, parts)


def angular_momentum_cm(scene: Scene, state: Columns) -> np.ndarray:
    """Angular momentum about the centre of mass at each sample of a 2D run: the particles'
    ``m (r - R) x v`` summed (= mu d x w, or I omega for the rigid body), plus the discs' own
    spin ``1/2 m r^2 omega_i`` where particles may spin.

    Parameters
    ----------
    scene : Scene
        A 2D scene (masses in kg, radii in m).
    state : mapping of str to numpy.ndarray
        Its state columns (m, m/s, rad/s).

    Returns
    -------
    numpy.ndarray
        ``L_cm`` (kg m²/s, counter-clockwise positive) at each sample.

    Raises
    ------
    UsageError
        A 1D scene, or state columns missing or of unequal lengths.

    Examples
    --------
    The rigid dumbbell: no spin before its first impact, then a steady one.

    >>> import dumbbell
    >>> from dumbbell.model.energy import angular_momentum_cm
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=0.6, dt=1e-3)
    >>> L = angular_momentum_cm(scene, traj.state)   # none before the impact, then a spin
    >>> float(L[0]), round(float(L[-1]), 4)
    (0.0, -0.0708)
    """
    scene = args.scene(scene)
    if scene.system.dimensions != 2:
        raise UsageError(f"scene = {scene.name}: must be a 2D scene (dimensions = 2)",
                         param="scene")
    state = _state(scene, state)
    mA, mB = scene.system.A.mass, scene.system.B.mass
    M = mA + mB
    Rx = (mA * state["xA"] + mB * state["xB"]) / M
    Ry = (mA * state["yA"] + mB * state["yB"]) / M
    total = sum(angular_momentum(p.mass, state[f"x{p.name}"], state[f"y{p.name}"],
                                 state[f"vx{p.name}"], state[f"vy{p.name}"], Rx, Ry)
                for p in (scene.system.A, scene.system.B))
    if spins(scene):
        total = total + sum(disc_inertia(p.mass, p.radius) * state[f"omega{p.name}"]
                            for p in (scene.system.A, scene.system.B))
    return np.asarray(total, dtype=float)


def _with_losses(
    scene: Scene, t: np.ndarray, state: Columns, events: Impacts,
    parts: dict[str, np.ndarray],
) -> dict[str, np.ndarray]:
    """``parts`` in :func:`energy_columns` order, with E_lost = E(0) - E, E_heat (:func:`heat`)
    and E_err = E_lost - E_heat added where the scene is dissipative (J)."""
    if scene.system.dissipative:
        parts["E_lost"] = parts["E"][0] - parts["E"] if len(parts["E"]) else parts["E"]
        parts["E_heat"] = _heat(scene, t, state, events)
        parts["E_err"] = parts["E_lost"] - parts["E_heat"]
    return {name: parts[name] for name in energy_columns(scene)}


def partition_from_terms(
    scene: Scene, t: np.ndarray, state: Columns, events: Impacts,
    terms: Columns,
) -> dict[str, np.ndarray]:
    """The dumbbell's energy columns (J, :func:`energy_columns` order) from the general
    accounting of its bodies over the same samples (``terms``: K_cm, K_int, K_rot (the bodies'
    own spin), U_g, U_spring, E, as :func:`dumbbell.spaces._evaluation.evaluate` gives them);
    ``t``, ``state`` and ``events`` as for :func:`partition`.

    K_cm, K_int (1D), U_g, U_spring and E are the accounting's. In 2D the internal motion is
    split the dumbbell's way, which the general accounting does not know: K_rot and K_vib of
    the axis from :func:`partition_2d`, and K_spin, the particles' own spin (the bodies' K_rot
    when each particle is a body; the discs' share of the one body when rigid). Equal to
    :func:`partition` to rounding where pymunk's model is the scene's (see docs/spaces-reference.md)."""
    parts = {name: terms[name] for name in ("K_cm", "U_g", "U_spring", "E")}
    if scene.system.dimensions == 1:
        parts["K_int"] = terms["K_int"]
    else:
        system = scene.system
        axis = partition_2d(system, *_positions_velocities(state))
        parts["K_rot"], parts["K_vib"] = axis["K_rot"], axis["K_vib"]
        if system.discs:
            parts["K_spin"] = (terms["K_rot"] if system.rigid is None
                               else _disc_spin(scene, state))
    return _with_losses(scene, t, state, events, parts)


#: Energies below this fraction of a scene's own energy (:func:`scene_energy`) are rounding,
#: not motion: the floor of the energy scale. A dumbbell at rest carries a spring energy of
#: the rounding of its stretch, about (2.2e-16 H / l)^2 of 1/2 k l^2 at a height H at most
#: (the textbook's at rest: 3e-31 J, 8e-32 of it); 1e-12 lies far above that and far below
#: any motion simulated on purpose (a stretch of 1.4e-6 l carries 1e-12 of 1/2 k l^2).
ROUNDING_FLOOR = 1e-12


def scene_energy(system: System) -> float:
    """The energy the scene's own numbers give, whatever its start (J): the larger of the
    spring's 1/2 k l^2 and the weight's M g l, with l the dumbbell's length (the largest of
    the spring's rest length, the rod and the particles' starting distance); 0 for a
    dumbbell with neither spring nor gravity, or of no length."""
    A, B = system.A, system.B
    length = max(system.b, system.rigid.length if system.rigid is not None else 0.0,
                 float(np.hypot(A.x - B.x, A.height - B.height)))
    return max(0.5 * system.k * length**2, system.M * abs(system.g) * length)


def energy_scale(E0: float, terms_at_start: dict[str, float] | None = None,
                 scene: Any = None) -> float:
    """The scale (J) that relative energy errors are taken against: the largest of |E(0)|
    and the single terms at the start (|K_cm|, |U_g|, ...), and, given the ``scene`` (a Scene
    or a path), :data:`ROUNDING_FLOOR` times its :func:`scene_energy`, so that a state at rest
    up to rounding is not its own scale; 1 J if all of them vanish (then nothing moves)."""
    E0 = args.real(E0, "E0", "J", positive=False)
    if terms_at_start is not None:
        args.mapping(terms_at_start, "terms_at_start", "a dict of energy terms (J) or None")
        terms_at_start = {key: args.real(v, "terms_at_start", "J", positive=False)
                          for key, v in terms_at_start.items()}
    system = None if scene is None else _scene(scene).system
    return _energy_scale(E0, terms_at_start, system)


def _energy_scale(E0: float, terms_at_start: Mapping[str, float] | None,
                  system: System | None = None) -> float:
    scale = abs(E0)
    if terms_at_start:
        scale = max(scale, max(abs(v) for v in terms_at_start.values()))
    if system is not None:
        scale = max(scale, ROUNDING_FLOOR * scene_energy(system))
    return scale if scale > 0 else 1.0


def relative_energy_error(energy: Columns, scene: Any = None) -> np.ndarray:
    """|E(t) - E(0)| / scale for every sample (dimensionless) of the energy columns ``energy``
    (J, as :func:`partition` gives them), scale from :func:`energy_scale` (with the floor of
    the ``scene`` it was run from, when given)."""
    args.mapping(energy, "energy", "a dict of energy columns (J) by name")
    if "E" not in energy:
        raise UsageError("energy has no column 'E': must hold the total energy E (J)",
                         param="energy")
    system = None if scene is None else _scene(scene).system
    return _relative_energy_error(args.columns(energy, _length(energy["E"]), "energy"), system)


def _relative_energy_error(energy: Columns, system: System | None = None) -> np.ndarray:
    E = energy["E"]
    if len(E) == 0:
        return E
    return np.abs(E - E[0]) / _start_scale(energy, system)


def _start_scale(energy: Columns, system: System | None = None) -> float:
    """The :func:`energy_scale` of energy columns (J) at their first sample, with the floor
    of ``system`` when given."""
    terms = {name: float(v[0]) for name, v in energy.items() if name not in BOOKKEEPING}
    return _energy_scale(float(energy["E"][0]), terms, system)
