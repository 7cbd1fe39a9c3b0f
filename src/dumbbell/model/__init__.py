"""Layer 1, the model: a scene (TOML -> :class:`Scene`), the energy formulas and the
:class:`Trajectory` a solver returns. Imports nothing else from the package but errors."""

#: The package's own names: none; the API is in its modules (scene, energy, trajectory).
__all__: list[str] = []
