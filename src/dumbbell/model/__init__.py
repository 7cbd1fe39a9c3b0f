"""Layer 1, the model: a scene (TOML -> :class:`Scene`), the energy formulas and the
:class:`Trajectory` a solver returns. Imports nothing else from the package but errors."""

from .._lazy import attach

#: The package's own names: none; the API is in its modules, imported when first read
#: (``args``, the checks, is the package's own).
__getattr__, __dir__, _ = attach(__name__, ["args", "energy", "scene", "trajectory"])
__all__ = ["energy", "scene", "trajectory"]
