"""The work budget of an analysis that makes many runs: the product of its axes (tilts x
stiffnesses in ``restitution``, steps x solvers in ``compare`` and ``bench``, cases x solvers
in ``stability``), checked before the first run. (``sweep`` has its own: at most 250,000
points, 1e10 steps in all.)"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import UsageError

#: No public names: the analyses check their own arguments with it.
__all__: list[str] = []

#: Most runs one call of an analysis may make: ten times the largest default (restitution's
#: 91 tilts x 4 dumbbells is 364).
MAX_RUNS = 1_000
#: Most steps of all the runs of one call together: the cap of a single run
#: (:data:`dumbbell.solvers.MAX_STEPS`), so that a command does at most the work one run may.
MAX_TOTAL_STEPS = 10**10


def check_runs(runs: int, product: str, fixes: Sequence[str], param: str | None = None
               ) -> None:
    """UsageError when ``runs`` (spelt out as ``product``, e.g. '91 tilts x 4 dumbbells')
    passes :data:`MAX_RUNS`; ``fixes`` name the parameters that lower it (see
    :class:`UsageError`)."""
    if runs > MAX_RUNS:
        raise UsageError(f"{product} is {runs:,} runs, past the budget of {MAX_RUNS:,} runs "
                         "per call", param=param, fixes=fixes)


def check_steps(steps: float, what: str, fixes: Sequence[str], budget: float = MAX_TOTAL_STEPS,
                param: str | None = None) -> None:
    """UsageError when ``steps`` (a float: it may be huge) for ``what`` pass ``budget``."""
    if not steps <= budget:
        count = f"{steps:.3g}" if steps < 1e300 else "more than 1e300"
        raise UsageError(f"{what} would take {count} steps in all, past the budget of "
                         f"{budget:.0e}", param=param, fixes=fixes)
