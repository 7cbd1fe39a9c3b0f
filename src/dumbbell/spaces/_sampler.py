"""The energy terms of one space sampled many times cheaply, for the recorder's energy panel
(:class:`_Sampler`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._pymunk import spring_function
from ._evaluation import State, evaluate, read_state
from ._refusals import refuse_bad_state
from ._what_counts import Inventory, inventory


class _Sampler:
    """The energy terms of one space, sampled many times cheaply (the recorder's energy
    panel, one sample per frame). :meth:`sample` reads every tracked body's state at once and
    keeps it; the :func:`inventory` is taken again only when something it holds changes:
    the space's bodies or constraints, a body's type, mass, moment or centre of gravity,
    gravity, a spring's anchors, rest length or angle, stiffness or force function (read in
    bulk from pymunk's structs; on a pymunk build whose structs cannot be read, every sample
    takes the inventory again). :meth:`terms` evaluates all samples at once with
    :func:`evaluate`: at each sample the numbers :func:`~dumbbell.spaces.accounting.energy`
    gives. A sample whose state is not finite is refused as
    :func:`~dumbbell.spaces.accounting.energy` refuses it."""

    #: Body fields read per sample: the fingerprint (type, mass, moment, centre of gravity),
    #: then the state (as :func:`read_state`).
    _PRINT = ("m", "i", "idle_time", "cog.x", "cog.y")
    _STATE = ("p.x", "p.y", "v.x", "v.y", "a", "w")
    _SPRING = (("spring", ("anchor_a.x", "anchor_a.y", "anchor_b.x", "anchor_b.y", "rest",
                           "stiffness")),
               ("rotary_spring", ("rest", "stiffness")))

    def __init__(self, space: Any) -> None:
        from . import _layout as layout

        self.space = space
        self.fast = layout.readable()
        self.inventories: list[Inventory] = []
        self.samples: list[tuple[int, np.ndarray]] = []
        self._bodies: list[Any] | None = None
        self._constraints: list[Any] = []
        self._print: np.ndarray | None = None

    def _same_objects(self) -> bool:
        import operator

        bodies, constraints = self.space.bodies, self.space.constraints
        return (self._bodies is not None and len(bodies) == len(self._bodies)
                and len(constraints) == len(self._constraints)
                and all(map(operator.is_, bodies, self._bodies))
                and all(map(operator.is_, constraints, self._constraints))
                and tuple(self.space.gravity) == self._gravity)

    def _take_stock(self) -> None:
        """The inventory now, and where to read what it rests on."""
        import pymunk

        from . import _memory as mem

        space = self.space
        inv = inventory(space)
        self.inventories.append(inv)
        self._bodies, self._constraints = list(space.bodies), list(space.constraints)
        self._gravity = tuple(space.gravity)
        if not self.fast:
            return
        place = {id(b): i for i, b in enumerate(self._bodies)}
        extra = [b for b in inv.bodies if id(b) not in place]
        self._at = mem.addresses([*self._bodies, *extra], "_body")
        self._span = mem.Span.over(self._at, mem.size("body"))
        self._fields = np.array([mem.offset("body", *f.split("."))
                                 for f in (*self._PRINT, *self._STATE)], dtype=np.uint64)[:, None]
        rows = {id(b): i for i, b in enumerate([*self._bodies, *extra])}
        self._rows = np.array([rows[id(b)] for b in inv.bodies], dtype=np.intp)
        springs = [c for c in self._constraints
                   if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
        self._funcs = [spring_function(c) for c in springs]
        self._springs = []
        for kind, fields in self._SPRING:
            objs = [c for c in springs if mem.struct_of(c) == kind]
            if objs:
                at = mem.addresses(objs, "_constraint")
                self._springs.append((mem.Span.over(at, mem.size(kind)), at, np.array(
                    [mem.offset(kind, *f.split(".")) for f in fields],
                    dtype=np.uint64)[:, None]))
        self._print = None
        self._print = self._fingerprint(self._read())

    def _read(self) -> np.ndarray:
        if self._span is None:  # no bodies
            return np.zeros((len(self._fields), 0))
        return self._span.f(self._at, self._fields)

    def _fingerprint(self, values: np.ndarray) -> np.ndarray:
        import pymunk

        n = len(self._PRINT)
        parts = [values[:n].ravel(), np.isinf(values[2])]
        parts += [span.f(at, fields).ravel() for span, at, fields in self._springs]
        funcs = [spring_function(c) for c in self._constraints
                 if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
        same = len(funcs) == len(self._funcs) and all(
            f is g for f, g in zip(funcs, self._funcs, strict=True))
        values = np.concatenate(parts)
        values[2 * len(self._at):3 * len(self._at)] = 0.0  # idle time: only whether inf
        return values if same else np.full(len(values), math.nan)

    def sample(self) -> None:
        """Keep the state of the space now."""
        if not self.fast:
            self._take_stock()
            inv = self.inventories[-1]
            st = read_state(inv)
            state = np.stack([st.x[0], st.y[0], st.vx[0], st.vy[0], st.angle[0], st.omega[0]])
        else:
            if not self._same_objects():
                self._take_stock()
            values = self._read()
            if not np.array_equal(self._fingerprint(values), self._print):
                self._take_stock()
                values = self._read()
            state = values[len(self._PRINT):, self._rows]
        inv = self.inventories[-1]
        n = inv.dynamic
        if not (np.isfinite(state[:, :n]).all() and np.isfinite(inv.mass[:n]).all()
                and (inv.mass[:n] > 0).all() and (inv.moment[:n] > 0).all()):
            refuse_bad_state(list(inv.labels[:n]), State(*state[:, None, :]), inv.mass,
                             inv.moment)
        self.samples.append((len(self.inventories) - 1, state))

    def drop(self) -> None:
        """Forget the last sample."""
        self.samples.pop()

    def terms(self, about: tuple[float, float] = (0.0, 0.0)) -> dict[str, np.ndarray]:
        """K_trans, K_rot, U_g, U_spring and E (and the other sums :func:`evaluate` gives)
        at every sample, in order (arrays of one value per sample)."""
        names = ("K_trans", "K_rot", "K_cm", "K_int", "U_g", "U_spring", "E")
        out = {k: np.zeros(len(self.samples)) for k in names}
        which = np.array([i for i, _ in self.samples], dtype=int)
        for i in sorted({i for i, _ in self.samples}):  # (np.unique would import numpy.ma)
            rows = np.flatnonzero(which == i)
            stacked = np.stack([self.samples[r][1] for r in rows.tolist()])
            st = State(*(np.ascontiguousarray(stacked[:, j]) for j in range(6)))
            terms = evaluate(self.inventories[i], st, about)
            for k in names:
                out[k][rows] = terms[k]
        return out
