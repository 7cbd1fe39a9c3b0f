"""The one result type every solver returns.

>>> traj = simulate(scene, "exact", every=100)              # doctest: +SKIP
>>> traj.t[:3], traj["xB"][:3], traj["E"][0]                # doctest: +SKIP
>>> traj.verdict.status, len(traj.events)                   # doctest: +SKIP
('ok', 22)

A Trajectory is frozen: a solver builds it once, after its verdict has decided where the run
ends, and nobody changes it afterwards (its arrays are read-only). State columns (positions in m,
velocities in m/s) come from the solver; energy columns (J) come from the solver where it
counts them itself (pymunk), else from :mod:`dumbbell.model.energy`, the one place that knows
the formulas, at construction.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import UsageError
from . import args
from .scene import Scene

if TYPE_CHECKING:
    import pandas

#: How many impacts the notebook table lists.
FIRST_IMPACTS = 5

#: Verdict statuses, from good to bad.
VERDICTS = ("ok", "inaccurate", "unstable", "tunnelled", "failed")
#: The statuses of a run that reached its end with every sample kept (stable): ``ok``, and
#: ``inaccurate`` (its energy error passed ``run.inaccurate_energy``).
COMPLETE = ("ok", "inaccurate")

_FINITE = math.isfinite

__all__ = ["Contact", "Impact", "Trajectory", "Verdict"]


def _time(value: Any, name: str, optional: bool = False) -> None:
    """UsageError naming ``name`` unless ``value`` is a finite number of seconds (or None
    when ``optional``). A float takes the fast path: solvers build an Impact per bounce."""
    if type(value) is float and math.isfinite(value) or optional and value is None:
        return
    args.real(value, name, "s", positive=False)


def _number(value: Any, name: str, unit: str) -> None:
    """UsageError naming ``name`` unless ``value`` is a number (``unit``). Not necessarily finite:
    a run that blows up may record an impact on its way out, and its verdict says so."""
    if type(value) is float or isinstance(value, int | np.floating) and not isinstance(
            value, bool):
        return
    raise UsageError(f"{name} = {args.show(value)}: must be a number ({unit})", param=name)


#: Rows of the samples' CSV formatted at once (a few MB of text).
CSV_BLOCK = 8192


@dataclass(frozen=True)
class Impact:
    """One impact with the floor, as a run's ``events`` hold them: when, which particle,
    its vertical velocity before and after, and the energy it dissipated.

    Parameters
    ----------
    t : float
        When (s).
    body : {'A', 'B'}
        Which particle hit the floor.
    v_before, v_after : float
        Its vertical velocity just before and just after (m/s).
    heat : float or None, default None
        The energy the impact dissipated (J) where the solver states it; None: a free
        particle's ``1/2 m (v_before^2 - v_after^2)``.

    Raises
    ------
    UsageError
        A body other than 'A' or 'B', a time that is not a finite number of seconds, or a
        velocity or heat that is not a number.

    Examples
    --------
    The textbook's first impact, and a body the dumbbell does not have:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=1.0, dt=1e-3)
    >>> traj.events[0]
    Impact(t=0.4517539514526256, body='B', v_before=-4.42718872423573, v_after=4.42718872423573, heat=None)
    >>> from dumbbell.model.trajectory import Impact
    >>> Impact(0.45, "C", -4.4, 4.4)
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: body = 'C': must be 'A' or 'B'
    """

    t: float
    body: str
    v_before: float
    v_after: float
    heat: float | None = None

    def __post_init__(self) -> None:
        # Cheap checks only: a misspelt body or a time that is not one would mislead every
        # table and figure built from the impacts. What solvers build (floats, 'A' or 'B')
        # passes the first test alone; anything else is looked at field by field.
        if (type(self.t) is float and type(self.v_before) is float
                and type(self.v_after) is float and (self.body == "A" or self.body == "B")
                and (self.heat is None or type(self.heat) is float) and _FINITE(self.t)):
            return
        if self.body != "A" and self.body != "B":
            raise UsageError(f"body = {args.show(self.body)}: must be 'A' or 'B'", param="body")
        _time(self.t, "t")
        _number(self.v_before, "v_before", "m/s")
        _number(self.v_after, "v_after", "m/s")
        if self.heat is not None:
            _number(self.heat, "heat", "J")


@dataclass(frozen=True)
class Contact:
    """A lasting contact with the floor, not an impact: a particle resting or rolling on the
    floor. Only a contact solver (pymunk) has them; how they are told from impacts:
    docs/solvers.md.

    Parameters
    ----------
    t_start, t_end : float
        When the contact starts and ends (s; ``t_end`` is the run's end if it still touches
        then); :attr:`duration` is the difference.
    body : {'A', 'B'}
        Which particle touches.

    Raises
    ------
    UsageError
        A body other than 'A' or 'B', a time that is not a finite number of seconds, or
        ``t_end`` before ``t_start``.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "topple-2d.toml")
    >>> traj = dumbbell.simulate(scene, solver="pymunk", dt=1e-4, t_end=0.5)
    >>> traj.contacts[1]                        # A lands at 0.4065 s and stays down
    Contact(t_start=0.40650000000000003, t_end=0.5, body='A')
    >>> round(traj.contacts[1].duration, 4)
    0.0935
    """

    t_start: float
    t_end: float
    body: str

    def __post_init__(self) -> None:
        if self.body != "A" and self.body != "B":
            raise UsageError(f"body = {args.show(self.body)}: must be 'A' or 'B'", param="body")
        _time(self.t_start, "t_start")
        _time(self.t_end, "t_end")
        if not self.t_start <= self.t_end:
            raise UsageError(f"t_end = {self.t_end!r} s: must not come before t_start = "
                             f"{self.t_start!r} s", param="t_end")

    @property
    def duration(self) -> float:
        """How long the contact lasts (s)."""
        return self.t_end - self.t_start


@dataclass(frozen=True)
class Verdict:
    """How a run ended: a trajectory's ``verdict``. ``str(verdict)`` is ``ok`` or one line with
    the status, the time and the reason.

    Parameters
    ----------
    status : {'ok', 'inaccurate', 'unstable', 'tunnelled', 'failed'}, default 'ok'
        How the run ended (:data:`VERDICTS`); :attr:`ok` is ``status == 'ok'``.
    t : float or None, default None
        The time of failure (s; None when ok; for ``inaccurate`` the step where the energy
        error first passed ``run.inaccurate_energy``, the run going on to its end).
    reason : str, default ''
        Why, in words, and what to change.

    Raises
    ------
    UsageError
        A status not in the list, a time that is not a finite number of seconds, or a reason
        that is not a str.

    Examples
    --------
    >>> from dumbbell.model.trajectory import Verdict
    >>> verdict = Verdict("unstable", 0.3, "energy grew 10-fold")
    >>> verdict.ok, str(verdict)
    (False, 'unstable at t = 0.3 s: energy grew 10-fold')
    >>> Verdict().ok
    True
    """

    status: str = "ok"
    t: float | None = None
    reason: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.status, str) or self.status not in VERDICTS:
            raise UsageError(f"status = {args.show(self.status)}: must be one of "
                             f"{', '.join(VERDICTS)}", param="status")
        _time(self.t, "t", optional=True)
        if type(self.reason) is not str:
            args.text(self.reason, "reason", "a str (why the run ended so)")

    @property
    def ok(self) -> bool:
        """Stable, and within the scene's ``run.inaccurate_energy`` to the end."""
        return self.status == "ok"

    @property
    def complete(self) -> bool:
        """The run reached its end with every sample kept: ``ok`` or ``inaccurate``."""
        return self.status in COMPLETE

    def __str__(self) -> str:
        if self.ok:
            return "ok"
        return f"{self.status} at t = {self.t:.6g} s: {self.reason}"


