"""Layer 4, files: every output is written atomically, through :mod:`dumbbell.files`."""

from .._lazy import attach

#: The writers, one module per result, and what they share; each is imported when first
#: read (``dumbbell.io.trajectory.write_csv``).
__getattr__, __dir__, _ = attach(__name__, [
    "bench", "compare", "figures", "restitution", "stability", "sweep",
    "tables", "trajectory"])
#: The public modules: one per command's files (``figures`` and ``tables`` serve the commands
#: and the other writers).
__all__ = ["bench", "compare", "restitution", "stability", "sweep", "trajectory"]
