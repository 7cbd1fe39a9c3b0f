"""Apparent restitution of a tilted dumbbell: the centre of mass's rebound against the tilt.

Drop a rigid dumbbell with its axis tilted theta from vertical on a floor of restitution e. The
floor's impulse J acts at B, off the line through the centre of mass, so it both reverses the
contact point's velocity (to -e times itself) and sets the body turning. With q = M a_B^2 / I
(a_B the distance from the centre of mass to B, I the moment about the centre of mass) the
impulse law gives the centre of mass's apparent restitution

    e_eff = -V_after / V_before = (e - q sin^2 theta) / (1 + q sin^2 theta),

q = 1 for two equal point masses: e_eff(30 degrees) = 0.6 for e = 1. Past sin^2 theta = e/q the
centre of mass keeps moving down after the "bounce". A spring dumbbell differs: the floor
pushes one particle at a time, and the first impact is followed by more (the other particle,
chatter) before the dumbbell leaves the floor; :func:`bounce` measures the whole cluster.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.energy import rigid_moment
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from .rotation import variant

__all__ = ["Bounce", "RestitutionResult", "bounce", "e_eff_rigid", "restitution"]

#: Impacts closer together than this (s) belong to one cluster.
CLUSTER_GAP = 0.1
#: Spring constants (N/m) of the spring dumbbells beside the rigid one.
STIFFNESSES = (200.0, 2e3, 2e4)


def _formula_args(theta_deg: Any, e: Any, q: Any) -> tuple[np.ndarray, float, float]:
    """The formulas' arguments at the border: tilts (degrees), 0 <= e <= 1, q > 0."""
    return (args.array(theta_deg, "theta_deg", "degrees"),
            args.real(e, "e", "floor restitution", lo=0.0, hi=1.0),
            args.real(q, "q", "M a_B^2 / I"))


def e_eff_rigid(theta_deg: np.ndarray | float, e: float, q: float = 1.0) -> np.ndarray:
    """The rigid dumbbell's apparent restitution, (e - q sin² θ) / (1 + q sin² θ): minus the
    centre of mass's vertical velocity after its first impact over before.

    Parameters
    ----------
    theta_deg : float or array_like
        The tilt (degrees from vertical).
    e : float
        The floor's restitution, 0..1.
    q : float, default 1.0
        M a_B² / I (1 for two equal point masses).

    Returns
    -------
    numpy.ndarray
        e_eff (dimensionless), one per tilt.

    Raises
    ------
    UsageError
        A tilt, ``e`` or ``q`` that is not allowed.

    Examples
    --------
    >>> from dumbbell.analysis.restitution import e_eff_rigid
    >>> e_eff_rigid([0.0, 30.0, 60.0], 1.0)      # upright, it bounces as the floor does
    array([1.        , 0.6       , 0.14285714])
    """
    theta_deg, e, q = _formula_args(theta_deg, e, q)
    s2 = np.sin(np.radians(theta_deg)) ** 2
    return (e - q * s2) / (1.0 + q * s2)


def sign_change_deg(e: float, q: float = 1.0) -> float:
    """The tilt (degrees) past which e_eff turns negative: sin^2 theta = e/q; nan if never."""
    _, e, q = _formula_args(0.0, e, q)
    return math.degrees(math.asin(math.sqrt(e / q))) if e <= q else math.nan


def k_rot_share_rigid(theta_deg: np.ndarray | float, e: float, q: float = 1.0) -> np.ndarray:
    """Share of the kinetic energy before the impact that the rigid dumbbell has as K_rot
    right after it (dimensionless): (1 + e)^2 q sin^2 theta / (1 + q sin^2 theta)^2."""
    theta_deg, e, q = _formula_args(theta_deg, e, q)
    s2 = np.sin(np.radians(theta_deg)) ** 2
    return (1.0 + e) ** 2 * q * s2 / (1.0 + q * s2) ** 2


def rigid_q(scene: Scene) -> float:
    """q = M a_B^2 / I of the scene's dumbbell made rigid (dimensionless): a_B = mA L / M."""
    scene = args.scene(scene)
    s = scene if scene.system.rigid is not None else variant(scene, None)
    a_B = s.system.A.mass * s.system.rigid.length / s.system.M
    return s.system.M * a_B**2 / rigid_moment(s)


