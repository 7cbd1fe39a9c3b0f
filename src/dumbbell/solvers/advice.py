"""What to change when a run does not end ``ok``: a step that should, with the reason for it.

Every verdict other than ``ok`` ends its message with what to change. Where the step is the
cause, that is a value, ``try dt = X s``: the largest of one significant digit below every
bound that applies, each of which keeps the relative energy error within a quarter of the
scene's ``run.inaccurate_energy`` (the :data:`MARGIN`):

- the spring (:func:`spring_bound`): a solver whose stable step swings the vibration energy
  by ``swing(w*dt)``, or moves it by ``drift(w*dt, steps)`` over the run (its class says so),
  needs that within the margin; a solver with a step limit and no such theory, a tenth of
  its limit;
- the impacts, from theory (:func:`impact_bound`): each impact is caught up to a step late,
  which costs up to w*dt of the energy (w the spring's, or the speed at impact over the
  dumbbell's length for a rod), so N impacts in the run need N w dt within the margin;
- the error the run itself measured (:func:`measured_bound`): an error e (at most
  :data:`MEASURED_MAX`) by the time t_m, grown linearly to ``t_end`` and scaled down as dt^p
  (p the solver's ``order``), replaces the impact theory when there is one (it is this
  scene's own);
- a floor of finite thickness (:func:`catch_bound`): half the step at which a contact is just
  caught.

``tests/test_advice.py`` runs the suggested step of every shipped failure and of variants of
them, and checks that it ends ``ok``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..model.scene import Scene, System

if TYPE_CHECKING:
    from .base import Solver

#: Nothing public: the verdicts' messages use it.
__all__: list[str] = []

#: The largest measured error that is scaled to a step: past it (the energy changed by more
#: than itself) the run is out of the regime where the error goes as dt^p, and the theory's
#: bounds stand alone.
MEASURED_MAX = 1.0
#: The share of ``run.inaccurate_energy`` a suggested step aims at: the bounds are estimates,
#: and the motion chaotic, so a step is suggested for a quarter of the threshold.
MARGIN = 0.25


@dataclass(frozen=True)
class Bound:
    """A step (s) that keeps one source of energy error within the margin, and that source
    in words."""

    dt: float
    why: str


def seconds(value: float) -> str:
    """A time as people write it: '0.031', '3.16e-3' (s, without the unit)."""
    if value == 0 or 1e-2 <= abs(value) < 1e4:
        return f"{value:.3g}"
    mantissa, exponent = f"{value:.2e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"


def one_digit(value: float) -> float:
    """``value`` (> 0) rounded down to one significant digit: 4.88e-5 -> 4e-5."""
    exponent = math.floor(math.log10(value))
    digit = math.floor(value / 10.0**exponent * (1 + 1e-12))
    return float(f"{max(digit, 1)}e{exponent}")


def target(scene: Scene) -> float:
    """The relative energy error a suggested step aims at: :data:`MARGIN` times the smaller of
    the scene's two thresholds."""
    return MARGIN * min(scene.run.inaccurate_energy, scene.run.unstable_energy)


def step_error(cls: type[Solver], ratio: float, periods: float) -> float | None:
    """The relative change of the vibration energy the theory of ``cls`` gives for a stable
    run at w*dt = ``ratio`` over ``periods`` radians of vibration (w t_end): the larger of its
    ``swing`` and its ``drift`` over those steps; None where it states neither."""
    found = [v for v in (cls.swing(ratio), cls.drift(ratio, periods / ratio if ratio > 0
                                                      else 0.0)) if v is not None]
    return max(found) if found else None


def quiet_ratio(cls: type[Solver], goal: float, periods: float) -> float | None:
    """The largest w*dt at which a stable run of ``cls`` over ``periods`` radians of
    vibration moves the vibration energy by at most ``goal`` (:func:`step_error`, bisected),
    a tenth of its step limit where its theory states nothing; None without a step limit."""
    limit = cls.step_limit
    if limit is None:
        return None
    if step_error(cls, limit / 2, periods) is None:
        return limit / 10
    lo, hi = 0.0, float(limit)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        error = step_error(cls, mid, periods)
        if error is not None and error <= goal:
            lo = mid
        else:
            hi = mid
    return lo


def spring_bound(cls: type[Solver], scene: Scene) -> Bound | None:
    """The step at which the spring's own error stays within the margin (None without a
    spring or a step limit)."""
    w, goal = scene.system.omega, target(scene)
    periods = w * scene.run.t_end
    ratio = quiet_ratio(cls, goal, periods) if w > 0 else None
    if ratio is None or ratio <= 0:
        return None
    error = step_error(cls, ratio, periods)
    why = (f"w*dt <= {ratio:.2g}, where a stable step moves the vibration energy by at most "
           f"{error:.2g}" if error is not None else f"w*dt <= {ratio:.2g}, a tenth of the "
           f"step limit {cls.step_limit:.3g}")
    return Bound(ratio / w, why)


def impact_speed(system: System) -> float:
    """Speed (m/s) at which the lower particle meets the floor, as a point falling from its
    height with its starting vertical velocity (the spring's vibration is left out)."""
    low = min((system.A, system.B), key=lambda p: p.height)
    return math.sqrt(low.vy**2 + 2.0 * max(system.g, 0.0) * max(low.height, 0.0))


