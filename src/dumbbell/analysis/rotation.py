"""Rotation preview: the tilted spring dumbbell for growing k beside the rigid dumbbell.

:func:`variants` builds, from one 2D scene, the spring dumbbell at each stiffness and the rigid
dumbbell of the same masses, tilt and length; :func:`series` runs them;
:func:`dumbbell.plot.rotation` draws K_rot(t) of each.

What the figure shows (measured, tilted-2d): between impacts the spring dumbbell turns more and
more like a rigid body as k grows (the ripple of K_rot, caused by the axis stretching, shrinks
like 1/k). But at an impact the floor pushes ONE particle, faster than any spring can pass the
push on to the other, so a stiff spring dumbbell does not take the rigid body's share of
rotation. When B (speed v, axis tilted by a from vertical) is reversed alone, the relative
velocity becomes 2v straight down, and K_rot = 1/2 mu (2 v sin a)^2 = 0.49 J for every k,
against 1.25 J for the rigid dumbbell (whose impulse turns the whole body); the rest stays as
vibration. On a hard floor the rigid body is not the limit of stiff springs.

About 0.07 s later A lands too (for stiff springs after a few quick bounces). What that impact
leaves in rotation depends on the phase of the vibration when A lands, so it varies with k
without a trend: mean K_rot from then until the next impact is 0.35, 0.11, 0.27 J for
k = 200, 2e3, 2e4 N/m (0.01 J at 5e4; pymunk, dt = 1e-5 s), always far below the rigid
dumbbell's 1.25 J. The figure quotes these means (:func:`mean_after_first_cluster`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.scene import Scene, scene_from_dict
from ..model.trajectory import Trajectory

__all__ = ["Series", "series"]

#: Spring constants of the preview (N/m).
STIFFNESSES = (200.0, 2e3, 2e4)
#: Sample spacing (s): fine enough for K_rot's ripple at k = 2e4 (period about 5 ms).
SAMPLE = 2e-4
#: Impacts closer than this (s) belong to one cluster (B's impact, then A's and any chatter).
CLUSTER_GAP = 0.1


def _length(scene: Scene) -> float:
    if scene.system.rigid is not None:
        return scene.system.rigid.length
    if scene.system.spring is not None:
        return scene.system.spring.rest_length
    A, B = scene.system.A, scene.system.B
    return math.hypot(A.x - B.x, A.height - B.height)


def variant(scene: Scene, stiffness: float | None, tilt: float | None = None) -> Scene:
    """``scene``'s dumbbell with a spring of ``stiffness`` (N/m), or rigid when it is None, at
    the same rest (or rod) length; tilted ``tilt`` degrees from vertical when given.
    Everything else is kept."""
    scene = args.scene(scene)
    stiffness = None if stiffness is None else args.real(stiffness, "stiffness", "N/m")
    tilt = None if tilt is None else args.real(tilt, "tilt", "degrees", positive=False)
    length = _length(scene)
    doc = scene.to_dict()
    doc.pop("spring", None)
    doc.pop("rigid", None)
    if stiffness is None:
        doc["rigid"] = {"length": length}
    else:
        doc["spring"] = {"stiffness": float(stiffness), "rest_length": length}
    if tilt is not None:
        doc["tilt"] = float(tilt)
        for key in ("x", "height"):  # the tilt places A now
            doc["bodies"]["A"].pop(key, None)
    return scene_from_dict(doc, scene.source)


def variants(scene: Scene, stiffnesses: tuple[float, ...] = STIFFNESSES) -> dict[str, Scene]:
    """Spring dumbbells at ``stiffnesses`` (N/m) and the rigid one, built from ``scene``:
    label -> scene. The rest length (or rod length) and everything else are kept."""
    scene = args.scene(scene)
    stiffnesses = args.reals(stiffnesses, "stiffnesses", "N/m", empty=True)
    if scene.system.dimensions != 2:
        raise UsageError(f"{scene.source}: the rotation preview needs a 2D scene "
                         "(dimensions = 2)")
    out = {f"k = {k:g} N/m": variant(scene, k) for k in stiffnesses}
    out["rigid"] = variant(scene, None)
    return out


@dataclass(frozen=True)
class Series:
    """The runs of the rotation chapter's preview: what :func:`series` returns.

    Parameters
    ----------
    runs : dict of str to Trajectory
        Label (``"k = 200 N/m"``, ``"rigid"``) -> its run.
    solver : str
        The solver asked for.
    dt : float
        The step used (s).
    scene : Scene
        The scene they were built from.

    Examples
    --------
    Each run is a Trajectory, by label; in 2D each carries L_cm:

    >>> import dumbbell
    >>> from dumbbell.analysis.rotation import series
    >>> from dumbbell.model.scene import scenes_dir
    >>> runs = series(dumbbell.load_scene(scenes_dir() / "tilted-2d.toml"), dt=1e-4, t_end=0.3,
    ...               stiffnesses=(200.0,)).runs
    >>> list(runs), runs["rigid"].columns[-3:]
    (['k = 200 N/m', 'rigid'], ['U_g', 'E', 'L_cm'])
    """

    runs: dict[str, Trajectory]
    solver: str
    dt: float
    scene: Scene

    def __repr__(self) -> str:
        from .._display import one_line

        return one_line(f"<Series {self.scene.name}: {counted(len(self.runs), 'run')} "
                        f"({', '.join(self.runs)}), {self.solver} at dt = {self.dt:g} s>")

    def _repr_html_(self) -> str:
        """The one-line summary above each run's summary line."""
        from .._display import html_table

        return html_table(repr(self), ["run", "trajectory"],
                          [(label, repr(traj)) for label, traj in self.runs.items()])


