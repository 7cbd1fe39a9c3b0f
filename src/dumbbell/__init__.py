"""dumbbell: how a body's mechanical energy is shared between its centre-of-mass motion and
its internal motion, from the bouncing dumbbell of textbook section 13.5.1.

>>> import dumbbell
>>> scene = dumbbell.load_scene("scenes/textbook-1d.toml")            # doctest: +SKIP
>>> traj = dumbbell.simulate(scene, solver="exact", every=100)        # doctest: +SKIP
>>> traj.t, traj["K_int"], traj.events[0].t                           # doctest: +SKIP
"""

from .analysis.api import bench, compare, stability, sweep
from .animation.render import Gif, render_gif
from .errors import ColumnError, DumbbellError, MissingExtraError, SceneError, UsageError
from .model.scene import Scene, load_scene
from .model.trajectory import Impact, Trajectory, Verdict

# Not bound to the name ``solvers``: that is the package (dumbbell.solvers.exact, ...).
from .solvers import available as available_solvers
from .solvers import simulate

__all__ = [
    "ColumnError", "DumbbellError", "Gif", "Impact", "MissingExtraError", "Scene", "SceneError",
    "Trajectory", "UsageError", "Verdict", "available_solvers", "bench", "compare", "load_scene",
    "render_gif", "simulate", "stability", "sweep",
]
__version__ = "0.1.0"
