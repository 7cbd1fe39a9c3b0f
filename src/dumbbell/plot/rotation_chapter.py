"""Figures of the rotation chapter's preview: apparent restitution against tilt, and the topple
against its closed form. Each draws on the axes it is given (or a new figure) and returns them;
none saves or switches matplotlib's backend. Legends sit outside the axes, on the right, on a
figure of their own; inside the user's axes, above the data."""

from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING, Any

import numpy as np

from .style import _subplots, finish, legend, plain, wrap_texts

if TYPE_CHECKING:
    from ..analysis.contact import ContactMomentum
    from ..analysis.restitution import RestitutionResult
    from ..analysis.topple import ToppleClosedForm, ToppleMeasure

__all__ = ["contact_momentum", "restitution", "topple"]

#: Colours of the spring dumbbells, softest to stiffest.
SPRING_COLOURS = ("#9ecae1", "#4292c6", "#08519c")


def _axes(ax: Any, nrows: int = 1, **fig_kw: Any) -> Any:
    if ax is not None:
        return ax
    _, axes = _subplots(nrows, 1, **fig_kw)
    return axes


def _end(axes: list[Any], own: bool) -> None:
    """Lay out what was drawn: the package's own figure finished, the user's axes' titles
    wrapped to their widths."""
    if own:
        finish(axes[0].figure)
    else:
        for a in axes:
            wrap_texts(a)


