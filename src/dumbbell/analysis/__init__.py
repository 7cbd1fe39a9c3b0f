"""Layer 3, analysis: computations over trajectories (compare, bench, sweep, stability,
rotation). Imports model and solvers; draws and writes through plot and io."""

from .._lazy import attach

#: The analyses, one module each, imported when first read; the functions :mod:`dumbbell`
#: exports are in :mod:`.api`.
__getattr__, __dir__, _ = attach(__name__, [
    "api", "bench", "compare", "contact", "extended", "metrics", "restitution", "rotation",
    "stability", "sweep", "topple"])
#: The modules with public names (``extended`` and ``metrics`` serve the others).
__all__ = ["api", "bench", "compare", "contact", "restitution", "rotation", "stability",
           "sweep", "topple"]
