"""Layer 4, files: every output is written atomically, through :mod:`dumbbell.io.files`."""

#: The writers, one module per result, and what they share.
__all__ = ["bench", "compare", "figures", "files", "restitution", "stability", "sweep",
           "tables", "trajectory"]