def restitution(result: RestitutionResult, ax: Any = None) -> Any:
    """e_eff against tilt (degrees), then the impacts in the first cluster and the share of
    kinetic energy that went into rotation.

    Parameters
    ----------
    result : RestitutionResult
        What :func:`~dumbbell.analysis.restitution.restitution` measured.
    ax : sequence of three matplotlib.axes.Axes or None, default None
        Draw on these (top to bottom: e_eff, the impacts, the rotation share); None: a new
        figure.

    Returns
    -------
    list of matplotlib.axes.Axes
        The three axes, top to bottom.

    Raises
    ------
    UsageError
        A ``result`` that is not a RestitutionResult, or an ``ax`` that is not three Axes.

    Examples
    --------
    The rigid dumbbell only (no spring runs), at three tilts:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> from dumbbell.analysis.restitution import restitution
    >>> result = restitution(dumbbell.load_scene(scenes_dir() / "rigid-2d.toml"),
    ...                      [0.0, 30.0, 60.0], stiffnesses=(), dt=1e-4)
    >>> len(dumbbell.plot.restitution(result))
    3
    """
    from ..analysis.restitution import RestitutionResult, e_eff_rigid, k_rot_share_rigid
    from ..model import args
    args.instance(result, "result", RestitutionResult,
                  "a RestitutionResult (from dumbbell.analysis.restitution.restitution)")
    ax = args.axes(ax, count=3)
    own = ax is None
    top, mid, bottom = _axes(ax, 3, figsize=(11.0, 9.0), sharex=True,
                             gridspec_kw={"height_ratios": [2.4, 1, 1.2]})
    th = np.linspace(float(result.theta.min()), float(result.theta.max()), 400)
    top.axhline(0, color="0.5", lw=0.8)
    top.plot(th, e_eff_rigid(th, result.e, result.q), color="black", lw=1.6,
             label=f"rigid, formula\n(e - q sin²θ)/(1 + q sin²θ), q = {result.q:.3g}")
    top.plot(result.theta, result.truth, "o", ms=9, mfc="none", mec="#d62728", mew=1.6,
             label=f"rigid, truth ({result.truth_solver}),\nfirst impact")
    top.plot(result.theta, result.pymunk, "x", ms=8, color="#2ca02c", mew=1.8,
             label=f"rigid, pymunk dt = {result.pymunk_dt:g} s,\nfirst impact")
    for (k, cols), colour in zip(result.springs.items(), SPRING_COLOURS, strict=False):
        top.plot(result.theta, cols["e_eff"], "s--", ms=5, color=colour, lw=1.1,
                 label=f"spring k = {k:g} N/m (pymunk),\nleaving after the first cluster")
    cross = result.sign_change
    if math.isfinite(cross) and th[0] <= cross <= th[-1]:
        top.axvline(cross, color="0.4", ls=":", lw=1.2)
        note = (f"the rigid dumbbell's e_eff changes sign at θ = {cross:.1f}° (sin²θ = e/q, "
                "dotted): past it the centre of mass keeps moving down after the bounce")
    elif math.isfinite(cross):
        note = (f"the rigid dumbbell's e_eff changes sign at θ = {cross:.1f}° (sin²θ = e/q), "
                "outside the tilts run here")
    else:
        note = "the rigid dumbbell's e_eff stays positive at every tilt (e > q)"
    top.set_ylabel("e_eff = -V_after / V_before [1]")
    top.set_title(f"Apparent restitution of a dumbbell dropped at tilt θ on a floor with "
                  f"e = {result.e:g}\n" + "\n".join(textwrap.wrap(note, 100)), fontsize=10)
    legend(top, own, fontsize=7.5)

    series = [("rigid (pymunk)", result.rigid_impacts, "#2ca02c")]
    series += [(f"k = {k:g} N/m", cols["impacts"], c) for (k, cols), c in
               zip(result.springs.items(), SPRING_COLOURS, strict=False)]
    span = float(np.min(np.diff(result.theta))) if len(result.theta) > 1 else 10.0
    bar = 0.8 * span / len(series)
    for j, (label, impacts, colour) in enumerate(series):
        x = result.theta + (j - (len(series) - 1) / 2) * bar
        mid.bar(x, impacts, width=bar, color=colour, label=label)
    mid.set_ylabel("impacts in the\nfirst cluster [1]")
    mid.set_ylim(0, 1.15 * max(float(np.max(s[1])) for s in series))
    mid.yaxis.get_major_locator().set_params(integer=True)    # counts
    legend(mid, own, fontsize=7.5)

    bottom.plot(th, k_rot_share_rigid(th, result.e, result.q), color="black", lw=1.6,
                label="rigid, formula (1+e)² q sin²θ / (1 + q sin²θ)²,\nafter the first impact")
    bottom.plot(result.theta, result.rigid_k_rot_share, "x", ms=8, color="#2ca02c", mew=1.8,
                label="rigid, pymunk,\nafter the first impact")
    for (k, cols), colour in zip(result.springs.items(), SPRING_COLOURS, strict=False):
        bottom.plot(result.theta, cols["K_rot_share"], "s--", ms=5, color=colour, lw=1.1,
                    label=f"k = {k:g} N/m, after the first cluster")
    bottom.set_ylabel("K_rot / K before [1]")
    bottom.set_ylim(0, 1.05)
    bottom.set_xlabel("tilt θ of the axis from vertical [degrees]")
    for a in (top, mid, bottom):
        a.grid(True, color="0.9")
    legend(bottom, own, fontsize=7.5)
    _end([top, mid, bottom], own)
    return top, mid, bottom


