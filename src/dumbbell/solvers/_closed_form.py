"""What the closed-form solutions share: the 1D ``exact`` solver (:mod:`.exact`) and the rigid
2D dumbbell's flight (:mod:`.exact_rigid`) find impacts with the same tolerances and end a
run the same way when a particle comes to rest. Both import it; neither imports the other at
file level.
"""

from __future__ import annotations

from ..model.trajectory import Verdict
from .kernels import REST_SPEED  # noqa: F401 - the stepping kernels end a run at this speed

#: Nothing public: tolerances and a verdict the closed-form solvers share.
__all__: list[str] = []

#: Root tolerance for impact times (s).
ROOT_XTOL = 1e-14
#: Intervals shorter than this (s) are not split further: a dip below the floor inside one
#: would be shallower than C * MIN_SPLIT^2 / 8, about 1e-25 m.
MIN_SPLIT = 1e-13
#: A point of a particle's height curve, as the root searches pass it: time (s), height (m)
#: and vertical velocity (m/s).
HeightPoint = tuple[float, float, float]


def at_rest(body: str, t: float, v: float) -> Verdict:
    """The verdict of ``body`` meeting the floor at ``t`` (s) at a speed ``v`` (m/s) below
    :data:`REST_SPEED`: ``failed``, since an inelastic floor has infinitely many impacts in
    finite time there."""
    from .verdicts import rest_reason

    return Verdict("failed", t, rest_reason(body, v))


def search_failed(t: float) -> RuntimeError:
    """The error of an impact search that could not go on in the segment starting at ``t``
    (s): a non-finite height, a bracket Brent's method could not solve (where scipy's
    ``brentq`` raises), or no answer within a run's whole search budget."""
    return RuntimeError(f"the impact search failed in the segment from t = {t:g} s: a "
                        "non-finite height, a bracket Brent's method could not solve, or no "
                        "answer within the search's budget")