@dataclass(frozen=True)
class Bounce:
    """What one drop did at the floor: what :func:`bounce` measures. Every velocity is carried
    along the free fall to its impact's time.

    Parameters
    ----------
    e_first : float
        -V_y after / V_y before the first impact (dimensionless).
    e_cluster : float
        V_y as the dumbbell leaves the floor after the whole first cluster of impacts (at its
        last impact) over -V_y before the first.
    impacts : int
        Impacts in the cluster.
    share_first, share_cluster : float
        K_rot right after the first impact and after the cluster, over the kinetic energy
        just before the first impact.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.analysis.restitution import bounce
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")       # tilted 30 deg
    >>> bounce(dumbbell.simulate(scene, solver="exact", t_end=0.6, dt=1e-4))
    <Bounce e_first=0.6, e_cluster=0.6 after 1 impact, K_rot share 0.64 after the first, 0.64 after the cluster>
    """

    e_first: float
    e_cluster: float
    impacts: int
    share_first: float
    share_cluster: float

    def __repr__(self) -> str:
        from .._display import one_line

        impacts = counted(self.impacts, "impact")
        return one_line(f"<Bounce e_first={self.e_first:.6g}, e_cluster={self.e_cluster:.6g} "
                        f"after {impacts}, K_rot share {self.share_first:.3g} after the first, "
                        f"{self.share_cluster:.3g} after the cluster>")

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(repr(self), ["", "e_eff", "K_rot / K before"],
                          [("first impact", self.e_first, self.share_first),
                           (f"first cluster ({counted(self.impacts, 'impact')})", self.e_cluster,
                            self.share_cluster)])


def _cm_vy(traj: Trajectory) -> np.ndarray:
    s = traj.scene
    return (s.system.A.mass * traj["vyA"] + s.system.B.mass * traj["vyB"]) / s.system.M


def bounce(traj: Trajectory, gap: float = CLUSTER_GAP) -> Bounce:
    """Measure the first impact cluster of a tilted drop. Velocities are read at the samples
    on either side and carried to the impact's time with the free fall's -g, so sampling does
    not bias them.

    Parameters
    ----------
    traj : Trajectory
        A 2D drop that runs on ``gap`` s past its first cluster of impacts.
    gap : float, default 0.1
        Seconds without an impact that end a cluster.

    Returns
    -------
    Bounce
        The apparent restitution and the K_rot share, after the first impact and after the
        cluster.

    Raises
    ------
    UsageError
        A 1D run, a run without an impact, or one that ends within ``gap`` of its cluster.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.analysis.restitution import bounce, e_eff_rigid
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> drop = bounce(dumbbell.simulate(scene, solver="exact", t_end=0.6, dt=1e-4))
    >>> round(float(drop.e_first), 12), round(float(e_eff_rigid(30.0, 1.0)), 12)  # formula
    (0.6, 0.6)
    """
    traj = args.trajectory(traj)
    gap = args.real(gap, "gap", "s")
    return _bounce(traj, gap, cluster=True)


def _bounce(traj: Trajectory, gap: float, cluster: bool) -> Bounce:
    """:func:`bounce`; without ``cluster`` only the first impact is measured (``e_cluster``
    and ``share_cluster`` then repeat ``e_first`` and ``share_first``), so the run may end
    right after it: a rigid drop on a nearly inelastic floor comes to rest in a cluster
    that never ends, and the exact solver stops there."""
    if traj.scene.system.dimensions != 2:
        raise UsageError(f"traj: {traj.scene.source} is 1D; a tilted drop is measured in 2D",
                         param="traj")
    s = traj.scene
    times = [e.t for e in traj.events]
    n, at_rest = _first_cluster(traj, gap, cluster)
    t0, t_last = times[0], times[n - 1]
    vy = _cm_vy(traj)
    g = s.system.g
    i_before = int(np.searchsorted(traj.t, t0, side="left")) - 1
    # The sample before the impact, carried forward to the impact's time.
    v_before = vy[i_before] - g * (t0 - traj.t[i_before])
    K_before = float(traj["K_cm"][i_before] + traj["K_rot"][i_before] + traj["K_vib"][i_before])
    # Gravity does work between that sample and the impact: carry K by the change of K_cm only
    # (between impacts, gravity acts on the centre of mass alone).
    K_before += 0.5 * s.system.M * (v_before**2 - vy[i_before] ** 2)

    spacing = float(traj.t[1] - traj.t[0]) if len(traj.t) > 1 else 0.0

    def after(t_imp: float, t_next: float) -> tuple[int, float]:
        # A sample two spacings past the impact (a stepping engine may spread a contact over
        # a step or two), unless the next impact comes first; carried back along the free
        # fall to the impact's own time, when the dumbbell leaves the floor.
        i = int(np.searchsorted(traj.t, t_imp + 1.5 * spacing, side="right"))
        if i >= len(traj.t) or traj.t[i] >= t_next:
            i = int(np.searchsorted(traj.t, t_imp, side="right"))
        if i >= len(traj.t):
            raise UsageError(f"{s.source}: the run ends at the impact at {t_imp:g} s "
                             f"({traj.verdict}), so the velocity after it is not known")
        return i, float(vy[i] + g * (traj.t[i] - t_imp))

    t_next_first = times[1] if n > 1 or (not cluster and len(times) > 1) else math.inf
    i_f, v_first = after(t0, t_next_first)
    if at_rest:  # it does not leave the floor again: V after the cluster is 0
        i_c, v_cluster = len(traj.t) - 1, 0.0
    else:
        i_c, v_cluster = after(t_last, times[n] if n < len(times) else math.inf)
    if v_before >= 0:
        raise UsageError(f"{s.source}: the centre of mass is not falling at the first impact")
    K_rot = traj["K_rot"]
    return Bounce(-v_first / v_before, -v_cluster / v_before, n,
                  float(K_rot[i_f]) / K_before, float(K_rot[i_c]) / K_before)


