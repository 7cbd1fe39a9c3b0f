"""The settings of the ``pymunk`` solver: the scene's ``[pymunk]`` table.

The scene reader hands the table to this class, which reads it: what its keys mean, their
bounds and their defaults are kept here, beside the scene that holds them (the model imports
nothing of the solvers). Why these defaults is explained in :mod:`dumbbell.solvers.engine`. The table's ``spin`` key is physics
(whether the particles are spinning discs, :attr:`~dumbbell.model.system.System.discs`), so the
scene reads that one itself.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

#: No public names: the pymunk solver's settings are ``scene.pymunk``.
__all__: list[str] = []


@dataclass(frozen=True)
class PymunkSettings:
    """Engine settings of the ``pymunk`` solver in SI units, as the scene's ``[pymunk]`` table
    gives them; ``None`` means the default below (:meth:`resolved` fills them in)."""

    collision_slop: float | None = None
    collision_bias: float | None = None
    iterations: int | None = None

    #: Overlap tolerated before the position correction acts (m); pymunk's 0.1 is pixels.
    DEFAULT_SLOP: ClassVar[float] = 1e-4
    #: Share of an overlap left after one second: 1.0 turns the correction off, which would
    #: otherwise add energy at each impact.
    DEFAULT_BIAS: ClassVar[float] = 1.0
    #: Contact-impulse iterations per step (pymunk's default).
    DEFAULT_ITERATIONS: ClassVar[int] = 10

    def resolved(self) -> dict[str, Any]:
        """The settings used: the scene's values, else the defaults."""
        return {
            "collision_slop": (self.DEFAULT_SLOP if self.collision_slop is None
                               else self.collision_slop),
            "collision_bias": (self.DEFAULT_BIAS if self.collision_bias is None
                               else self.collision_bias),
            "iterations": self.DEFAULT_ITERATIONS if self.iterations is None else self.iterations,
        }

    @classmethod
    def _read(cls, table: Any) -> PymunkSettings:
        """The settings the scene's ``[pymunk]`` table gives (its checker; None: no table),
        each key checked against its bounds (a SceneError naming the file and key)."""
        if table is None:
            return cls()
        return cls(
            table.number("collision_slop", lo=0.0, unit="m") if table.has("collision_slop")
            else None,
            table.number("collision_bias", lo=0.0, hi=1.0) if table.has("collision_bias")
            else None,
            table.integer("iterations", 10, lo=1, hi=10000) if table.has("iterations")
            else None,
        )

    def _table(self) -> dict[str, Any]:
        """The keys the scene gave, as its ``[pymunk]`` table holds them."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if getattr(self, f.name) is not None}