def topple(cf: ToppleClosedForm, measured: ToppleMeasure, ax: Any = None,
           solver: str = "pymunk") -> Any:
    """The topple against its closed form: angle, the centre of mass's horizontal position and
    the top particle's speed, all against time (s).

    Parameters
    ----------
    cf : ToppleClosedForm
        The closed form (:func:`~dumbbell.analysis.topple.closed_form`).
    measured : ToppleMeasure
        The run's topple (:func:`~dumbbell.analysis.topple.measure`).
    ax : sequence of three matplotlib.axes.Axes or None, default None
        Draw on these; None: a new figure.
    solver : str, default "pymunk"
        The run's solver, for the legend.

    Returns
    -------
    list of matplotlib.axes.Axes
        The three axes.

    Raises
    ------
    UsageError
        Arguments of the wrong kind, or an ``ax`` that is not three Axes.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> from dumbbell.analysis.topple import closed_form, measure
    >>> scene = dumbbell.load_scene(scenes_dir() / "topple-2d.toml")
    >>> run = dumbbell.simulate(scene, dt=1e-4, every=1, t_end=0.45)
    >>> axes = dumbbell.plot.topple(closed_form(scene), measure(run))
    >>> axes[0].get_ylabel()
    'tilt θ [degrees]'
    """
    from ..analysis.topple import ToppleClosedForm, ToppleMeasure
    from ..model import args

    args.instance(cf, "cf", ToppleClosedForm,
                  "a ToppleClosedForm (from dumbbell.analysis.topple.closed_form)")
    args.instance(measured, "measured", ToppleMeasure,
                  "a ToppleMeasure (from dumbbell.analysis.topple.measure)")
    ax = args.axes(ax, count=3)
    solver = plain(args.text(solver, "solver", "a str (the name in the legend)"))
    own = ax is None
    a1, a2, a3 = _axes(ax, 3, figsize=(10.5, 8.0), sharex=True)
    t, theta = cf.angle_curve()
    step = max(1, len(measured.t) // 60)
    a1.plot(t, np.degrees(theta), color="black", lw=1.6, label="closed form (quadrature)")
    a1.plot(measured.t[::step], np.degrees(measured.theta[::step]), "o", ms=4, mfc="none",
            color="#2ca02c", label=solver)
    a1.axhline(90, color="0.6", lw=0.8, ls=":", label="θ = 90°: lying on the floor")
    a1.set_ylabel("tilt θ [degrees]")
    a1.set_ylim(0, 100)
    T, late = cf.fall_time(), measured.fall_time - cf.fall_time()
    # To the microsecond: the two landings differ by a few µs at dt = 1e-5 s.
    a1.annotate(f"landing (θ = 90°):\nclosed form {T:.6f} s\n{solver} {measured.fall_time:.6f} s"
                f"\n({solver} {abs(late) * 1e6:.0f} µs {'late' if late >= 0 else 'early'})",
                (T, 90), xytext=(0.03, 0.83), textcoords="axes fraction", va="top",
                fontsize=8.5, arrowprops={"arrowstyle": "->", "color": "0.4",
                                          "shrinkA": 4, "shrinkB": 2})
    legend(a1, own)

    a2.axhline(0, color="black", lw=1.6,
               label="closed form: no\nhorizontal force,\nx_cm stays put")
    a2.plot(measured.t, measured.cm_x, color="#2ca02c", lw=1, label=solver)
    a2.set_ylabel("x_cm - x_cm(0) [m]")
    lim = max(1e-6, 2 * float(np.max(np.abs(measured.cm_x))))
    a2.set_ylim(-lim, lim)
    a2.text(0.01, 0.08, f"largest drift: {measured.cm_drift:.2g} m", transform=a2.transAxes,
            fontsize=8.5)
    legend(a2, own)

    w = cf.omega(theta)
    vA = w * np.sqrt((cf.L - cf.a) ** 2 * np.cos(theta) ** 2 + cf.L**2 * np.sin(theta) ** 2)
    a3.plot(t, vA, color="black", lw=1.6, label="closed form")
    a3.plot(measured.t[::step], measured.v_top_curve[::step], "o", ms=4, mfc="none",
            color="#2ca02c", label=solver)
    v_cf = cf.landing_speeds()[1]
    a3.axhline(math.sqrt(2 * cf.g * cf.L), color="0.5", ls=":", lw=1,
               label=f"√(2gL) = {math.sqrt(2 * cf.g * cf.L):.4f} m/s\n(started upright)")
    a3.set_ylabel("speed of the top particle [m/s]")
    a3.set_xlabel("t [s]")
    a3.text(0.01, 0.55, f"at the landing: closed form {v_cf:.5f} m/s,\n{solver} "
            f"{measured.v_top:.5f} m/s", transform=a3.transAxes, fontsize=8.5)
    legend(a3, own)
    for a in (a1, a2, a3):
        a.grid(True, color="0.9")
    a1.set_title(f"Toppling rigid dumbbell: L = {cf.L:g} m, released at "
                 f"{math.degrees(cf.theta0):g}° on a frictionless floor", fontsize=10.5)
    _end([a1, a2, a3], own)
    return a1, a2, a3


def contact_momentum(cm: ContactMomentum, ax: Any = None, solver: str = "") -> Any:
    """Angular momentum about the contact point through one impact: L_cm and the orbital part
    jump, their sum L_P does not. Time in ms from the impact.

    Parameters
    ----------
    cm : ContactMomentum
        What :func:`~dumbbell.analysis.contact.about_contact` measured.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes (the numbers in a smaller title); None: a new figure.
    solver : str, default ""
        The run's solver, for the title.

    Returns
    -------
    matplotlib.axes.Axes
        The one axes drawn on.

    Raises
    ------
    UsageError
        A ``cm`` not from :func:`~dumbbell.analysis.contact.about_contact`, an ``ax`` that
        is not one Axes, or a ``solver`` that is not a str.

    Examples
    --------
    The rigid dumbbell's first impact, solved exactly:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> from dumbbell.analysis.contact import about_contact
    >>> run = dumbbell.simulate(dumbbell.load_scene(scenes_dir() / "rigid-2d.toml"),
    ...                         solver="exact", t_end=0.6, dt=1e-4)
    >>> ax = dumbbell.plot.contact_momentum(about_contact(run), solver="exact")
    >>> ax.get_ylabel()
    'angular momentum [kg m²/s]'
    """
    from ..analysis.contact import ContactMomentum
    from ..model import args

    args.instance(cm, "cm", ContactMomentum,
                  "a ContactMomentum (from dumbbell.analysis.contact.about_contact)")
    ax = args.axes(ax)
    solver = plain(args.text(solver, "solver", "a str (the name in the title)"))
    own = ax is None
    ax = _axes(ax, 1, figsize=(10.5, 4.8))
    t = (cm.t - cm.impact.t) * 1e3
    ax.axvline(0, color="0.6", lw=0.8, ls=":")
    ax.plot(t, cm.L_cm, color="#2ca02c", lw=1.4, label="L_cm, spin about the\ncentre of mass")
    ax.plot(t, cm.L_orbit, color="#1f77b4", lw=1.4, ls="--",
            label="M (R - P) x V, the centre\nof mass's orbit about P")
    ax.plot(t, cm.L_P, color="black", lw=2.0, label="L_P, their sum: about\nthe contact point")
    impact = f"impact of {cm.impact.body} at {cm.impact.t:.6f} s, P = ({cm.px:.4f} m, 0)"
    ax.set_ylabel("angular momentum [kg m²/s]")
    ax.grid(True, color="0.9")
    legend(ax, own)
    who = f" ({solver})" if solver else ""
    numbers = (f"L_cm jumps {cm.L_cm_before:+.5f} → {cm.L_cm_after:+.5f}, L_P stays "
               f"{cm.before:+.6f} → {cm.after:+.6f} kg m²/s")
    if own:
        ax.set_xlabel(f"t - t_impact [ms]   ({impact})")
        ax.set_title(f"Through a frictionless impact{who}: {numbers}\n(the floor's push acts "
                     "at P: no torque about it; gravity turns L_P slowly and evenly)",
                     fontsize=9)
    else:   # the user's axes: the numbers only, in a smaller title
        ax.set_xlabel("t - t_impact [ms]")
        ax.set_title(f"{impact[0].upper()}{impact[1:]}{who}: {numbers}", fontsize=8)
    _end([ax], own)
    return ax
