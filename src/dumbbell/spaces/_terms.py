"""The ledger's running sums, and how they become named terms: per dynamic body (forces,
custom velocity functions, what nothing explains, the program's changes), per row (what
driven bodies did through contacts), per declared field, per constraint (in its
:class:`._constraints.Group`) and per pair of bodies (in :class:`._inventory.Pairs`); and
the named terms they are folded into, (source, kind) -> energy."""

from __future__ import annotations

import numpy as np

from ._constraints import Group
from ._inventory import PAIR, Build, Pairs

_INSIDE = "changed inside the step by something no source explains (a callback)"
#: Below this fraction of the energy scale, a body's unexplained impulse work is rounding.
ROUNDING = 1e-12
#: The energies' own rounding, as a fraction of the largest magnitude of E and its parts seen
#: (64 roundings of a double): below it nothing is measurable, whatever the scale (a stack
#: at rest has a scale of 1e-11 and an E of 45,000, whose last bit is 7e-12).
ROUNDED = 64 * float(np.finfo(float).eps)


class Sums:
    """Running sums for one build: ``force``, ``vf``, ``unattributed``, ``program`` per
    dynamic row, ``kin`` per row, ``field`` per declared field; and the named terms
    (``terms``, with ``notes``), which outlive builds."""

    def __init__(self) -> None:
        self.terms: dict[tuple[str, str], float] = {}
        self.notes: dict[tuple[str, str], str] = {}
        self.reset(0, 0, 0)

    def reset(self, n: int, rows: int, fields: int) -> None:
        """Fresh per-row sums for a build of ``n`` dynamic rows of ``rows``."""
        self.force, self.vf, self.unattributed, self.program = (np.zeros(n) for _ in range(4))
        self.kin = np.zeros(rows)
        self.field = np.zeros(fields)

    def add(self, source: str, kind: str, value: float, note: str = "") -> None:
        key = (source, kind)
        self.terms[key] = self.terms.get(key, 0.0) + float(value)
        if note:
            self.notes[key] = note

    def fold(self, b: Build, scale: float, floor: float = 0.0) -> None:
        """Move the running sums of build ``b`` into the named terms (and zero them);
        ``floor``: the energies' own rounding (:data:`ROUNDED`)."""
        labels, n = b.table.labels, b.table.n
        self._fold_bodies(labels, scale, floor)
        for j, f in enumerate(b.fields):
            if self.field[j]:
                self.add(f.label, "step error", self.field[j],
                         "declared field: its kicks and its potential's change over the moves")
        self.field[:] = 0.0
        for r in np.nonzero(self.kin)[0]:
            src = (f"{labels[r]} through contacts" if r >= n else
                   f"fixed spin of {labels[r]} through contacts")
            self.add(src, "kinematic", self.kin[r],
                     "work of a body whose motion the program imposes")
        self.kin[:] = 0.0
        for g in b.groups.values():
            self._fold_group(g, labels, n)

    def _fold_bodies(self, labels: list[str], scale: float, floor: float = 0.0) -> None:
        """The per-body sums: forces, unexplained impulses (rounding apart), the program's
        changes and custom velocity functions."""
        kinds = {"force": ("force on {}", "force", "work of Body.force"),
                 "unattributed": ("{}", "unattributed", _INSIDE),
                 "program": ("program: {}", "program", "changed between steps by the program")}
        for name, (fmt, kind, note) in kinds.items():
            acc = getattr(self, name)
            if name == "unattributed":
                # What the solver's sums round off (1e-16 of the impulses) is one term;
                # a body whose residual is more than that is named.
                tiny = np.abs(acc) <= max(ROUNDING * max(scale, 1e-300), floor)
                if tiny.any():
                    self.add("rounding", "rounding", float(acc[tiny].sum()),
                             "what the solver's and the ledger's sums round off")
                    acc[tiny] = 0.0
            for i in np.nonzero(acc)[0]:
                self.add(fmt.format(labels[i]), kind, acc[i], note)
            acc[:] = 0.0
        for i in np.nonzero(self.vf)[0]:
            self.add(f"velocity_func of {labels[i]}", "velocity_func", self.vf[i],
                     "kicks of a custom velocity_func and the moves they cause (no declared "
                     "potential)")
        self.vf[:] = 0.0

    def _fold_group(self, g: Group, labels: list[str], n: int) -> None:
        """The sums of the constraints of ``g``: each one's work (a spring's step error and
        damping), and what driven ends did through it."""
        for i, lab in enumerate(g.labels):
            if g.spring and g.default[i]:
                self.add(lab, "step error", g.work[i] + g.pot[i],
                         "spring: its kicks and its potential's change over the moves")
                self.add(f"{lab} damping", "spring damping", g.extra[i])
            elif g.spring:
                self.add(lab, "custom spring", g.work[i] + g.extra[i],
                         "work of a spring with a custom force function")
            else:
                self.add(lab, "constraint", g.work[i], joint_note(g.objs[i]))
            for row, acc in ((g.a[i], g.kin_a), (g.b[i], g.kin_b)):
                if acc[i]:
                    who = labels[row]
                    src = (f"{who} through {lab}" if row >= n else
                           f"fixed spin of {who} through {lab}")
                    self.add(src, "kinematic", acc[i],
                             "work of a body whose motion the program imposes")
        for arr in (g.work, g.extra, g.pot, g.kin_a, g.kin_b):
            arr[:] = 0.0


def pair_terms(pairs: Pairs, labels: list[str]) -> list[tuple[str, str, float, str]]:
    """The contact work and gravity's part of the position correction of each pair that
    touched, as (source, kind, energy, note)."""
    out = []
    for key, w, p in zip(pairs.keys.tolist(), pairs.work.tolist(), pairs.push.tolist(),
                         strict=True):
        a, b = divmod(key, PAIR)
        name = f"{labels[a]} / {labels[b]}"
        if w != 0.0:
            out.append((f"contact {name}", "contact", w,
                        "work of the contact impulses (heat when negative)"))
        if p != 0.0:
            out.append((f"pushed apart {name}", "correction", p,
                        "gravity's part of the contacts' position correction"))
    return out


def joint_note(c: object) -> str:
    import math

    parts = [type(c).__name__]
    for name in ("max_force", "max_bias"):
        value = getattr(c, name)
        if math.isfinite(value):
            parts.append(f"{name} {value:g}")
    return ", ".join(parts)