def _first_cluster(traj: Trajectory, gap: float, cluster: bool) -> tuple[int, bool]:
    """How many impacts the first cluster of ``traj`` holds (impacts less than ``gap`` s
    apart; 1 without ``cluster``), and whether the dumbbell comes to rest on the floor
    after it before the run ends; a UsageError when that is not known."""
    s = traj.scene
    times = [e.t for e in traj.events]
    if not times:
        raise UsageError(f"{s.source}: no impact in this run (t_end = {float(traj.t[-1]):g} "
                         "s); run longer")
    if not cluster:
        return 1, False
    n = 1
    while n < len(times) and times[n] - times[n - 1] <= gap:
        n += 1
    t_last = times[n - 1]
    if float(traj.t[-1]) >= t_last + gap:
        return n, False
    # No flight of gap s after the last impact before the run ends: the cluster is over
    # only if the dumbbell can no longer make one (it is coming to rest on the floor).
    if not _settled(traj, gap):
        raise UsageError(f"{s.source}: the dumbbell still has the energy to leave the floor "
                         f"for {gap:g} s when the drop's run ends at "
                         f"{float(traj.t[-1]):g} s (last impact at {t_last:g} s), so the "
                         "end of its first cluster of impacts is not known")
    return n, True


def _settled(traj: Trajectory, gap: float) -> bool:
    """Whether the dumbbell of ``traj`` can no longer leave the floor for ``gap`` s after its
    last sample: a flight that long needs the centre of mass to rise at g gap / 2 or faster,
    kinetic energy M (g gap)^2 / 8, which must come out of E above its least value on the
    floor, M g y_rest with both particles resting on it (y_rest = (mA rA + mB rB) / M)."""
    s = traj.scene.system
    y_rest = (s.A.mass * s.A.radius + s.B.mass * s.B.radius) / s.M
    spare = float(traj["E"][-1]) - s.M * s.g * y_rest
    return spare < s.M * (s.g * gap) ** 2 / 8


def tilted(scene: Scene, theta_deg: float, stiffness: float | None = None) -> Scene:
    """``scene``'s dumbbell tilted ``theta_deg`` (degrees from vertical), rigid when
    ``stiffness`` is None, else a spring of that stiffness (N/m) at the same length."""
    theta_deg = args.real(theta_deg, "theta_deg", "degrees", positive=False)
    return variant(scene, stiffness, theta_deg)


def _check_scene(scene: Scene) -> None:
    if scene.system.dimensions != 2 or (scene.system.spring is None and scene.system.rigid is None):
        raise UsageError(f"{scene.source}: restitution needs a 2D dumbbell with a [spring] or "
                         "[rigid] (dimensions = 2)")
    if scene.system.floor is None or scene.system.g <= 0:
        raise UsageError(f"{scene.source}: restitution needs a [floor] and gravity (g > 0)")
    if scene.system.floor.friction != 0:
        raise UsageError(f"{scene.source}: restitution needs a frictionless floor "
                         "(floor.friction = 0): the formula has no friction")
    if scene.system.B.height <= 0 or scene.system.B.vy > 0:
        raise UsageError(f"{scene.source}: restitution drops the dumbbell: bodies.B.height "
                         "must be > 0 and B must not move up")


