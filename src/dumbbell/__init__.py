"""dumbbell: how a body's mechanical energy is shared between its centre-of-mass motion and
its internal motion, from the bouncing dumbbell of textbook section 13.5.1.

>>> import dumbbell
>>> scene = dumbbell.load_scene("scenes/textbook-1d.toml")            # doctest: +SKIP
>>> traj = dumbbell.simulate(scene, solver="exact", every=100)        # doctest: +SKIP
>>> traj.t, traj["K_int"], traj.events[0].t                           # doctest: +SKIP
>>> dumbbell.plot.kinetic(traj)                                       # doctest: +SKIP

Everything loads on first use (the scientific-Python lazy-loading convention): ``import
dumbbell`` imports neither numpy-heavy solvers nor matplotlib, pymunk, numba or scipy, and
``dumbbell.plot``, ``dumbbell.io.trajectory``, ``dumbbell.spaces`` work without an import of
their own.
"""

from __future__ import annotations

from ._lazy import attach as _attach

#: Public name -> the module that defines it.
_NAMES = {
    "bench": "analysis.api", "compare": "analysis.api", "stability": "analysis.api",
    "sweep": "analysis.api",
    "Gif": "animation.render", "render_gif": "animation.render",
    "Player": "animation.player", "player": "animation.player",
    "ColumnError": "errors", "DumbbellError": "errors", "MissingExtraError": "errors",
    "PymunkVersionError": "errors", "SceneError": "errors", "UsageError": "errors",
    "Scene": "model.scene", "load_scene": "model.scene",
    "Impact": "model.trajectory", "Trajectory": "model.trajectory", "Verdict": "model.trajectory",
    "simulate": "solvers",
}
#: The subpackages and modules, each imported when first read (``dumbbell.plot``).
SUBMODULES = ("analysis", "animation", "cli", "errors", "examples", "io", "model", "parallel",
              "plot", "progress", "solvers", "spaces")

_getattr, _, _ = _attach(__name__, SUBMODULES, _NAMES)

__all__ = [
    "ColumnError", "DumbbellError", "Gif", "Impact", "MissingExtraError", "Player",
    "PymunkVersionError", "Scene", "SceneError", "Trajectory", "UsageError", "Verdict",
    "available_solvers", "bench", "compare", "load_scene", "player", "render_gif", "simulate",
    "stability", "sweep",
]


def __getattr__(name: str) -> object:
    if name == "available_solvers":
        # Not bound to the name ``solvers``: that is the package (dumbbell.solvers.exact, ...).
        from .solvers import available

        globals()[name] = available
        return available
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            value = version(__name__)
        except PackageNotFoundError:  # run from a source tree that was never installed
            value = "unknown"
        globals()[name] = value
        return value
    return _getattr(name)


def __dir__() -> list[str]:
    return sorted(set(__all__) | set(SUBMODULES) | {"__version__"})


# typing is not imported here (it costs more than the rest of `import dumbbell`).
TYPE_CHECKING = False
if TYPE_CHECKING:
    from .analysis.api import bench, compare, stability, sweep
    from .animation.player import Player, player
    from .animation.render import Gif, render_gif
    from .errors import ColumnError, DumbbellError, MissingExtraError, SceneError, UsageError
    from .model.scene import Scene, load_scene
    from .model.trajectory import Impact, Trajectory, Verdict
    from .solvers import available as available_solvers
    from .solvers import simulate
