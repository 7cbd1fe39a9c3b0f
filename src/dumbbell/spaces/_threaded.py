"""pymunk's threaded solver (``pymunk.Space(threaded=True)``, Munk2D's cpHastySpace), in
the words the guard's ``threads`` row and the ledger's reasons share.

A threaded space steps as the serial one, bit for bit, at ``space.threads = 1`` (pymunk's
default). At 2 (pymunk's most), a step with more than :data:`THREADED_FROM` touching pairs
and joints splits the solver's iterations between the two threads: each sweeps every contact
and joint at the same time as the other, reading and writing the same bodies' velocities
and the same accumulated impulses without locks. Whatever one thread writes between the
other's read and write is lost: the bodies' velocities then disagree with the impulses the
contacts and joints accumulated, and a run does not repeat."""

from __future__ import annotations

#: Touching pairs and joints a step needs before the threaded solver runs on more than one
#: thread ("arbiters + constraints > 50" in cpHastySpaceStep; not settable from pymunk).
THREADED_FROM = 50

__all__: list[str] = []


def hazard(threads: int) -> str:
    """What ``space.threads = threads`` (more than 1) does to a step, in one clause."""
    return (f"in a step with more than {THREADED_FROM} touching pairs and joints, pymunk's "
            f"threaded solver splits the iterations between the {threads} threads, each "
            "sweeping every contact and joint at the same time as the other without locks, "
            "so an impulse one thread applies can be overwritten by the other's and a run "
            "does not repeat")
