"""The ledger's account, as users read it: :class:`Term` (one source) and :class:`Balance`
(the terms, E(0) and E(t), the check), with their text (:meth:`Balance.table`). Every number
in them is a plain Python float (``json.dumps`` takes them), every energy carries the space's
unit (:mod:`.units`: J in SI), and every text a program chose (a declared potential's name,
a constraint's class name) is printed with its control characters escaped, on one line."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._display import counted, one_line

__all__ = ["Balance", "Term"]

#: Kinds of terms that are heat (energy turned into heat, negative when energy leaves).
HEAT_KINDS = ("contact", "spring damping", "damping")
#: Every kind of term the ledgers write (the full one, and the fallback's lumped term).
KINDS = ("contact", "correction", "constraint", "spring damping", "custom spring",
         "kinematic", "damping", "force", "step error", "velocity_func", "program",
         "entered", "left", "unattributed", "rounding", "contacts and joints")
#: Longest text of a source, note or reason printed by :meth:`Balance.table`.
TEXT_CHARS = 120


def shown(text: str, limit: int = TEXT_CHARS) -> str:
    """``text`` for one line of a table: control characters escaped (a newline as
    ``\\n``), cut to ``limit`` characters with "..." where it was cut."""
    out = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii")
                  for ch in text)
    return out if len(out) <= limit else out[: limit - 3] + "..."


@dataclass(frozen=True, repr=False)
class Term:
    """One source in the ledger: ``energy`` it put into the bodies over the run (negative
    when it took energy out, in ``unit``: J in SI), its ``kind`` (see
    :mod:`dumbbell.spaces.ledger`) and a note.

    Parameters
    ----------
    source : str
        Who (a body, a spring, gravity, the program, ...).
    kind : str
        What kind of term.
    energy : float
        What it put in (negative: took out).
    note : str, default ''
        A note.
    unit : str, default 'J'
        The energy unit.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball slowed by the space's damping
    >>> space.damping = 0.5                       # each second keeps half of every velocity
    >>> ball = pymunk.Body(1.0, 1.0)
    >>> ball.velocity = (2.0, 0.0)                # m/s: 2 J
    >>> space.add(ball)
    >>> ledger = spaces.Ledger(space, units="m")
    >>> for _ in range(100):
    ...     space.step(0.01)
    >>> ledger.balance().sources()[0]             # after 1 s, 1 m/s: 1.5 of the 2 J taken out
    Term('space.damping', 'damping', -1.5 J)
    """

    source: str
    kind: str
    energy: float
    note: str = ""
    unit: str = "J"

    def __repr__(self) -> str:
        return one_line(f"Term({shown(self.source)!r}, {self.kind!r}, "
                        f"{self.energy:+.6g} {self.unit})")


@dataclass(frozen=True, repr=False)
class Balance:
    """The ledger over a run: E(0) and E(t) (with the declared fields), the terms, and the
    check, every energy in ``unit`` (J in SI). ``E + heat + work_out - work_in = E0 +
    closure`` holds exactly; ``heat`` is what contacts, spring damping and ``space.damping``
    dissipated, ``work_in`` and ``work_out`` the other terms' inputs and outputs. ``scale``
    is the largest kinetic energy and change of a potential seen, ``worst_step`` the largest
    closure of one step relative to it; ``complete`` is True when
    the closure and anything unattributed stay within ``tolerance`` of it and every source
    is accounted for (``unaccounted`` names the others, with why).

    Parameters
    ----------
    E0, E : float
        The energy at the start and now.
    terms : tuple of Term
        The sources.
    closure : float
        E(t) - E(0) - the sum of the terms.
    worst_step : float
        The largest closure of one step, relative to ``scale``.
    scale : float
        The largest kinetic energy and change of a potential seen.
    tolerance : float
        What ``complete`` allows, relative to ``scale``.
    unaccounted : tuple of (str, str)
        Sources not accounted for, with why.
    steps : int
        Steps counted.
    t : float
        The time counted.
    notes : tuple of str, default ()
        What else to know.
    unit : str, default 'J'
        The energy unit.
    time_unit : str, default 's'
        The time unit.
    rounding : float, default 0.0
        The energies' own rounding: 64 roundings of a double of the largest magnitude of E
        and its parts seen. A closure (or a term) within it is rounding, whatever the
        scale: a pile at rest moves nothing, and E's last bit is all its closure.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball on a damped spring, SI units
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(0.2, 1e-4)
    >>> ball.position = (0.0, -0.5)                # 0.2 m past the rest length, 0.3 m
    >>> damped = pymunk.DampedSpring(space.static_body, ball, (0, 0), (0, 0), 0.3, 50.0, 0.5)
    >>> space.add(ball, damped)
    >>> ledger = spaces.Ledger(space, units="m")
    >>> for _ in range(60):
    ...     space.step(1 / 600)
    >>> balance = ledger.balance()
    >>> balance.complete, balance.steps, round(balance.E0, 6)
    (True, 60, 0.02)
    >>> round(balance.by_kind()["spring damping"], 4)  # J: the damper's heat
    -0.138
    >>> [term.source for term in balance.sources("step error")]
    ['DampedSpring 0', 'gravity']
    >>> print(balance.table(top=1))
    energy ledger over 60 steps, t = 0.1 s, energies in J
      E(0) = 0.02   E(t) = -0.116817533   scale = 0.9329
      spring damping   -0.137998  (1 source)
          DampedSpring 0 damping                   -0.137998
      step error       +0.0011808  (2 sources)
          ...
      complete: True
    """

    E0: float
    E: float
    terms: tuple[Term, ...]
    closure: float
    worst_step: float
    scale: float
    tolerance: float
    unaccounted: tuple[tuple[str, str], ...]
    steps: int
    t: float
    notes: tuple[str, ...] = ()
    unit: str = "J"
    time_unit: str = "s"
    rounding: float = 0.0

    def __post_init__(self) -> None:
        # Plain numbers only (numpy scalars neither print nor serialise as numbers).
        from ..model import args

        for name in ("E0", "E", "closure", "worst_step", "scale", "tolerance", "t",
                     "rounding"):
            unit = self.time_unit if name == "t" else "-" if name in (
                "worst_step", "tolerance") else self.unit
            value = args.real(getattr(self, name), name, unit, positive=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "steps", args.whole(self.steps, "steps", "steps", lo=0))

    @property
    def heat(self) -> float:
        """Energy dissipated: minus the heat-kind terms."""
        return -math.fsum(t.energy for t in self.terms if t.kind in HEAT_KINDS)

    @property
    def work_in(self) -> float:
        """Energy the other terms put in."""
        return math.fsum(t.energy for t in self.terms
                         if t.kind not in HEAT_KINDS and t.energy > 0)

    @property
    def work_out(self) -> float:
        """Energy the other terms took out (positive)."""
        return -math.fsum(t.energy for t in self.terms
                          if t.kind not in HEAT_KINDS and t.energy < 0)

    @property
    def relative_closure(self) -> float:
        """|closure| / scale (0 when nothing moved)."""
        return abs(self.closure) / self.scale if self.scale > 0 else 0.0

    @property
    def complete(self) -> bool:
        """True when every joule is accounted for: nothing in ``unaccounted`` and the
        closure within ``tolerance`` of ``scale`` (or within the energies' ``rounding``)."""
        return bool(not self.unaccounted
                    and abs(self.closure) <= max(self.tolerance * self.scale, self.rounding))

    def by_kind(self) -> dict[str, float]:
        """Energy per kind of term.

        Returns
        -------
        dict of str to float
            Kind -> its terms' energy, summed.
        """
        out: dict[str, float] = {}
        for t in self.terms:
            out[t.kind] = out.get(t.kind, 0.0) + t.energy
        return out

    def sources(self, kind: str | None = None, at_least: float = 0.0) -> list[Term]:
        """Terms (of ``kind``, all when None) with |energy| >= ``at_least``, largest
        first.

        Parameters
        ----------
        kind : str or None, default None
            Only terms of this kind.
        at_least : float, default 0.0
            Only terms with at least this much energy.

        Returns
        -------
        list of Term
            Largest first.

        Raises
        ------
        UsageError
            A ``kind`` the ledger never writes (one line naming it and the kinds there
            are), or ``at_least`` negative or not a number.
        """
        from ..model import args

        at_least = args.real(at_least, "at_least", self.unit, lo=0.0)
        if kind is not None and (not isinstance(kind, str) or kind not in KINDS):
            from ..errors import UsageError

            raise UsageError(f"kind = {args.show(kind)}: must be None (every kind) or one of "
                             f"{', '.join(map(repr, KINDS))}", param="kind")
        chosen = [t for t in self.terms if (kind is None or t.kind == kind)
                  and abs(t.energy) >= at_least]
        return sorted(chosen, key=lambda t: -abs(t.energy))

    def __repr__(self) -> str:
        u = self.unit
        return one_line(
            f"Balance({counted(self.steps, 'step')}, t = {self.t:.6g} {self.time_unit}, E0 = "
            f"{self.E0:.9g} {u}, "
            f"E = {self.E:.9g} {u}, closure = {self.closure:+.3g} {u}, complete = "
            f"{self.complete}; {len(self.terms)} terms: .table())")

    def table(self, top: int = 4) -> str:
        """The ledger as text: totals per kind with the ``top`` largest sources of each,
        then the check, and what is unaccounted for (sources with the same reason on one
        line, ``top`` of them named).

        Parameters
        ----------
        top : int, default 4
            Sources shown per kind.

        Returns
        -------
        str
            The text.
        """
        from ..model import args

        top = args.whole(top, "top", "sources", lo=0)
        u = self.unit
        lines = [(f"energy ledger over {counted(self.steps, 'step')}, t = {self.t:.6g} {self.time_unit}, "
                 f"energies in {u}"),
                 f"  E(0) = {self.E0:.9g}   E(t) = {self.E:.9g}   scale = {self.scale:.4g}"]
        for kind, total in sorted(self.by_kind().items(), key=lambda kv: -abs(kv[1])):
            terms = self.sources(kind)
            lines.append(f"  {shown(kind):16s} {total:+.6g}  ({len(terms)} source"
                         f"{'' if len(terms) == 1 else 's'})")
            for t in terms[:top]:
                lines.append(f"      {shown(t.source):40s} {t.energy:+.6g}")
        rounding = ("; within the energies' rounding, "
                    f"{self.rounding:.2g} {u}" if self.tolerance * self.scale
                    < abs(self.closure) <= self.rounding else "")
        lines.append(f"  closure E(t) - E(0) - sum = {self.closure:+.3g} "
                     f"({self.relative_closure:.2e} of the scale; worst step "
                     f"{self.worst_step:.2e}{rounding})")
        for note in self.notes:
            lines.append(f"  note: {shown(note, 400)}")
        # Sources with the same reason on one line (a threaded solver names every body).
        grouped: dict[str, list[str]] = {}
        for source, why in self.unaccounted:
            grouped.setdefault(why, []).append(shown(source))
        most = max(top, 1)
        for why, sources in grouped.items():
            named = ", ".join(sources[:most])
            if len(sources) > most:
                named += f" and {len(sources) - most} more"
            lines.append(f"  unaccounted: {named}: {shown(why, 400)}")
        lines.append(f"  complete: {self.complete}")
        return "\n".join(lines)


def notes(terms: list[Term], scale: float, unit: str) -> tuple[str, ...]:
    """What deserves a word beyond the terms: shapes pushed apart (they overlapped) putting
    energy in, with the pairs that did most."""
    pushed = [t for t in terms if t.kind == "correction"]
    total = sum(abs(t.energy) for t in pushed)
    if scale <= 0 or total <= 0.01 * scale:
        return ()
    pairs = sorted((t for t in pushed if t.source.startswith("pushed apart")),
                   key=lambda t: -abs(t.energy))[:3]
    which = ", ".join(t.source.removeprefix("pushed apart ") for t in pairs)
    return (f"overlapping shapes pushed apart by the contacts' position correction moved "
            f"{total:.3g} {unit} ({total / scale:.2g} of the scale)"
            + (f", most between {which}" if which else "")
            + " (shapes that start overlapping, or that a joint holds in another)",)


def order(t: Term) -> tuple[str, float]:
    return (t.kind, -abs(t.energy))