def _view(values: np.ndarray) -> np.ndarray:
    """A read-only view of the array ``values``; the caller's own array stays writeable."""
    view = values.view()
    view.flags.writeable = False
    return view


def _first_rows(cells: list[list[str]], total: int) -> str:
    """HTML table rows of ``cells`` (the first :data:`FIRST_IMPACTS` items' cell texts), then
    one saying how many more of ``total`` items there are."""
    rows = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in cells)
    if total > len(cells):
        rows += f"<tr><td colspan='{len(cells[0])}'>... and {total - len(cells)} more</td></tr>"
    return rows


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Samples of one run: ``t`` (s), state columns by name, impacts, and a verdict. Made by
    :func:`dumbbell.simulate`; ``traj["E"]`` is any CSV column. Every array is read-only and
    every column as long as ``t``; a run that failed ends at its failure, energy columns
    included.

    Parameters
    ----------
    scene : Scene
        The scene that was run.
    solver : str
        The solver's name.
    t : numpy.ndarray
        Sample times (s): step * dt, the same for every solver.
    state : mapping of str to numpy.ndarray
        The state columns by name: positions (m) and velocities (m/s) (``xA``, ``vA``, ...;
        in 2D also angles and spins).
    events : tuple of Impact, default ()
        The impacts.
    verdict : Verdict, default Verdict()
        How the run ended.
    dt : float or None, default None
        The step used (s; None for the exact solution).
    every : int, default 1
        How many steps lie between samples.
    wall_time : float, default 0.0
        The solver's run time (s).
    info : mapping, default {}
        Solver-specific notes (settings used, an estimated error, ...).
    energy : mapping of str to numpy.ndarray or None, default None
        The energy columns (J) when the solver counted them itself; None: computed from the
        state by :func:`dumbbell.model.energy.partition`.
    contacts : tuple of Contact, default ()
        The lasting contacts with the floor (resting or rolling: a contact solver's, told
        apart from impacts as docs/solvers.md says).

    Raises
    ------
    UsageError
        A field of the wrong kind, or columns not as long as ``t`` (a trajectory built by
        hand is checked).

    Examples
    --------
    The exact run's summary, then its columns:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=1.0, dt=1e-3)
    >>> traj
    <Trajectory textbook-1d: solver=exact, dt=0.001 s, t=0..1 s, 11 samples, 2 impacts, verdict: ok>
    >>> traj.columns
    ['t', 'xA', 'vA', 'xB', 'vB', 'K_cm', 'K_int', 'U_g', 'U_spring', 'E']
    >>> traj["K_cm"][:3]                        # J, every 0.1 s
    array([0.     , 0.09604, 0.38416])
    >>> traj["nope"]
    Traceback (most recent call last):
    ...
    dumbbell.errors.ColumnError: name = 'nope': no such column; columns are t, xA, vA, xB, vB, K_cm, K_int, U_g, U_spring, E
    >>> traj.table().shape                      # (samples, columns)
    (11, 10)
    >>> traj.first_impact("B").t, traj.first_impact("A")
    (0.4517539514526256, None)
    >>> traj.to_pandas().attrs["units"]["E"]
    'J'
    >>> traj.to_csv("exact.csv").name
    'exact.csv'
    """

    scene: Scene
    solver: str
    t: np.ndarray
    state: Mapping[str, np.ndarray]
    events: tuple[Impact, ...] = ()
    verdict: Verdict = field(default_factory=Verdict)
    dt: float | None = None
    every: int = 1
    wall_time: float = 0.0
    info: Mapping[str, Any] = field(default_factory=dict)
    energy: Mapping[str, np.ndarray] | None = field(default=None, repr=False)
    contacts: tuple[Contact, ...] = ()

    def __post_init__(self) -> None:
        # A Trajectory built by hand: checked, then frozen (copies and read-only views).
        put = object.__setattr__
        args.instance(self.scene, "scene", Scene, "a Scene")
        args.text(self.solver, "solver", "the solver's name (str)")
        args.instance(self.verdict, "verdict", Verdict, "a Verdict")
        if self.dt is not None:
            args.real(self.dt, "dt", "s")
        args.whole(self.every, "every", "steps")
        args.real(self.wall_time, "wall_time", "s", lo=0.0)
        t = args.samples(self.t, "t")
        put(self, "t", t)
        put(self, "state", args.columns(self.state, len(t), "state"))
        put(self, "events", tuple(args.impacts(self.events)))
        contacts = self.contacts
        if not isinstance(contacts, list | tuple) or not all(
                isinstance(c, Contact) for c in contacts):
            raise UsageError(f"contacts = {args.show(contacts)}: must be a list of Contact",
                             param="contacts")
        args.mapping(self.info, "info", "a dict")
        if self.energy is not None:
            put(self, "energy", args.columns(self.energy, len(t), "energy"))
        else:
            from .energy import _state

            _state(self.scene, self.state, len(t))  # every column the partition needs
        self._freeze()

    @classmethod
    def _made(cls, **fields: Any) -> Trajectory:
        """The Trajectory of ``fields`` that a solver has built and checked (what
        :func:`dumbbell.solvers.verdicts.conclude` makes), frozen as the constructor freezes
        one, without its checks."""
        self = object.__new__(cls)
        for f in dataclasses.fields(cls):
            if f.name in fields:
                value = fields[f.name]
            else:
                value = f.default_factory() if f.default is dataclasses.MISSING else f.default
            object.__setattr__(self, f.name, value)
        self._freeze()
        return self

    def _freeze(self) -> None:
        """The one place a Trajectory's fields are made final: copies and read-only views, so
        neither the solver nor a user can change the result afterwards; the energy columns
        from :func:`dumbbell.model.energy.partition` when the solver did not count them."""
        put = object.__setattr__
        put(self, "t", _view(np.asarray(self.t)))
        put(self, "state", {key: _view(np.asarray(col)) for key, col in self.state.items()})
        put(self, "events", tuple(self.events))
        put(self, "contacts", tuple(self.contacts))
        put(self, "info", dict(self.info))
        energy = self.energy
        if energy is None:
            from .energy import _partition

            energy = _partition(self.scene, self.t, self.state, self.events)
        put(self, "energy", {key: _view(np.asarray(col)) for key, col in energy.items()})

    @property
    def columns(self) -> list[str]:
        """The CSV columns, in order: t, the state, the energy terms the scene has, then the
        angular momentum about the centre of mass (2D)."""
        from .energy import energy_columns, momentum_columns, state_columns

        return ["t", *state_columns(self.scene), *energy_columns(self.scene),
                *momentum_columns(self.scene)]

    @cached_property
    def _momentum(self) -> np.ndarray:
        """L_cm (kg m^2/s), computed on first use (2D only)."""
        from .energy import angular_momentum_cm

        return _view(angular_momentum_cm(self.scene, self.state))

    def __getitem__(self, name: str) -> np.ndarray:
        """One column by name: ``t``, a state column, an energy term, ``L_cm`` in 2D.

        Parameters
        ----------
        name : str
            One of :attr:`columns`.

        Returns
        -------
        numpy.ndarray
            The column (read-only), as long as ``t``.

        Raises
        ------
        ColumnError
            A name that is not a column (the message lists the columns).
        """
        if not isinstance(name, str):
            from ..errors import ColumnError
            from .args import show

            raise ColumnError(f"name = {show(name)}: must be a column name (str), one of "
                              f"{', '.join(self.columns)}", param="name")
        if name == "t":
            return self.t
        if name in self.state:
            return self.state[name]
        if name == "L_cm" and self.scene.system.dimensions == 2:
            return self._momentum
        if name in self.energy:
            return self.energy[name]
        from ..errors import ColumnError

        raise ColumnError(f"name = {name!r}: no such column; columns are "
                          f"{', '.join(self.columns)}", param="name")

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        """One line: scene, solver, dt, time span, samples, impacts (and lasting contacts, if
        any), verdict."""
        dt = "-" if self.dt is None else f"{self.dt:g} s"
        span = f"{self.t[0]:g}..{self.t[-1]:g} s" if len(self.t) else "empty"
        from .._display import counted, one_line

        verdict = " ".join(str(self.verdict).split())     # one line even if a reason is not
        contacts = f", {counted(len(self.contacts), 'contact')}" if self.contacts else ""
        return one_line(f"<Trajectory {self.scene.name}: solver={self.solver}, dt={dt}, "
                        f"t={span}, {counted(len(self.t), 'sample')}, {counted(len(self.events), 'impact')}"
                        f"{contacts}, verdict: {verdict}>")

    def _repr_html_(self) -> str:
        """A small table for notebooks: the one-line summary, the energy terms (J) at the start
        and the end, the first impacts, and the verdict with its reason."""
        from html import escape

        from .energy import energy_columns

        rows = [f"<tr><th>{escape(name)} (J)</th><td>{self[name][0]:.6g}</td>"
                f"<td>{self[name][-1]:.6g}</td></tr>"
                for name in energy_columns(self.scene)] if len(self.t) else []
        impacts = _first_rows([[f"{e.t:.6g}", escape(e.body), f"{e.v_before:.4g}",
                                f"{e.v_after:.4g}"] for e in self.events[:FIRST_IMPACTS]],
                              len(self.events))
        contacts = _first_rows([[escape(c.body), f"{c.t_start:.6g}", f"{c.t_end:.6g}"]
                                for c in self.contacts[:FIRST_IMPACTS]], len(self.contacts))
        if contacts:
            contacts = ("<table><tr><th>lasting contact: body</th><th>from t (s)</th>"
                        f"<th>to t (s)</th></tr>{contacts}</table>")
        return (
            f"<div><p><code>{escape(repr(self))}</code></p>"
            f"<p><b>verdict:</b> {escape(str(self.verdict))}</p>"
            "<table><tr><th>energy</th><th>start</th><th>end</th></tr>"
            f"{''.join(rows)}</table>"
            f"<table><tr><th>impact t (s)</th><th>body</th><th>v before (m/s)</th>"
            f"<th>v after (m/s)</th></tr>{impacts}</table>{contacts}</div>")

    def to_csv(self, path: str | Path) -> Path:
        """Write the samples as ``dumbbell simulate -o FILE`` does (the :attr:`columns`,
        atomically, through :func:`dumbbell.files.atomic_output`; what
        :func:`dumbbell.io.trajectory.write_csv` writes).

        Parameters
        ----------
        path : str or pathlib.Path
            The CSV file to write (replaced whole, or left as it was on failure).

        Returns
        -------
        pathlib.Path
            The file written.
        """
        from ..files import atomic_output, writable_path

        path = writable_path(path)  # before the work: a folder, /proc, 'newdir/', ...
        # One open of our own: given a name, numpy opens the file twice, and the first,
        # empty open would end a FIFO's reader.
        with atomic_output(path) as tmp, open(tmp, "w") as fh:
            self._write_csv(fh)
        return path

    def _write_csv(self, stream: Any) -> None:
        """The samples with a header row on the open text ``stream``: one row per sample,
        the :attr:`columns`, each float with 17 significant digits (read back exactly)."""
        table = self.table()
        stream.write(",".join(self.columns) + "\n")
        # np.savetxt's text (fmt "%.17g", "," between cells), formatted a block of rows at a
        # time rather than row by row.
        row = ",".join(["%.17g"] * table.shape[1]) + "\n"
        for start in range(0, len(table), CSV_BLOCK):
            block = table[start:start + CSV_BLOCK]
            stream.write((row * len(block)) % tuple(block.ravel().tolist()))

    def to_pandas(self) -> pandas.DataFrame:
        """The CSV's columns as a pandas DataFrame with ``t`` (s) as its index and every
        column's unit in ``df.attrs["units"]``. Needs the extra: pip install 'dumbbell[pandas]'.

        Returns
        -------
        pandas.DataFrame
            One row per sample.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame
        from .energy import column_unit

        return data_frame({name: self[name] for name in self.columns}, index="t",
                          units={name: column_unit(name) for name in self.columns})

    def table(self) -> np.ndarray:
        """All CSV columns as one array.

        Returns
        -------
        numpy.ndarray
            Shape (samples, columns), the columns in the order of :attr:`columns`.
        """
        return np.column_stack([self[c] for c in self.columns])

    def first_impact(self, body: str | None = None) -> Impact | None:
        """The first impact, of one particle or of either.

        Parameters
        ----------
        body : {'A', 'B'} or None, default None
            The particle; None: either.

        Returns
        -------
        Impact or None
            The first such impact; None when there is none.

        Raises
        ------
        UsageError
            A body other than 'A', 'B' or None.
        """
        if body is not None:
            args.choice(body, "body", ("A", "B"))
        return next((e for e in self.events if body in (None, e.body)), None)