def series(scene: Scene, solver: str = "pymunk", dt: float = 1e-5, t_end: float = 2.0,
           stiffnesses: tuple[float, ...] = STIFFNESSES) -> Series:
    """Run every variant of a 2D scene, one per spring stiffness and a rigid one, as the
    rotation chapter's preview compares them. The step is cut where needed to keep
    w*dt <= 0.05 for the stiffest spring; a variant the solver cannot run runs in pymunk.

    Parameters
    ----------
    scene : Scene
        A 2D scene.
    solver : str, default "pymunk"
        The solver's name.
    dt : float, default 1e-5
        The step (s), at most.
    t_end : float, default 2.0
        The runs' end (s), at most the scene's.
    stiffnesses : tuple of float, default (200.0, 2000.0, 20000.0)
        The springs (N/m).

    Returns
    -------
    Series
        The runs by label, the rigid one last.

    Raises
    ------
    UsageError
        A scene that is not 2D, or another argument that is not allowed.

    Examples
    --------
    A short preview, one spring beside the rigid body:

    >>> import dumbbell
    >>> from dumbbell.analysis.rotation import series
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "tilted-2d.toml")
    >>> series(scene, dt=1e-4, t_end=0.3, stiffnesses=(200.0,))
    <Series tilted-2d: 2 runs (k = 200 N/m, rigid), pymunk at dt = 0.0001 s>
    """
    from ..solvers import available, simulate, solver_class

    scene = args.scene(scene)
    solver = args.choice(solver, "solver", available())
    dt = args.real(dt, "dt", "s")
    t_end = args.real(t_end, "t_end", "s")
    stiffnesses = args.reals(stiffnesses, "stiffnesses", "N/m", empty=True)
    scenes = variants(scene, stiffnesses)
    w_max = max(s.system.omega for s in scenes.values())
    dt = min(dt, 0.05 / w_max) if w_max > 0 else dt
    t_end = min(t_end, scene.run.t_end)
    every = max(1, round(SAMPLE / dt))
    runs = {}
    for label, s in scenes.items():
        name = solver if solver_class(solver).supports(s) is None else "pymunk"
        runs[label] = simulate(s, name, dt=dt, t_end=t_end, every=every)
    return Series(runs, solver, dt, scene)


def mean_after_first_cluster(traj: Trajectory, name: str, gap: float = CLUSTER_GAP
                             ) -> tuple[float, float, float]:
    """Mean of column ``name`` (J) over the flight after the first cluster of impacts: from
    the cluster's last impact (the first one followed by more than ``gap`` s without impact)
    to the next impact or the end of the run. Returns (mean, start s, end s); nan without
    impacts. Averaging only up to the second impact would, for a stiff spring, cover just
    the short time before the other particle lands."""
    traj = args.trajectory(traj)
    name = args.text(name, "name", "a column name (str)")
    gap = args.real(gap, "gap", "s")
    traj[name]  # an unknown column is named before anything is computed
    times = [e.t for e in traj.events]
    if not times:
        return math.nan, math.nan, math.nan
    last = next((i for i in range(len(times) - 1) if times[i + 1] - times[i] > gap),
                len(times) - 1)
    start = times[last]
    end = times[last + 1] if last + 1 < len(times) else float(traj.t[-1])
    m = (traj.t > start + 1e-3) & (traj.t < end - 1e-3)
    return (float(np.mean(traj[name][m])) if m.any() else math.nan), start, end


def preview(traj: Trajectory, window: float = 2.0) -> Series:
    """The runs of the rotation preview for ``traj``'s scene (2D): its solver, its step (the
    scene's without one) and ``window`` s."""
    traj = args.trajectory(traj)
    window = args.real(window, "window", "s")
    dt = traj.dt if traj.dt else traj.scene.run.dt
    return series(traj.scene, solver=traj.solver, dt=dt, t_end=window)