def drop_duration(scene: Scene) -> float:
    """Run time (s) that covers the fall, the first cluster of impacts and the gap after it."""
    scene = args.scene(scene)
    g, h, v = scene.system.g, scene.system.B.height, -scene.system.B.vy
    t_fall = (-v + math.sqrt(v * v + 2 * g * h)) / g if g > 0 else h / max(v, 1e-9)
    return t_fall + 0.4


def truth_for(scene: Scene) -> str:
    """The name of the most exact solver that runs ``scene`` (rigid or spring, 2D)."""
    scene = args.scene(scene)
    from ..solvers import METHODS

    for name, cls in METHODS.items():
        if cls.is_truth and cls.supports(scene) is None:
            return name
    raise UsageError(f"{scene.source}: no truth solver runs this scene")


@dataclass(frozen=True)
class RestitutionResult:
    """e_eff against tilt: the formula, the rigid dumbbell in the truth and in pymunk (first
    impact), each spring dumbbell (after the first cluster, with its impacts and K_rot
    share). What :func:`restitution` returns.

    Parameters
    ----------
    theta : numpy.ndarray
        The tilts (degrees).
    e : float
        The floor's restitution.
    q : float
        M a_B² / I.
    formula, truth, pymunk : numpy.ndarray
        e_eff by :func:`e_eff_rigid`, by the truth's rigid run, and by pymunk's.
    truth_solver : str
        The truth's solver.
    pymunk_dt : float
        pymunk's step (s).
    springs : dict of float to dict of str to numpy.ndarray
        Stiffness (N/m) -> its ``e_eff``, ``impacts`` and ``K_rot_share`` columns.
    rigid_k_rot_share, rigid_impacts : numpy.ndarray or None
        The rigid dumbbell's K_rot share right after its first impact (like its e_eff), and
        its impacts.

    Examples
    --------
    Two tilts, the rigid dumbbell only (no spring runs):

    >>> import dumbbell
    >>> from dumbbell.analysis.restitution import restitution
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> result = restitution(scene, [0.0, 30.0], stiffnesses=(), dt=1e-4)
    >>> result
    <RestitutionResult e=1, q=1: 2 tilts 0..30 deg; exact within 0 of the formula>
    >>> list(result.columns())
    ['theta', 'formula', 'truth', 'pymunk', 'rigid_impacts', 'rigid_K_rot_share']
    """

    theta: np.ndarray
    e: float
    q: float
    formula: np.ndarray
    truth: np.ndarray
    truth_solver: str
    pymunk: np.ndarray
    pymunk_dt: float
    springs: dict[float, dict[str, np.ndarray]] = field(default_factory=dict)
    rigid_k_rot_share: np.ndarray | None = None
    rigid_impacts: np.ndarray | None = None

    def __repr__(self) -> str:
        """One line: e, q, the tilts, the truth against the formula, the springs."""
        from .._display import one_line

        n = len(self.theta)
        tilts = (f"{counted(n, 'tilt')} {self.theta[0]:g}..{self.theta[-1]:g} deg" if n
                 else "no tilts")
        gap = float(np.max(np.abs(self.truth - self.formula))) if n else math.nan
        springs = ", ".join(f"{k:g}" for k in self.springs)
        return one_line(f"<RestitutionResult e={self.e:g}, q={self.q:.4g}: {tilts}; "
                        f"{self.truth_solver} within {gap:.2g} of the formula"
                        + (f"; springs k = {springs} N/m" if springs else "") + ">")

    def _repr_html_(self) -> str:
        """The one-line summary above one row per tilt: the CSV's columns."""
        from .._display import html_table

        cols = self.columns()
        return html_table(repr(self), list(cols), zip(*cols.values(), strict=True))

    @property
    def sign_change(self) -> float:
        """Tilt (degrees) past which the rigid e_eff is negative; nan if never."""
        return sign_change_deg(self.e, self.q)

    def columns(self) -> dict[str, np.ndarray]:
        """The CSV's columns by name, in order.

        Returns
        -------
        dict of str to numpy.ndarray
            ``theta``, ``formula``, ``truth``, ``pymunk``, the rigid dumbbell's impacts and
            K_rot share, then ``k{stiffness}_{e_eff, impacts, K_rot_share}`` per spring.
        """
        out = {"theta": self.theta, "formula": self.formula, "truth": self.truth,
               "pymunk": self.pymunk}
        if self.rigid_impacts is not None:
            out["rigid_impacts"] = self.rigid_impacts
            out["rigid_K_rot_share"] = self.rigid_k_rot_share
        for k, cols in self.springs.items():
            for name, col in cols.items():
                out[f"k{k:g}_{name}"] = col
        return out