def length(system: System) -> float:
    """The dumbbell's length (m): its rod, else its spring's rest length, else the particles'
    starting distance (for a spring of zero rest length)."""
    if system.rigid is not None:
        return system.rigid.length
    return system.b or math.hypot(system.A.x - system.B.x, system.A.height - system.B.height)


def impact_bound(cls: type[Solver], scene: Scene) -> Bound | None:
    """The step at which N impacts, each caught up to a step late, cost the margin at most
    (None without a floor, without a step, or when nothing falls onto the floor)."""
    system = scene.system
    v = impact_speed(system)
    if system.floor is None or not cls.has_step or not v > 0:
        return None
    size = length(system)
    w = max(system.omega, v / size if size > 0 else 0.0)
    if not w > 0:
        return None
    # An elastic bounce of the lower particle takes 2 v / g; each bounce is about two impacts.
    impacts = max(2.0, scene.run.t_end * system.g / v) if system.g > 0 else 2.0
    dt = target(scene) / (impacts * w)
    return Bound(dt, f"about {impacts:.0f} impacts, each caught up to a step late, at "
                     f"w*dt = {w * dt:.2g} of the energy each")


def measured_bound(cls: type[Solver], scene: Scene, dt: float, error: float, until: float
                   ) -> Bound | None:
    """The step at which the relative energy error ``error`` this run measured by ``until``
    (s) at step ``dt``, grown linearly to the scene's ``t_end`` and scaled as dt^order, stays
    within the margin (None when nothing was measured)."""
    if not (0 < error <= MEASURED_MAX and until > 0):
        return None
    grown = error * max(1.0, scene.run.t_end / until)
    order = cls.order or 1
    new = dt * (target(scene) / grown) ** (1.0 / order)
    return Bound(new, f"the energy error {error:.2g} measured by t = {until:.4g} s, grown to "
                      f"{scene.run.t_end:g} s and scaled as dt^{order}")


def catch_bound(depth: float | None, speed: float) -> Bound | None:
    """Half the step at which a particle moving down at ``speed`` (m/s) is still caught
    within ``depth`` (m) of the floor (None without such a depth)."""
    if depth is None or not depth > 0 or not speed > 0:
        return None
    return Bound(0.5 * depth / speed, f"half the step that moves it {depth:.3g} m at "
                                      f"{speed:.3g} m/s, where a contact is still caught")


def step_bounds(cls: type[Solver], scene: Scene, measured: tuple[float, float, float] | None
                ) -> list[Bound]:
    """The bounds that apply to a run of ``cls`` on ``scene``; ``measured`` = (dt, error,
    until) when the run measured a finite energy error, which then replaces the impact
    theory. A spring alone (no floor, no gravity) has its theory, which is exact: its error
    is the swing, not an error that grows with time or scales as a power of dt."""
    bounds = [spring_bound(cls, scene)]
    if scene.system.floor is not None or scene.system.g > 0 or bounds[0] is None:
        found = measured_bound(cls, scene, *measured) if measured is not None else None
        bounds.append(found if found is not None else impact_bound(cls, scene))
    return [b for b in bounds if b is not None]


def suggest(dt: float, bounds: Sequence[Bound | None]) -> tuple[float, str] | None:
    """The suggested step (s, one significant digit, below ``dt``) and why, from the
    tightest of ``bounds``; None when no bound asks for a step below ``dt``."""
    found = [b for b in bounds if b is not None and b.dt > 0]
    if not found:
        return None
    tight = min(found, key=lambda b: b.dt)
    value = one_digit(tight.dt)
    if not value < dt:
        return None
    return value, tight.why


def step_text(scene: Scene, dt: float, bounds: Sequence[Bound | None]) -> str:
    """``"try dt = X s (why)"`` for the tightest bound, with what it costs when that is
    more steps than a run may take; empty when no bound asks for a smaller step."""
    from .base import MAX_SAMPLES, MAX_STEPS

    found = suggest(dt, bounds)
    if found is None:
        return ""
    value, why = found
    text = f"try dt = {seconds(value)} s ({why})"
    steps = scene.run.t_end / value
    if steps > MAX_STEPS:
        text += f"; that is {steps:.2g} steps over {scene.run.t_end:g} s: shorten run.t_end"
    elif steps / scene.run.every > MAX_SAMPLES:
        every = math.ceil(scene.run.every * dt / value)
        text += f", with every = {every:,} to keep a sample every {seconds(dt * scene.run.every)} s"
    return text


def holding_solvers(scene: Scene) -> list[str]:
    """The registered solvers that hold a particle in lasting contact (no flip floor) and
    can run ``scene``."""
    from .base import REGISTRY

    return [cls.name for cls in REGISTRY.values()
            if not cls.flip_floor and cls._supports(scene) is None]


def rest_text(scene: Scene, t: float) -> str:
    """What to change for a run that ends at ``t`` (s) because a particle came to rest on an
    inelastic floor, which no step of a velocity-flip floor can get past."""
    text = f"end the run before it (run.t_end = {seconds_below(t)} s)"
    holders = holding_solvers(scene)
    if holders:
        text += f" or use a solver that holds resting contact ({', '.join(holders)})"
    return text


def seconds_below(t: float) -> str:
    """A time just below ``t`` (s) as people write it: two significant digits, rounded
    down."""
    if not t > 0:
        return "0"
    exponent = math.floor(math.log10(t)) - 1
    return seconds(math.floor(t / 10.0**exponent * (1 + 1e-12)) * 10.0**exponent)
