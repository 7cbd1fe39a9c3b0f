"""The toppling dumbbell: a rigid dumbbell stands on end on a frictionless floor and falls over.

The floor can only push up, so no horizontal force acts: the centre of mass falls straight
down. With B on the floor, a = mA L / M the distance from B to the centre of mass, I the moment
about the centre of mass and theta the axis' angle from vertical, the centre of mass sits at
height a cos(theta) and energy conservation gives the angular velocity in closed form:

    1/2 (M a^2 sin^2(theta) + I) theta'^2 = M g a (cos(theta0) - cos(theta))

At the landing (theta = 90 degrees, started near upright, point masses) the centre of mass
moves at sqrt(g a) and the top particle at L theta' (sqrt(2 g L) for equal masses). The time to
fall is one quadrature of d(theta)/theta'. :func:`closed_form` gives all of it for a scene;
:func:`measure` reads the same quantities off any trajectory, so that pymunk (resting contact
on the floor) can be held against the closed form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.energy import rigid_moment
from ..model.scene import Scene
from ..model.trajectory import Trajectory

__all__ = ["ToppleClosedForm", "ToppleMeasure", "closed_form", "measure"]

#: Most points :meth:`ToppleClosedForm.angle_curve` computes (one quadrature each).
MAX_CURVE_POINTS = 100_000


@dataclass(frozen=True)
class ToppleClosedForm:
    """The closed form of the topple for a rigid dumbbell with B resting on a frictionless
    floor: what :func:`closed_form` returns. Angles are in rad from vertical.

    Parameters
    ----------
    mA, mB : float
        The top and bottom particles' masses (kg).
    L : float
        The rod's length (m).
    I : float
        The moment of inertia about the centre of mass (kg m²).
    g : float
        Gravity (m/s²).
    theta0 : float
        The angle it is released at (rad).

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.analysis.topple import closed_form
    >>> from dumbbell.model.scene import scenes_dir
    >>> topple = closed_form(dumbbell.load_scene(scenes_dir() / "topple-2d.toml"))
    >>> topple
    <ToppleClosedForm mA=0.1 kg, mB=0.1 kg, L=0.2 m, I=0.002 kg m^2, g=9.8 m/s^2, released at 5 deg>
    >>> round(topple.fall_time(), 6), topple.check()          # s; B stays on the floor
    (0.406387, None)
    >>> [round(v, 4) for v in topple.landing_speeds()]         # centre of mass, top (m/s)
    [0.9881, 1.9761]
    >>> round(topple.landing_omega(), 4)                        # rad/s
    9.8806
    >>> topple.omega([0.5, 1.0]).round(4)                      # rad/s at 0.5 and 1 rad
    array([4.3478, 7.2328])
    >>> round(float(topple.alpha(1.0)), 4)                     # rad/s²
    34.3545
    >>> topple.normal_force([topple.theta0, 1.0]).round(4)     # N: M g at the release
    array([1.9452, 0.8165])
    >>> t, theta = topple.angle_curve(5)
    >>> t.round(4), theta.round(4)
    (array([0.    , 0.1377, 0.2425, 0.328 , 0.4064]), array([0.0873, 0.18  , 0.4581, 0.9218, 1.5708]))
    """

    mA: float
    mB: float
    L: float
    I: float
    g: float
    theta0: float

    def __repr__(self) -> str:
        from .._display import one_line

        return one_line(f"<ToppleClosedForm mA={self.mA:g} kg, mB={self.mB:g} kg, "
                        f"L={self.L:g} m, I={self.I:.4g} kg m^2, g={self.g:g} m/s^2, released "
                        f"at {math.degrees(self.theta0):g} deg>")

    def _repr_html_(self) -> str:
        """The one-line summary above the fall time and the landing speeds."""
        from .._display import html_table

        v_cm, v_top = self.landing_speeds()
        return html_table(repr(self), ["fall time (s)", "centre of mass at landing (m/s)",
                                       "top particle at landing (m/s)"],
                          [(self.fall_time(), v_cm, v_top)])

    @property
    def M(self) -> float:
        """Total mass (kg)."""
        return self.mA + self.mB

    @property
    def a(self) -> float:
        """Distance from B (on the floor) to the centre of mass (m)."""
        return self.mA * self.L / self.M

    def omega(self, theta: np.ndarray | float) -> np.ndarray:
        """Angular speed |theta'| at an angle, from energy conservation.

        Parameters
        ----------
        theta : float or array_like
            The angle from vertical (rad), from ``theta0`` to pi/2.

        Returns
        -------
        numpy.ndarray
            The angular speed (rad/s).

        Raises
        ------
        UsageError
            Angles that are not finite numbers.
        """
        return self._omega_past(args.array(theta, "theta", "rad") - self.theta0)

    def _omega_past(self, delta: np.ndarray | float) -> np.ndarray:
        # Angular speed ``delta`` rad past the release. cos(theta0) - cos(theta) is written as
        # a product of sines of delta so that it keeps its digits right after the release.
        d = np.maximum(np.asarray(delta, dtype=float), 0.0)
        th = self.theta0 + d
        M, a = self.M, self.a
        drop = 2.0 * np.sin(self.theta0 + 0.5 * d) * np.sin(0.5 * d)
        return np.sqrt(2.0 * M * self.g * a * drop / (M * a * a * np.sin(th) ** 2 + self.I))

    def alpha(self, theta: np.ndarray | float) -> np.ndarray:
        """Angular acceleration theta'' at an angle: half the derivative of omega² with
        respect to theta.

        Parameters
        ----------
        theta : float or array_like
            As for :meth:`omega`.

        Returns
        -------
        numpy.ndarray
            The angular acceleration (rad/s²).

        Raises
        ------
        UsageError
            As for :meth:`omega`.
        """
        th = args.array(theta, "theta", "rad")
        M, a, g = self.M, self.a, self.g
        s, c = np.sin(th), np.cos(th)
        den = M * a * a * s * s + self.I
        num = 2.0 * M * g * a * (math.cos(self.theta0) - c)
        return 0.5 * (2.0 * M * g * a * s * den - num * 2.0 * M * a * a * s * c) / den**2

    def normal_force(self, theta: np.ndarray | float) -> np.ndarray:
        """The floor's push on B at an angle: M (g + Y''). It must stay >= 0 for B to keep
        touching the floor; :meth:`check` says where it does not.

        Parameters
        ----------
        theta : float or array_like
            The angle from vertical (rad), as for :meth:`omega`.

        Returns
        -------
        numpy.ndarray
            The normal force (N), one per angle.

        Raises
        ------
        UsageError
            An angle that is not a finite number.
        """
        th = args.array(theta, "theta", "rad")
        w, al = self.omega(th), self.alpha(th)
        y_dd = -self.a * (np.cos(th) * w * w + np.sin(th) * al)
        return self.M * (self.g + y_dd)

    def landing_omega(self) -> float:
        """Angular speed at the landing, theta = 90 degrees.

        Returns
        -------
        float
            rad/s.
        """
        return float(self.omega(math.pi / 2))

    def landing_speeds(self) -> tuple[float, float]:
        """Speeds at the landing, both straight down.

        Returns
        -------
        tuple of float
            The centre of mass's and the top particle A's (m/s).
        """
        w = self.landing_omega()
        return self.a * w, self.L * w

    def fall_time(self) -> float:
        """Time from release to the landing, by quadrature of d(theta)/theta'.

        theta' vanishes at the release like sqrt(theta - theta0); writing
        theta = theta0 + (pi/2 - theta0) u^2 turns that into a smooth integrand.

        Returns
        -------
        float
            The fall time (s).
        """
        from scipy.integrate import quad

        return quad(self._dt_du, 0.0, 1.0, epsabs=1e-13, epsrel=1e-12, limit=200)[0]

    def _dt_du(self, u: float) -> float:
        span = math.pi / 2 - self.theta0
        if u == 0.0:
            # Limit u -> 0: theta' ~ sqrt(2 M g a sin(theta0) span u^2 / (M a^2 s0^2 + I)).
            s0 = math.sin(self.theta0)
            k = 2.0 * self.M * self.g * self.a * s0 * span / (self.M * self.a**2 * s0**2 + self.I)
            return 2.0 * span / math.sqrt(k)
        return 2.0 * span * u / float(self._omega_past(span * u * u))

    def angle_curve(self, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
        """The angle against time from the release to the landing, each time by its own
        quadrature from the release.

        Parameters
        ----------
        n : int, default 400
            Points, at least 2.

        Returns
        -------
        t : numpy.ndarray
            Times (s).
        theta : numpy.ndarray
            Angles (rad).

        Raises
        ------
        UsageError
            ``n`` not a whole number from 2 to the most allowed.
        """
        n = args.whole(n, "n", "points", lo=2, hi=MAX_CURVE_POINTS)
        from scipy.integrate import quad

        u = np.linspace(0.0, 1.0, n)
        t = np.zeros(n)
        for i in range(1, n):
            t[i] = t[i - 1] + quad(self._dt_du, u[i - 1], u[i], epsabs=1e-14, epsrel=1e-12)[0]
        return t, self.theta0 + (math.pi / 2 - self.theta0) * u * u

    def check(self) -> str | None:
        """Whether the closed form holds: B stays on the floor all the way down.

        Returns
        -------
        str or None
            None when it holds; else why not (the floor would have to pull).
        """
        th = np.linspace(self.theta0, math.pi / 2, 2001)
        n = self.normal_force(th)
        if float(n.min()) < 0:
            where = math.degrees(float(th[int(np.argmax(n < 0))]))
            return (f"B leaves the floor at {where:.1f} degrees (the normal force would turn "
                    "negative): the closed form assumes B stays on the floor")
        return None


def closed_form(scene: Scene) -> ToppleClosedForm:
    """The closed form for a topple scene: a rigid dumbbell, B at rest on a frictionless floor
    at height 0, A above it, tilted by a small nonzero angle.

    Parameters
    ----------
    scene : Scene
        The topple scene.

    Returns
    -------
    ToppleClosedForm
        Its masses, length, moment of inertia, gravity and release angle.

    Raises
    ------
    UsageError
        A scene that does not fit (one line naming what does not).

    Examples
    --------
    The shipped topple scene's fall time (s), and a scene that does not fit:

    >>> import dumbbell
    >>> from dumbbell.analysis.topple import closed_form
    >>> from dumbbell.model.scene import scenes_dir
    >>> round(closed_form(dumbbell.load_scene(scenes_dir() / "topple-2d.toml")).fall_time(), 6)
    0.406387
    >>> closed_form(dumbbell.load_scene(scenes_dir() / "textbook-1d.toml"))
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: ...textbook-1d.toml: the topple needs a rigid 2D dumbbell ([rigid], dimensions = 2)
    """
    scene = args.scene(scene)
    where = scene.source
    if scene.system.dimensions != 2 or scene.system.rigid is None:
        raise UsageError(f"{where}: the topple needs a rigid 2D dumbbell ([rigid], dimensions = 2)")
    if scene.system.floor is None or scene.system.floor.friction != 0:
        raise UsageError(f"{where}: the topple needs a frictionless [floor] (friction = 0)")
    if scene.system.g <= 0:
        raise UsageError(f"{where}: the topple needs gravity ([gravity] g > 0)")
    B, A = scene.system.B, scene.system.A
    if B.height != 0 or B.vx != 0 or B.vy != 0 or A.vx != 0 or A.vy != 0:
        raise UsageError(f"{where}: the topple starts with B at rest on the floor (bodies.B."
                         "height = 0) and no velocities")
    L = scene.system.rigid.length
    theta0 = math.atan2(A.x - B.x, A.height - B.height)
    if not (0 < abs(theta0) < math.pi / 2):
        raise UsageError(f"{where}: tilt = {math.degrees(theta0):g}: the topple needs A above "
                         "B, tilted by an angle strictly between 0 and 90 degrees")
    cf = ToppleClosedForm(A.mass, B.mass, L, rigid_moment(scene), scene.system.g, abs(theta0))
    reason = cf.check()
    if reason:
        raise UsageError(f"{where}: {reason}")
    return cf


@dataclass(frozen=True)
class ToppleMeasure:
    """The topple as read off a trajectory: what :func:`measure` returns.

    Parameters
    ----------
    fall_time : float
        When A's centre reaches the floor (s).
    v_top, v_cm : float
        The top particle's and the centre of mass's speeds at the landing (m/s).
    cm_drift : float
        The largest horizontal drift of the centre of mass (m).
    t : numpy.ndarray
        Times up to the landing (s).
    theta, cm_x, v_top_curve : numpy.ndarray
        At those times: the angle from vertical (rad), the centre of mass's horizontal
        displacement (m) and the top particle's speed (m/s).

    Examples
    --------
    pymunk's run of the shipped topple, sampled every step:

    >>> import dumbbell
    >>> from dumbbell.analysis.topple import measure
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "topple-2d.toml")
    >>> topple = measure(dumbbell.simulate(scene, dt=1e-4, every=1, t_end=0.45))  # pymunk
    >>> round(topple.fall_time, 6), round(topple.v_top, 4), len(topple.t)   # s, m/s
    (0.406437, 1.9763, 4065)
    """

    fall_time: float
    v_top: float
    v_cm: float
    cm_drift: float
    t: np.ndarray
    theta: np.ndarray
    cm_x: np.ndarray
    v_top_curve: np.ndarray

    def __repr__(self) -> str:
        from .._display import one_line

        return one_line(f"<ToppleMeasure lands at {self.fall_time:.6g} s: top particle "
                        f"{self.v_top:.6g} m/s, centre of mass {self.v_cm:.6g} m/s, "
                        f"horizontal drift {self.cm_drift:.2g} m; {counted(len(self.t), 'sample')}>")

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(repr(self), ["fall time (s)", "top particle (m/s)",
                                       "centre of mass (m/s)", "horizontal drift (m)"],
                          [(self.fall_time, self.v_top, self.v_cm, self.cm_drift)])


def measure(traj: Trajectory) -> ToppleMeasure:
    """Measure the topple in a run: the landing is where A's height first reaches 0, found by
    linear interpolation between samples; the speeds are taken at the last sample before it.

    Parameters
    ----------
    traj : Trajectory
        A 2D run of the topple scene (B on the floor), sampled finely (1 ms or less).

    Returns
    -------
    ToppleMeasure
        The fall time, the landing speeds and the curves up to the landing.

    Raises
    ------
    UsageError
        A 1D run, or one in which A never reaches the floor.

    Examples
    --------
    pymunk's fall, against the closed form's:

    >>> import dumbbell
    >>> from dumbbell.analysis.topple import closed_form, measure
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "topple-2d.toml")
    >>> pymunk = measure(dumbbell.simulate(scene, dt=1e-4, every=1, t_end=0.45)).fall_time
    >>> f"{pymunk - closed_form(scene).fall_time():.1e} s"   # late by about half a step
    '5.0e-05 s'
    """
    traj = args.trajectory(traj)
    if traj.scene.system.dimensions != 2:
        raise UsageError(f"traj: {traj.scene.source} is 1D; the topple is measured in 2D",
                         param="traj")
    s = traj.scene
    yA = traj["yA"]
    hit = np.flatnonzero(yA <= 0.0)
    if hit.size == 0 or hit[0] == 0:
        raise UsageError(f"{s.source}: A never reaches the floor in this run "
                         f"(t_end = {float(traj.t[-1]):g} s); run longer")
    i = int(hit[0])
    t0, t1, y0, y1 = traj.t[i - 1], traj.t[i], yA[i - 1], yA[i]
    t_land = float(t0 + (t1 - t0) * y0 / (y0 - y1))
    M = s.system.M
    xcm = (s.system.A.mass * traj["xA"] + s.system.B.mass * traj["xB"]) / M
    vcm = (s.system.A.mass * traj["vyA"] + s.system.B.mass * traj["vyB"]) / M
    speed = np.hypot(traj["vxA"][:i], traj["vyA"][:i])
    theta = np.arctan2(np.abs(traj["xA"][:i] - traj["xB"][:i]), traj["yA"][:i] - traj["yB"][:i])
    drift = xcm[:i] - xcm[0]
    return ToppleMeasure(t_land, float(speed[-1]), float(abs(vcm[i - 1])),
                         float(np.max(np.abs(drift))), traj.t[:i].copy(), theta, drift, speed)
