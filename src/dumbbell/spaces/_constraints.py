"""The constraints of a space as the ledger reads them, by struct kind (:class:`Group`):
the fields read of each struct before and after the solver, the rows of each constraint's
two bodies in the ledger's table (:class:`._inventory.Table`), whether a spring has pymunk's
own force, and the running sums of their work. :func:`groups` makes them for a build
(:func:`._inventory.build`), naming the constraints the ledger cannot read or whose energy is
not in E."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .._pymunk import spring_function
from . import _layout as layout
from . import _memory as mem

__all__: list[str] = []

#: Per constraint struct: fields read before the solver (the impulse carried in; a spring's
#: settings), and after it (the impulse, its geometry).
BEFORE = {"pin": ("j",), "slide": ("j",), "pivot": ("j.x", "j.y"), "groove": ("j.x", "j.y"),
          "spring": ("rest", "stiffness", "damping", "c.max_force"),
          "rotary_spring": ("rest", "stiffness", "damping", "c.max_force"),
          "rotary_limit": ("j",), "ratchet": ("j",), "gear": ("j",), "motor": ("j",)}
AFTER = {"pin": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
         "slide": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
         "pivot": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
         "groove": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
         "spring": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
         "rotary_spring": ("j",), "rotary_limit": ("j", "bias"), "ratchet": ("j", "bias"),
         "gear": ("j", "ratio_inv"), "motor": ("j",)}


class Members(NamedTuple):
    """The constraints of one struct kind as the build lists them: the objects, their
    labels, the table rows of their two bodies, and whether each (a spring) has pymunk's
    own force."""

    objs: list[Any]
    labels: list[str]
    a: list[int]
    b: list[int]
    default: list[bool]


class Group:
    """The constraints of one struct kind: rows of their two bodies in the table, readers,
    and running sums (energy units) per constraint: ``work`` (work of its impulses on the
    relative motion; for a spring, its elastic part), ``extra`` (a spring's damping part),
    ``pot`` (a spring's potential change over the steps' moves), ``kin_a``/``kin_b`` (work
    of a driven end through it)."""

    def __init__(self, kind: str, members: Members) -> None:
        objs = members.objs
        self.kind = kind
        self.objs = objs
        self.labels = members.labels
        self.at = mem.addresses(objs, "_constraint")
        self.a = np.array(members.a, dtype=np.int64)
        self.b = np.array(members.b, dtype=np.int64)
        self.default = np.array(members.default, dtype=bool)
        self.spring = kind in ("spring", "rotary_spring")
        self.slot = -1  # place among the space's spring groups
        func = {"spring": ("force_func",), "rotary_spring": ("torque_func",)}.get(kind, ())
        self.before = mem.Reader(kind, self.at, BEFORE[kind], func)
        self.after = mem.Reader(kind, self.at, AFTER[kind])
        z = np.zeros(len(objs))
        self.work, self.extra, self.pot, self.kin_a, self.kin_b = (z.copy() for _ in range(5))
        self.settings = self.before.floats().copy() if self.spring else None
        self.funcs = self.before.pointers().copy() if self.spring else None
        # The same bytes are the same settings (unless one is NaN, never equal to itself).
        self._same = None if not self.spring or np.isnan(self.settings).any() else (
            self.settings.tobytes(), self.funcs.tobytes())
        if kind == "spring":
            self.anchor = np.array(
                [[c.anchor_a[0] - c.a.center_of_gravity[0],
                  c.anchor_a[1] - c.a.center_of_gravity[1],
                  c.anchor_b[0] - c.b.center_of_gravity[0],
                  c.anchor_b[1] - c.b.center_of_gravity[1]] for c in objs],
                dtype=float).reshape(len(objs), 4)

    def changed(self) -> bool:
        """A spring's settings or force function changed since the build."""
        if not self.spring:
            return False
        settings, funcs = self.before.both()
        if self._same is not None and (settings.tobytes(), funcs.tobytes()) == self._same:
            return False
        return not (np.array_equal(settings, self.settings)
                    and np.array_equal(funcs, self.funcs))


def groups(t: Any, current: dict[str, str]) -> tuple[dict[str, Group], list[Group]]:
    """The constraints by struct kind, the springs among them; the constraints the ledger
    cannot read or whose energy is not in E are named in ``current``."""
    rows = {int(a): r for r, a in enumerate(t.at.tolist())}
    spring_default, rotary_default = layout.default_spring_funcs()
    by_kind: dict[str, tuple[list[Any], ...]] = {}
    for i, c in enumerate(t.constraint_key):
        name = type(c).__name__
        kind = mem.struct_of(c)
        clabel = f"{name} {i}"
        if kind is None:
            current[clabel] = f"{name}: a constraint class the ledger cannot read"
            continue
        layout.check_constraint(c)
        default = True
        if kind in ("spring", "rotary_spring"):
            r = mem.view(kind, mem.address(c._constraint))
            func = mem.address(r.force_func if kind == "spring" else r.torque_func)
            # pymunk's own Python spring function, set explicitly, runs through a callback
            # (another address) but is the default force: told apart as _pymunk does.
            default = (func in (spring_default if kind == "spring" else rotary_default)
                       or spring_function(c) is None)
            if not default:
                current[clabel] = ("custom force function: its potential is not in E (its "
                                   "work is counted)")
        entry = by_kind.setdefault(kind, ([], [], [], [], []))
        for lst, value in zip(entry, (c, clabel, rows[mem.address(c.a._body)],
                                      rows[mem.address(c.b._body)], default), strict=True):
            lst.append(value)
    groups = {kind: Group(kind, Members(*entry)) for kind, entry in by_kind.items()}
    springs = [g for g in groups.values() if g.spring]
    for slot, g in enumerate(springs):
        g.slot = slot
    return groups, springs