def _check_samples(rigid: Scene, dt: float, t_end: float) -> None:
    """UsageError before anything runs when a rigid run of the drop, which keeps every step
    (pymunk at ``dt``, the truth at the scene's run.dt; s), would keep more samples than
    :data:`~dumbbell.solvers.MAX_SAMPLES`."""
    from ..solvers import MAX_SAMPLES, make_options

    for step, what, fix in ((dt, "dt", "use a larger {dt}"),
                            (rigid.run.dt, "run.dt", "use a larger run.dt in the scene")):
        samples = make_options(rigid, dt=step, t_end=t_end).n_samples
        if samples > MAX_SAMPLES:
            raise UsageError(f"{what} = {step:g} s over the drop's {t_end:g} s: a rigid run "
                             f"would keep {samples:,} samples, past the budget of "
                             f"{MAX_SAMPLES:,}", param="dt" if what == "dt" else None,
                             fixes=(fix,))


#: Most pymunk steps one :func:`restitution` call may take in all: about 2.5 minutes of CPU
#: on the 2-core test machine at its measured 3.5e5 steps/s (91 tilts with the default
#: springs take 3.1e7 steps; docs/hardening.md).
MAX_PYMUNK_STEPS = 5 * 10**7


def _check_work(scene: Scene, thetas: np.ndarray, stiffnesses: tuple[float, ...],
                dt: float, t_end: float) -> None:
    """UsageError before any run when the drops (tilts x (the rigid dumbbell + the
    springs)) would be more than :data:`~.budget.MAX_RUNS` runs or take more than
    :data:`MAX_PYMUNK_STEPS` pymunk steps in all (a spring of stiffness k steps at
    min(dt, 0.02 / w), w = sqrt(k / mu)); each fix offered lowers the larger part."""
    from .budget import check_runs, check_steps

    n, m = len(thetas), len(stiffnesses)
    fewer = ["fewer tilts ({thetas})"] if n > 1 else []
    check_runs(n * (1 + m), f"{n} tilts x (the rigid dumbbell + {m} springs)",
               fewer + (["fewer {stiffnesses}"] if m else []))
    s = scene.system
    mu = s.A.mass * s.B.mass / s.M
    # Pymunk steps per tilt: at dt (the rigid run, and springs soft enough), or at 0.02/w.
    at_dt, stiff = t_end / dt, {}
    for k in stiffnesses:
        step = 0.02 / math.sqrt(k / mu)
        if step < dt:
            stiff[k] = t_end / step
        else:
            at_dt += t_end / dt
    total = n * (at_dt + sum(stiff.values()))
    if total <= MAX_PYMUNK_STEPS:
        return
    drops = f"{n} drop{'s' if n > 1 else ''}"
    fixes = [f for f in fewer if total / n <= MAX_PYMUNK_STEPS]
    if sum(stiff.values()) > at_dt:
        k = max(stiff, key=stiff.get)
        what = (f"{drops} (the stiffest spring, {k:g} N/m, steps at 0.02/w = "
                f"{t_end / stiff[k]:.3g} s)")
        fixes.append("smaller {stiffnesses}")
    else:
        what = f"{drops} at dt = {dt:g} s"
        fixes.append("a larger {dt}")
    check_steps(total, what, fixes, budget=MAX_PYMUNK_STEPS)


def _check_elasticity(scene: Scene) -> None:
    """UsageError when the floor is so inelastic that an end leaves it slower than the exact
    solver's rest speed: the truth then stops at the first impact, before it can be
    measured."""
    from ..solvers.exact_rigid import REST_SPEED

    s = scene.system
    e = s.floor.elasticity
    v = math.sqrt(s.B.vy**2 + 2 * s.g * s.B.height)  # the drop's speed at the floor
    least = 10 * REST_SPEED / v
    if e < least:
        raise UsageError(
            f"elasticity = {e:g}: an end leaves this floor at about {e:g} x {v:.3g} m/s, "
            f"slower than the {REST_SPEED:g} m/s at which the exact solver (the truth) "
            "takes it to rest and stops, so the first impact cannot be measured",
            param="elasticity", fixes=(f"use an {{elasticity}} of at least {least:.2g}",))


