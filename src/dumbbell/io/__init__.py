"""Layer 4, files: every output is written atomically, through :mod:`dumbbell.io.files`."""
