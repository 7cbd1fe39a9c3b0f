"""A run's files (:class:`dumbbell.model.trajectory.Trajectory` in): the samples as CSV (the
columns of ``traj.columns``: t in s, positions in m, velocities in m/s, energies in J) and the
impacts as CSV (``t,body,v_before,v_after``: s, -, m/s, m/s). ``dumbbell simulate`` and
``dumbbell run`` write these.

>>> write_csv(traj, "out.csv"); write_events(traj, "out-impacts.csv")   # doctest: +SKIP

Every float is written with 17 significant digits (samples) or ``repr`` (impacts), so the
numbers read back exactly.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

from ..model import args
from ..model.trajectory import Trajectory
from .tables import csv_text, write_text

__all__ = ["dump_csv", "events_csv", "write_csv", "write_events"]

#: Columns of the impacts' CSV (s, -, m/s, m/s).
EVENT_COLUMNS = ("t", "body", "v_before", "v_after")


def _checked(traj: Any) -> Trajectory:
    return args.instance(traj, "traj", Trajectory, "a Trajectory (from simulate)")


def dump_csv(traj: Trajectory, stream: IO[str]) -> None:
    """Write the samples with a header row to the open text ``stream`` (standard output,
    say): one row per sample, the columns of ``traj.columns``."""
    traj = _checked(traj)
    if not callable(getattr(stream, "write", None)):
        from ..errors import UsageError

        raise UsageError(f"stream = {args.show(stream)}: must be an open text file "
                         "(with a write method)", param="stream")
    traj._write_csv(stream)


def write_csv(traj: Trajectory, path: str | Path) -> Path:
    """Write the samples as CSV to ``path`` (see :func:`dump_csv`), whole or not at all (a
    device or a FIFO is written directly); returns the path."""
    return _checked(traj).to_csv(path)


def events_csv(traj: Trajectory) -> str:
    """The impacts as CSV text with :data:`EVENT_COLUMNS`, one line per impact."""
    traj = _checked(traj)
    return csv_text(EVENT_COLUMNS, ((e.t, e.body, e.v_before, e.v_after) for e in traj.events))


def write_events(traj: Trajectory, path: str | Path) -> Path:
    """Write :func:`events_csv` to ``path``, whole or not at all; returns the path."""
    traj = _checked(traj)
    return write_text(args.path(path, "path"), events_csv(traj))