def restitution(scene: Scene, thetas: np.ndarray | list[float],
                stiffnesses: tuple[float, ...] = STIFFNESSES, dt: float = 1e-5,
                progress=None) -> RestitutionResult:
    """Drop the scene's dumbbell at each tilt: rigid in the truth and in pymunk, and as spring
    dumbbells in pymunk; ``dumbbell restitution`` without the files.

    Parameters
    ----------
    scene : Scene
        A rigid 2D scene (its floor's restitution and masses are used).
    thetas : array_like
        Tilts (degrees from vertical).
    stiffnesses : tuple of float, default (200.0, 2000.0, 20000.0)
        Springs (N/m) to drop as well; () for none.
    dt : float, default 1e-5
        pymunk's step (s).
    progress : callable or None, default None
        Called once per run.

    Returns
    -------
    RestitutionResult
        e_eff of each tilt by the formula, the truth, pymunk and each spring.

    Raises
    ------
    UsageError
        An argument that is not allowed, a scene that is not a rigid 2D drop, or runs that
        would keep more samples than allowed.

    Examples
    --------
    The formula and the exact runs agree at three tilts (at 60°, e_eff = 1/7):

    >>> import dumbbell
    >>> from dumbbell.analysis.restitution import restitution
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> result = restitution(scene, [0.0, 30.0, 60.0], stiffnesses=(), dt=1e-4)
    >>> result.formula, result.truth
    (array([1.        , 0.6       , 0.14285714]), array([1.        , 0.6       , 0.14285714]))
    """
    from ..solvers import simulate

    scene = args.scene(scene)
    thetas = np.asarray(args.reals(thetas, "thetas", "degrees", positive=False))
    stiffnesses = tuple(args.reals(stiffnesses, "stiffnesses", "N/m", empty=True))
    dt = args.real(dt, "dt", "s")
    if progress is not None:
        args.function(progress, "progress", "a function called once per run, or None")
    _check_scene(scene)
    t_end = drop_duration(scene)
    _check_work(scene, thetas, stiffnesses, dt, t_end)
    _check_elasticity(scene)
    e = scene.system.floor.elasticity
    q = rigid_q(scene)
    truth, pm, shares, impacts = [], [], [], []
    springs: dict[float, dict[str, list[float]]] = {
        k: {"e_eff": [], "impacts": [], "K_rot_share": []} for k in stiffnesses}
    truth_name = truth_for(tilted(scene, float(thetas[0])))
    _check_samples(tilted(scene, float(thetas[0])), dt, t_end)
    for th in thetas:
        rigid = tilted(scene, float(th))
        tr = simulate(rigid, truth_name, t_end=t_end, every=1)
        truth.append(_bounce(tr, CLUSTER_GAP, cluster=False).e_first)
        b = bounce(simulate(rigid, "pymunk", dt=dt, t_end=t_end, every=1))
        pm.append(b.e_first)
        shares.append(b.share_first)
        impacts.append(b.impacts)
        if progress:
            progress()
        for k in stiffnesses:
            sp = tilted(scene, float(th), k)
            # Keep w*dt small: the impact is resolved over the spring's own fast time scale.
            step = min(dt, 0.02 / sp.system.omega)
            bs = bounce(simulate(sp, "pymunk", dt=step, t_end=t_end,
                                 every=max(1, round(1e-4 / step))))
            springs[k]["e_eff"].append(bs.e_cluster)
            springs[k]["impacts"].append(bs.impacts)
            springs[k]["K_rot_share"].append(bs.share_cluster)
            if progress:
                progress()
    return RestitutionResult(
        theta=thetas, e=e, q=q, formula=e_eff_rigid(thetas, e, q), truth=np.array(truth),
        truth_solver=truth_name, pymunk=np.array(pm), pymunk_dt=dt,
        springs={k: {n: np.array(v) for n, v in cols.items()} for k, cols in springs.items()},
        rigid_k_rot_share=np.array(shares), rigid_impacts=np.array(impacts, dtype=float))
