"""What the ledger's tests measure by hand: a body's energy from pymunk's getters, and a
balance's terms of one kind by source. Shared by ``tests/test_spaces_ledger_sources.py`` and
``tests/test_spaces_ledger_shortcuts.py``."""

from __future__ import annotations

import pymunk

from dumbbell import spaces


def body_energy(body: pymunk.Body, g: tuple[float, float]) -> float:
    """A body's kinetic and gravitational energy, from pymunk's getters (its centre of
    gravity in world coordinates)."""
    cog = body.local_to_world(body.center_of_gravity)
    return (0.5 * body.mass * body.velocity.length_squared
            + 0.5 * body.moment * body.angular_velocity ** 2
            - body.mass * (g[0] * cog[0] + g[1] * cog[1]))


def terms_of(bal: spaces.Balance, kind: str) -> dict[str, float]:
    """The energy of ``bal``'s terms of ``kind``, summed by source."""
    out: dict[str, float] = {}
    for t in bal.terms:
        if t.kind == kind:
            out[t.source] = out.get(t.source, 0.0) + t.energy
    return out
