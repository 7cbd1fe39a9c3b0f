"""Layer 1, the model: a scene (TOML -> :class:`Scene`), the energy formulas and the
:class:`Trajectory` a solver returns. Imports nothing else from the package but errors."""
