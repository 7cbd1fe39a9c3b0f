"""Layer 3, analysis: computations over trajectories (compare, bench, sweep, stability,
rotation). Imports model and solvers; draws and writes through plot and io."""

#: The analyses, one module each; the functions :mod:`dumbbell` exports are in :mod:`.api`.
__all__ = ["api", "bench", "compare", "contact", "extended", "metrics", "restitution",
           "rotation", "stability", "sweep", "topple"]
