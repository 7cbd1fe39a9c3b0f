"""A run's files (:class:`dumbbell.model.trajectory.Trajectory` in): the samples as CSV (the
columns of ``traj.columns``: t in s, positions in m, velocities in m/s, energies in J) and the
impacts as CSV (``t,body,v_before,v_after``: s, -, m/s, m/s). ``dumbbell simulate`` and
``dumbbell run`` write these.

Every float is written with 17 significant digits (samples) or ``repr`` (impacts), so the
numbers read back exactly.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

from ..files import writable_path
from ..model import args
from ..model.trajectory import Trajectory
from .tables import csv_text, write_text

__all__ = ["dump_csv", "events_csv", "write_csv", "write_events"]

#: Columns of the impacts' CSV (s, -, m/s, m/s).
EVENT_COLUMNS = ("t", "body", "v_before", "v_after")


def _checked(traj: Any) -> Trajectory:
    return args.instance(traj, "traj", Trajectory, "a Trajectory (from simulate)")


def dump_csv(traj: Trajectory, stream: IO[str]) -> None:
    """Write the samples with a header row to an open text stream: one row per sample, the
    columns of ``traj.columns``, every float with 17 significant digits.

    Parameters
    ----------
    traj : Trajectory
        The run.
    stream : text file
        Where to write (standard output, say): anything with a ``write`` method.

    Raises
    ------
    UsageError
        A ``traj`` that is not a Trajectory, or a stream without ``write``.

    Examples
    --------
    >>> from dumbbell.io.trajectory import dump_csv
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=1.0, dt=0.1)
    >>> import sys
    >>> dump_csv(traj, sys.stdout)
    t,xA,vA,xB,vB,K_cm,K_int,U_g,U_spring,E
    0,1.2000000000000002,0,1,0,0,0,2.1560000000000006,...
    """
    traj = _checked(traj)
    if not callable(getattr(stream, "write", None)):
        from ..errors import UsageError

        raise UsageError(f"stream = {args.show(stream)}: must be an open text file "
                         "(with a write method)", param="stream")
    traj._write_csv(stream)


def write_csv(traj: Trajectory, path: str | Path) -> Path:
    """Write the samples as CSV (see :func:`dump_csv`), whole or not at all (a device or a
    FIFO is written directly): ``dumbbell simulate -o FILE``.

    Parameters
    ----------
    traj : Trajectory
        The run.
    path : str or pathlib.Path
        The CSV file (missing folders are made).

    Returns
    -------
    pathlib.Path
        ``path``, now holding the samples.

    Raises
    ------
    UsageError
        A ``traj`` that is not a Trajectory, or a path that cannot be written (one line
        saying why).

    Examples
    --------
    The header row of the file written:

    >>> from dumbbell.io.trajectory import write_csv
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> traj = dumbbell.simulate(dumbbell.load_scene(scenes_dir() / "textbook-1d.toml"),
    ...                          solver="exact", t_end=1.0, dt=0.1)
    >>> write_csv(traj, "exact.csv").read_text().splitlines()[0]
    't,xA,vA,xB,vB,K_cm,K_int,U_g,U_spring,E'
    """
    return _checked(traj).to_csv(path)


def events_csv(traj: Trajectory) -> str:
    """The impacts as CSV text: ``t,body,v_before,v_after`` (s, -, m/s, m/s), one line per
    impact, each float as its ``repr``.

    Parameters
    ----------
    traj : Trajectory
        The run (its ``events``).

    Returns
    -------
    str
        The CSV text, a header line first.

    Raises
    ------
    UsageError
        A ``traj`` that is not a Trajectory.

    Examples
    --------
    The textbook's first two impacts, both of particle B:

    >>> import dumbbell
    >>> from dumbbell.io.trajectory import events_csv
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> print(events_csv(dumbbell.simulate(scene, solver="exact", t_end=1.0, dt=0.1)))
    t,body,v_before,v_after
    0.4517539514526256,B,-4.42718872423573,4.42718872423573
    0.49895130056316217,B,-4.835568954040384,4.835568954040384
    <BLANKLINE>
    """
    traj = _checked(traj)
    return csv_text(EVENT_COLUMNS, ((e.t, e.body, e.v_before, e.v_after) for e in traj.events))


def write_events(traj: Trajectory, path: str | Path) -> Path:
    """Write :func:`events_csv` to a file, whole or not at all: ``dumbbell simulate --events
    FILE``.

    Parameters
    ----------
    traj, path
        As for :func:`write_csv`.

    Returns
    -------
    pathlib.Path
        The impacts' file, written.

    Raises
    ------
    UsageError
        As for :func:`write_csv`.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.io.trajectory import write_events
    >>> from dumbbell.model.scene import scenes_dir
    >>> traj = dumbbell.simulate(dumbbell.load_scene(scenes_dir() / "textbook-1d.toml"),
    ...                          solver="exact", t_end=1.0)
    >>> len(write_events(traj, "impacts.csv").read_text().splitlines())   # header, 2 impacts
    3
    """
    traj = _checked(traj)
    path = writable_path(path)
    return write_text(path, events_csv(traj))
