"""The frozen parts of a scene: its physics (:class:`System`, with its particles, spring or
rod and floor) and the settings of its run and outputs, as :mod:`.scene` reads them."""

from __future__ import annotations

import math
from dataclasses import dataclass

#: No public names: these are the fields of :class:`dumbbell.model.scene.Scene`.
__all__: list[str] = []

#: Relative energy error above which a run is called unstable, unless ``[run]`` says otherwise.
DEFAULT_UNSTABLE_ENERGY = 10.0
#: Default ``run.inaccurate_energy``: past a relative energy error of 0.1 a run that stays
#: stable is ``inaccurate`` (docs/stability.md says why 0.1).
DEFAULT_INACCURATE_ENERGY = 0.1


@dataclass(frozen=True)
class Particle:
    """One particle. Positions in m, velocities in m/s, spin in rad/s, mass in kg."""

    name: str
    mass: float
    x: float
    height: float
    vx: float
    vy: float
    radius: float
    spin: float


@dataclass(frozen=True)
class Spring:
    """A Hooke spring between A and B: stiffness in N/m, rest length in m."""

    stiffness: float
    rest_length: float


@dataclass(frozen=True)
class Rigid:
    """A massless rigid rod between A and B (2D only): length in m."""

    length: float


@dataclass(frozen=True)
class Floor:
    """The floor at height 0 for the particle centres. ``elasticity`` is the restitution
    coefficient (1: elastic), ``friction`` the Coulomb coefficient (2D only)."""

    elasticity: float
    friction: float


@dataclass(frozen=True)
class RunSettings:
    """Default run options: ``t_end`` and ``dt`` in s, ``every`` in steps (keep every N-th),
    ``unstable_energy`` the relative energy error that makes a run ``unstable``, and
    ``inaccurate_energy`` the one past which a run that stays stable is ``inaccurate``."""

    t_end: float
    dt: float
    solver: str
    every: int
    unstable_energy: float
    inaccurate_energy: float = DEFAULT_INACCURATE_ENERGY


@dataclass(frozen=True)
class GifSettings:
    """[outputs.gif]: the animation ``dumbbell run`` writes. ``t_end`` (s) is the scene's
    ``run.t_end`` unless the table says otherwise; the other defaults are written only here."""

    t_end: float
    fps: int = 25
    size: str = "640x360"  # WIDTHxHEIGHT in px
    strip: bool = True


@dataclass(frozen=True)
class OutputSettings:
    """[outputs]: what ``dumbbell run`` makes for the scene (figure names, a CSV, a GIF)."""

    figures: tuple[str, ...]
    csv: bool
    gif: GifSettings | None


@dataclass(frozen=True)
class System:
    """The physics of a scene: the dumbbell, its spring or rod, the floor and gravity.

    ``dimensions`` is 1 (vertical line) or 2; ``g`` in m/s^2 (downward, 0 without gravity);
    ``tilt`` in degrees.
    Solvers, energy formulas and closed forms need only this, not the run or output settings.
    """

    dimensions: int
    A: Particle
    B: Particle
    spring: Spring | None
    rigid: Rigid | None
    floor: Floor | None
    g: float
    #: The axis's angle from vertical (degrees) that placed A from B, or None when the scene
    #: gives A's position. Kept so that changing the length moves A, as in the file.
    tilt: float | None = None
    #: The particles are discs that spin (moment 1/2 m r^2, a ``K_spin`` energy term, 2D
    #: only) rather than points of infinite moment (the textbook's particles). Physics, not
    #: an engine option: every solver and the energy terms follow it. A file sets it with the
    #: ``[pymunk]`` key ``spin``, where it was first introduced.
    discs: bool = False

    @property
    def M(self) -> float:
        """Total mass (kg)."""
        return self.A.mass + self.B.mass

    @property
    def mu(self) -> float:
        """Reduced mass mA*mB/M (kg)."""
        return self.A.mass * self.B.mass / (self.A.mass + self.B.mass)

    @property
    def omega(self) -> float:
        """Angular frequency of the spring's vibration sqrt(k/mu) (rad/s); 0 without spring."""
        return math.sqrt(self.spring.stiffness / self.mu) if self.spring else 0.0

    @property
    def k(self) -> float:
        """Spring stiffness (N/m); 0 without a spring."""
        return self.spring.stiffness if self.spring else 0.0

    @property
    def b(self) -> float:
        """Spring rest length (m); 0 without a spring."""
        return self.spring.rest_length if self.spring else 0.0

    @property
    def elasticity(self) -> float:
        """Floor restitution coefficient; 1 without a floor (it is then never used)."""
        return self.floor.elasticity if self.floor else 1.0

    @property
    def dissipative(self) -> bool:
        """True when energy can leave the system (elasticity below 1, or friction in 2D)."""
        if self.floor is None:
            return False
        return self.floor.elasticity < 1.0 or (self.dimensions == 2 and self.floor.friction > 0)

    def resting_contact(self) -> str | None:
        """None, or why a particle starts in resting contact: on the floor (height 0), not
        moving up, pressed down by gravity. Solvers that model the floor only by impacts
        cannot run such a scene (it would bounce on the spot forever)."""
        if self.floor is None or self.g <= 0:
            return None
        for p in (self.A, self.B):
            if p.height == 0 and p.vy <= 0:
                return (f"bodies.{p.name} starts at rest on the floor (height 0): resting "
                        "contact needs a contact solver such as pymunk; impacts alone cannot "
                        "hold it")
        return None
