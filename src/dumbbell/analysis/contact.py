"""Angular momentum about the contact point through one impact.

A frictionless floor's impulse is vertical and acts at the contact point P, so it exerts no
torque about P: the angular momentum about P is the same just before and just after the impact,
although its two parts both jump, the spin about the centre of mass (L_cm) one way and the
centre of mass's orbit about P, M (R - P) x V, the other. Between impacts gravity turns L_P at
the steady rate -M g (X - P_x); both sides are carried to the impact's time with it before they
are compared.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.energy import angular_momentum
from ..model.trajectory import Impact, Trajectory

__all__ = ["ContactMomentum", "about_contact"]


@dataclass(frozen=True)
class ContactMomentum:
    """Angular momentum about the contact point P of one impact, before, through and after it:
    what :func:`about_contact` returns. ``change`` is L_P after minus before.

    Parameters
    ----------
    impact : Impact
        The impact.
    px : float
        P's x (m); P = (px, 0) on the floor.
    t : numpy.ndarray
        Sample times around the impact (s).
    L_cm, L_orbit, L_P : numpy.ndarray
        At those samples (kg m²/s): the spin about the centre of mass, the orbital part
        M (R - P) x V, and their sum.
    before, after : float
        L_P just before and just after, carried to the impact's time (kg m²/s).
    L_cm_before, L_cm_after : float
        L_cm just before and just after (kg m²/s).

    Examples
    --------
    What :func:`about_contact` finds at the rigid dumbbell's first impact, in one line:

    >>> import dumbbell
    >>> from dumbbell.analysis.contact import about_contact
    >>> from dumbbell.model.scene import scenes_dir
    >>> about_contact(dumbbell.simulate(dumbbell.load_scene(scenes_dir() / "rigid-2d.toml"),
    ...                                 solver="exact", t_end=0.6, dt=1e-4))
    <ContactMomentum B's impact at t = 0.451754 s, P = (..., 0) m: L_P -0.04427189 -> -0.04427189 (change ...), L_cm ... -> -0.07083502 kg m^2/s>
    """

    impact: Impact
    px: float
    t: np.ndarray
    L_cm: np.ndarray
    L_orbit: np.ndarray
    L_P: np.ndarray
    before: float
    after: float
    L_cm_before: float
    L_cm_after: float

    @property
    def change(self) -> float:
        """L_P after minus before (kg m^2/s): zero for a frictionless impact."""
        return self.after - self.before

    def __repr__(self) -> str:
        from .._display import one_line

        return one_line(f"<ContactMomentum {self.impact.body}'s impact at t = "
                        f"{self.impact.t:.6g} s, P = ({self.px:.4g}, 0) m: L_P "
                        f"{self.before:.7g} -> {self.after:.7g} (change {self.change:.2g}), "
                        f"L_cm {self.L_cm_before:.7g} -> {self.L_cm_after:.7g} kg m^2/s>")

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(repr(self), ["", "before (kg m^2/s)", "after (kg m^2/s)",
                                       "change (kg m^2/s)"],
                          [("L_P", self.before, self.after, self.change),
                           ("L_cm", self.L_cm_before, self.L_cm_after,
                            self.L_cm_after - self.L_cm_before)])


def about_contact(traj: Trajectory, index: int = 0, window: float = 0.02) -> ContactMomentum:
    """Angular momentum about the contact point of one impact of a 2D run. A frictionless
    floor exerts no torque about P, so L_P is the same just before and just after, although
    its two parts both jump.

    Parameters
    ----------
    traj : Trajectory
        A 2D run, sampled finely (every step or two) for a sharp before and after.
    index : int, default 0
        Which impact (0: the first).
    window : float, default 0.02
        Seconds either side of the impact to keep.

    Returns
    -------
    ContactMomentum
        L_P, L_cm and the orbital part around the impact, and before and after it.

    Raises
    ------
    UsageError
        A 1D run, an impact it does not have, or a window that is not a positive number.

    Examples
    --------
    The rigid dumbbell's first impact: L_P is kept while the spin jumps.

    >>> import dumbbell
    >>> from dumbbell.analysis.contact import about_contact
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=0.6, dt=1e-4)
    >>> about = about_contact(traj)
    >>> round(about.before, 6), round(about.after, 6), abs(about.change) < 1e-12   # kg m²/s
    (-0.044272, -0.044272, True)
    >>> round(about.L_cm_before, 6), round(about.L_cm_after, 6)   # the spin jumps
    (0.0, -0.070835)
    """
    traj = args.trajectory(traj)
    index = args.whole(index, "index", "impacts", lo=0)
    window = args.real(window, "window", "s")
    s = traj.scene
    if s.system.dimensions != 2:
        raise UsageError(f"{s.source}: angular momentum about a contact point needs a 2D scene")
    if not 0 <= index < len(traj.events):
        raise UsageError(f"index = {index}: the run has {counted(len(traj.events), 'impact')}",
                         param="index")
    imp = traj.events[index]
    t = traj.t
    i = int(np.searchsorted(t, imp.t, side="left"))
    # Where the particle touched: its x at the last sample before the impact, moved on to the
    # impact's time (x does not jump at a frictionless impact).
    px = float(traj[f"x{imp.body}"][i - 1] + traj[f"vx{imp.body}"][i - 1] * (imp.t - t[i - 1]))
    M = s.system.M
    X = (s.system.A.mass * traj["xA"] + s.system.B.mass * traj["xB"]) / M
    Y = (s.system.A.mass * traj["yA"] + s.system.B.mass * traj["yB"]) / M
    VX = (s.system.A.mass * traj["vxA"] + s.system.B.mass * traj["vxB"]) / M
    VY = (s.system.A.mass * traj["vyA"] + s.system.B.mass * traj["vyB"]) / M
    L_cm = traj["L_cm"]
    L_orbit = angular_momentum(M, X, Y, VX, VY, px, 0.0)
    L_P = L_cm + L_orbit
    torque = -M * s.system.g * (X - px)  # gravity's torque about P, N m

    def at_impact(j: int) -> tuple[float, float]:
        return float(L_P[j] + torque[j] * (imp.t - t[j])), float(L_cm[j])

    # The first sample after the impact that a stepping engine has finished resolving.
    j_after = int(np.searchsorted(t, imp.t, side="right"))
    j_after = min(j_after + (1 if traj.dt else 0), len(t) - 1)
    before, cm_before = at_impact(i - 1)
    after, cm_after = at_impact(j_after)
    m = (t >= imp.t - window) & (t <= imp.t + window)
    return ContactMomentum(imp, px, t[m].copy(), L_cm[m].copy(), L_orbit[m], L_P[m], before,
                           after, cm_before, cm_after)
