"""The energy ledger over pymunk's own example programs: the cases, one run each, and the
table of docs/spaces-reference.md ("The ledger on pymunk's examples").

Shared by ``tests/test_spaces_ledger_corpus.py`` (which checks each case and that the table
in the docs is the one these runs give) and ``benchmarks/spaces_ledger.py`` (which prints
it): ``python benchmarks/spaces_ledger.py --table``.

What a case adds to a program, and only this:

- the constraints demo, one kind at a time (``keep_only``), with its two bodies set
  spinning at 2 and -1 rad/s, and the free ones (the balls of the first five boxes) thrown
  apart at 100 px/s (at rest most of its boxes never move, so most kinds would do nothing);
- planet, a second time with the field's potential -G M m / r declared;
- damped_rotary_spring_pointer: its pointer (a kinematic body the mouse turns) turned by
  1 rad at the 10th step, as a mouse would.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .pymunk_corpus import CONSTRAINT_KINDS, keep_only, run_example

#: Kinds whose two bodies the demo does not pin to the wall.
_FREE = ("PinJoint", "SlideJoint", "PivotJoint", "GrooveJoint", "DampedSpring")


@dataclass(frozen=True)
class Case:
    """One run: the table's label, the example program, the steps, and what is added."""

    label: str
    example: str
    steps: int
    kind: str | None = None
    declare: bool = False
    turn_pointer: bool = False


CASES = (
    *(Case(f"constraints: {kind}", "constraints", 150, kind=kind) for kind in CONSTRAINT_KINDS),
    Case("constraints (all)", "constraints", 150),
    Case("newtons_cradle", "newtons_cradle", 300),
    Case("planet", "planet", 120),
    Case("planet, -GMm/r declared", "planet", 300, declare=True),
    Case("box2d_pyramid", "box2d_pyramid", 150),
    Case("box2d_vertical_stack", "box2d_vertical_stack", 300),
    Case("slide_and_pinjoint", "slide_and_pinjoint", 300),
    Case("damped_rotary_spring_pointer", "damped_rotary_spring_pointer", 60,
         turn_pointer=True),
    Case("spiderweb", "spiderweb", 150),
    Case("tank", "tank", 200),
    Case("flipper", "flipper", 150),
    Case("contact_with_friction", "contact_with_friction", 200),
    Case("bouncing_balls", "bouncing_balls", 300),
    Case("breakout", "breakout", 120),
)


@dataclass
class Result:
    """A case's run: the balance, the energy ``spaces.energy`` gives at the end (plus the
    declared field's), and the space."""

    case: Case
    balance: Any
    energy_now: float
    space: Any


def _field(space: Any) -> tuple[Callable[..., Any], Callable[..., Any]]:
    """planet's velocity function and the potential of its field: the function pulls with
    g = -G (p - c) / r^3, so U = -G m / r."""
    import numpy as np

    func = next(iter(space.bodies)).velocity_func
    G, c = func.__globals__["gravityStrength"], func.__globals__["center"]
    return func, lambda x, y, m: -G * m / np.hypot(x - c.x, y - c.y)


def run(case: Case) -> Result:
    """Run ``case`` with a ledger attached before its first step."""
    from dumbbell import spaces

    held: dict[str, Any] = {}

    def start(space: Any) -> None:
        if case.kind is not None:
            for i, body in enumerate(space.bodies):
                body.angular_velocity = (2.0, -1.0)[i % 2]
                if case.kind in _FREE:
                    body.velocity = ((-100.0, 0.0), (100.0, 0.0))[i % 2]
        ledger = held["ledger"] = spaces.Ledger(space)
        if case.declare:
            func, potential = _field(space)
            held["potential"] = potential
            ledger.declare_potential(func, potential, name="planet's field")

    def step(space: Any, dt: float) -> None:
        held["steps"] = held.get("steps", 0) + 1
        if case.turn_pointer and held["steps"] == 10:
            pointer = next(iter(space.constraints)).a
            pointer.angle += 1.0

    isolate = keep_only(case.kind) if case.kind is not None else None
    run = run_example(case.example, case.steps, on_start=start, on_step=step, isolate=isolate)
    balance = held["ledger"].balance()
    now = spaces.energy(run.space).E
    if "potential" in held:
        import numpy as np

        bodies = list(run.space.bodies)
        x = np.array([b.local_to_world(b.center_of_gravity)[0] for b in bodies])
        y = np.array([b.local_to_world(b.center_of_gravity)[1] for b in bodies])
        now += float(np.sum(held["potential"](x, y, np.array([b.mass for b in bodies]))))
    return Result(case, balance, now, run.space)


def _bound(x: float) -> str:
    """An upper bound, a power of ten, and at least 1e-12 (below that it is rounding,
    whose digits may differ from one machine to another)."""
    if x < 1e-12:
        return "< 1e-12"
    return f"< 1e{math.floor(math.log10(x)) + 1}"


def _unaccounted(balance: Any) -> str:
    names = [name for name, _ in balance.unaccounted]
    if not names:
        return "-"
    reasons = {why.split(":")[0].split(" (")[0] for _, why in balance.unaccounted}
    if len(names) > 3:
        return f"{len(names)} sources ({'; '.join(sorted(reasons))})"
    return ", ".join(names)


def row(result: Result) -> str:
    """The case's line in the table."""
    b = result.balance
    kinds = sorted(b.by_kind().items(), key=lambda kv: -abs(kv[1]))
    top = ", ".join(f"{kind} {value / b.scale:+.2g}" for kind, value in kinds[:3]
                    if b.scale > 0 and abs(value) >= 1e-4 * b.scale) or "-"
    return (f"| {result.case.label} | {b.steps} | {b.E0:.4g} | {b.scale:.3g} | "
            f"{_bound(b.relative_closure)} | {top} | {_unaccounted(b)} | "
            f"{'yes' if b.complete else 'no'} |")


HEADER = ("| example | steps | E(0) | scale | closure / scale | largest terms / scale "
          "| named as unaccounted | complete |\n|---|---|---|---|---|---|---|---|")


def table(results: list[Result]) -> str:
    """The docs table of these runs."""
    return "\n".join([HEADER, *(row(r) for r in results)])
