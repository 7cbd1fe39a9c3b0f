"""The step-size guard on pymunk's own example programs: its reach estimates against the real
peak speeds, and what its advice changes when applied.

For each case (:data:`CASES`: the constraints demo one kind at a time and whole, and eleven
other programs), run headless by :mod:`pymunk_corpus`:

- **peaks**: the program runs :data:`STEPS` of its own steps. Before the first, and again
  whenever a body is added or removed or a kinematic body changes speed (the space the guard
  would be asked about is then another), ``spaces.reach`` estimates every dynamic body. After
  each step each body's real speed is read: of its centre of gravity, or for a body the
  estimate calls ``point`` (turning about a fixed pivot) its speed plus spin times its reach.
  A free body that has fallen past its estimate's ``level`` (below everything it could meet)
  is no longer counted. ``estimated`` is the largest first estimate, ``real`` the largest
  speed read, and each estimate that claims to be a ``bound`` is checked against the speeds
  read while it stood.
- **advice**: the guard's ``substeps`` and failing checks at the program's step, before the
  first step. What the advice names is then measured at the program's step and with the
  advice applied (sub-steps, or the setting it gives), over :data:`ADVICE_STEPS` steps:

  - ``spring`` kinds: the energy error, ``max |E(t) - E_ref(t)|`` over the steps divided by
    the largest kinetic-plus-spring energy of the reference run, E from ``spaces.energy`` and
    the reference run at a quarter of the advised step;
  - ``tunnelling``: the deepest overlap of a contact in the step that makes it (pymunk's
    ``is_first_contact``), as a fraction of the guard's smallest tunnelling limit in the
    space (pass-through begins near 1);
  - ``bias``: the largest energy gain over the start, ``max (E(t) - E(0)) / E_scale``, with
    ``space.collision_bias = 1`` (the fix) against the program's;
  - ``joint``: the largest drift per second of a failing joint, ``spaces.Ledger``'s term of
    that joint over the run divided by its time and by the ledger's energy scale (the
    guard's tolerance is 0.01 a second);
  - a program the guard calls fine: that overlap at its own step (it must stay under 1).

``python tests/guard_corpus.py`` prints the table (Markdown) that docs/spaces-reference.md holds.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

try:
    from .pymunk_corpus import CONSTRAINT_KINDS, keep_only, run_example
except ImportError:  # run as a script: python tests/guard_corpus.py
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from pymunk_corpus import CONSTRAINT_KINDS, keep_only, run_example

#: Case -> (example, isolate): the constraints demo one kind at a time, whole, and the rest.
CASES: dict[str, tuple[str, Any]] = {
    **{f"constraints/{k}": ("constraints", k) for k in CONSTRAINT_KINDS},
    "constraints": ("constraints", None),
    **{n: (n, None) for n in ("newtons_cradle", "planet", "box2d_pyramid",
                              "box2d_vertical_stack", "slide_and_pinjoint",
                              "damped_rotary_spring_pointer", "spiderweb", "tank", "flipper",
                              "contact_with_friction", "bouncing_balls")},
}
#: Steps of the program for the peaks (its own dt): long enough for the first impacts and
#: the pyramid's settling; longer where the peak comes late (balls rolling off the L, the
#: tank's pushing).
STEPS = 300
LONGER = {"slide_and_pinjoint": 600}
#: Steps for measuring what the advice changes, and most steps of one reference run.
ADVICE_STEPS = 120
REFERENCE_STEPS = 8_000
#: Units of the corpus: every program works in pixels.
UNITS = "px"
#: Spring kinds of findings.
SPRINGS = ("spring", "rotary-spring", "spring-network")


def _isolate(kind: str | None) -> Any:
    return None if kind is None else keep_only(kind)


def _dynamic(space: Any) -> list[Any]:
    import pymunk

    return [b for b in space.bodies if b.body_type == pymunk.Body.DYNAMIC]


def _reach_of_shapes(body: Any) -> float:
    """The farthest point of a body's shapes from its centre of gravity."""
    r = 0.0
    cg = body.center_of_gravity
    for s in body.shapes:
        kind = type(s).__name__
        if kind == "Circle":
            r = max(r, (s.offset - cg).length + s.radius)
        elif kind == "Segment":
            r = max(r, (s.a - cg).length + s.radius, (s.b - cg).length + s.radius)
        else:
            r = max(r, max((v - cg).length for v in s.get_vertices()) + s.radius)
    return r


@dataclass
class Peaks:
    """What :func:`peaks` measured: per body (by the order it appeared) its first estimate,
    the largest of its estimates and its real peak; the bound claims checked (one per body
    and step) and those that failed (case text); how many times the space was estimated."""

    case: str
    dt: float
    first: dict[int, Any] = field(default_factory=dict)
    largest: dict[int, float] = field(default_factory=dict)
    real: dict[int, float] = field(default_factory=dict)
    broken: list[str] = field(default_factory=list)
    estimates: int = 0
    claims: int = 0

    @property
    def estimated(self) -> float:
        return max((r.speed for r in self.first.values()), default=0.0)

    @property
    def peak(self) -> float:
        return max(self.real.values(), default=0.0)

    def worst(self) -> tuple[float, str]:
        """The largest real / estimate over the bodies, and its body."""
        out = (0.0, "")
        for k, r in self.first.items():
            est = self.largest[k]
            ratio = self.real.get(k, 0.0) / est if est > 0 else (math.inf if self.real.get(k)
                                                                   else 0.0)
            out = max(out, (ratio, r.subject))
        return out


def peaks(case: str, steps: int | None = None) -> Peaks:
    """Run ``case`` and compare each body's reach estimates with its real speeds."""
    import pymunk

    from dumbbell import spaces

    steps = steps or LONGER.get(case, STEPS)
    name, kind = CASES[case]
    out = Peaks(case, 0.0)
    current: dict[int, Any] = {}
    reach_r: dict[int, float] = {}
    signature: list[Any] = [None]

    def estimate(space: Any, dt: float) -> None:
        kin = tuple((id(b), tuple(b.velocity), b.angular_velocity) for b in space.bodies
                    if b.body_type == pymunk.Body.KINEMATIC)
        sig = (tuple(id(b) for b in space.bodies), kin)
        if sig == signature[0]:
            return
        signature[0] = sig
        out.estimates += 1
        for b, r in zip(_dynamic(space), spaces.reach(space, dt, units=UNITS), strict=True):
            current[id(b)] = (b, r)
            out.first.setdefault(id(b), r)
            out.largest[id(b)] = max(out.largest.get(id(b), 0.0), r.speed)
            reach_r.setdefault(id(b), _reach_of_shapes(b))

    def first(space: Any, dt: float) -> None:
        out.dt = dt
        estimate(space, dt)

    def step(space: Any, dt: float) -> None:
        alive = {id(b) for b in space.bodies}
        for key in [k for k in current if k not in alive]:
            del current[key]
        for key, (b, r) in current.items():
            v = b.velocity.length
            if r.point:
                v += abs(b.angular_velocity) * reach_r[key]
            elif r.level is not None and not r.held:
                g = space.gravity
                down = g / g.length
                depth = b.local_to_world(b.center_of_gravity).dot(down)
                if depth > r.level + b.velocity.length * dt:
                    continue               # fallen past everything it could meet
            out.real[key] = max(out.real.get(key, 0.0), v)
            if r.bound:
                out.claims += 1
                if v > r.speed * (1 + 1e-9):
                    out.broken.append(f"{case}: {r.subject}: {v:.6g} > bound {r.speed:.6g}")
        estimate(space, dt)

    run_example(name, steps, isolate=_isolate(kind), on_first=first, on_step=step)
    return out


# --- what the advice changes -----------------------------------------------------------------


def first_overlap(space: Any, sizes: dict[int, float]) -> float:
    """The deepest overlap of the contacts the last step found for the first time (pymunk's
    ``is_first_contact``), each as a fraction of its pass-through limit: half the thinnest
    shape of one body plus half that of the other (``sizes``: body id -> its thinnest shape);
    0 if none. How far shapes move into each other in the step that brings them together:
    pass-through is the extreme of it."""
    import pymunk.batch as pb

    fields = (pb.ArbiterFields.BODY_A_ID | pb.ArbiterFields.BODY_B_ID
              | pb.ArbiterFields.IS_FIRST_CONTACT | pb.ArbiterFields.CONTACT_COUNT
              | pb.ArbiterFields.DISTANCE_1 | pb.ArbiterFields.DISTANCE_2)
    buf = pb.Buffer()
    pb.get_space_arbiters(space, fields, buf)
    rows = np.frombuffer(buf.float_buf(), dtype=float).reshape(-1, 2)
    ints = np.frombuffer(buf.int_buf(), dtype=np.uintp).reshape(-1, 4)
    worst = 0.0
    for (a, b, new, count), (d1, d2) in zip(ints, rows, strict=True):
        if new:
            depth = -min(d1, d2 if count >= 2 else 0.0)
            limit = 0.5 * (sizes.get(int(a), 0.0) + sizes.get(int(b), 0.0))
            if depth > 0 and limit > 0:
                worst = max(worst, depth / limit)
    return worst


def _sizes(space: Any) -> dict[int, float]:
    """Body id -> the thinnest of its solid shapes (``spaces.shape_size``)."""
    from dumbbell import spaces

    out: dict[int, float] = {}
    for s in space.shapes:
        if not s.sensor:
            out[s.body.id] = min(out.get(s.body.id, math.inf), spaces.shape_size(s))
    return out


def _series(case: str, steps: int, substeps: int = 1, setting: dict | None = None,
            what: str = "energy") -> tuple[list[float], list[float]]:
    """Run ``case`` ``steps`` program steps of ``substeps`` each with ``setting`` applied to
    the space. After each program step, ``what`` = 'energy': E (``spaces.energy``);
    'balance': E + heat - E(0) (``spaces.HeatCounter``); after each of its sub-steps but the
    very first, 'overlap': :func:`first_overlap`. Returns the series, and the energy scale
    K + |U_spring| after each program step ('energy', 'balance')."""
    from dumbbell import spaces

    name, kind = CASES[case]
    series: list[float] = []
    scale: list[float] = []
    heat: dict[str, Any] = {}

    def read(space: Any) -> None:
        if what == "overlap":
            return
        e = spaces.energy(space)
        scale.append(e.K_trans + e.K_rot + abs(e.U_spring))
        if what == "balance":
            series.append(e.E + heat["counter"].total - heat["E0"])
        else:
            series.append(e.E)

    def first(space: Any, dt: float) -> None:
        for key, value in (setting or {}).items():
            setattr(space, key, value)
        if what == "balance":
            heat["counter"] = spaces.HeatCounter(space)
            heat["E0"] = spaces.energy(space).E

    def each(space: Any, h: float) -> None:
        # Not the first step: its contacts are how the program placed its shapes.
        if what == "overlap" and heat.setdefault("stepped", False):
            if heat.get("shapes") != len(space.shapes):
                heat["shapes"], heat["sizes"] = len(space.shapes), _sizes(space)
            series.append(first_overlap(space, heat["sizes"]))
        heat["stepped"] = True

    run_example(name, steps, isolate=_isolate(kind), on_first=first,
                on_step=lambda space, dt: read(space), substeps=substeps, on_substep=each)
    return series, scale


def _joint_drift(case: str, steps: int, substeps: int, subjects: set[str]) -> float:
    """The largest drift per second of the joints ``subjects`` over ``steps`` program steps
    of ``substeps`` each: ``spaces.Ledger``'s term of each over the run, divided by the time
    and by the ledger's scale."""
    from dumbbell import spaces

    name, kind = CASES[case]
    held: dict[str, Any] = {}

    def first(space: Any, dt: float) -> None:
        held["ledger"], held["dt"] = spaces.Ledger(space), dt

    run_example(name, steps, isolate=_isolate(kind), on_first=first, substeps=substeps)
    balance = held["ledger"].balance()
    held["ledger"].detach()
    seconds = steps * held["dt"]
    worst = max((abs(t.energy) for t in balance.terms
                 if t.kind == "constraint" and t.source in subjects), default=0.0)
    return worst / seconds / balance.scale if balance.scale > 0 else 0.0


@dataclass
class Advice:
    """The guard's advice on a case at the program's step (``substeps``, the kinds that fail,
    the settings it gives) and what applying it changed: ``measure`` names the quantity,
    ``before`` its value for the program as written, ``after`` with the advice applied."""

    case: str
    dt: float
    substeps: int
    failing: tuple[str, ...]
    settings: dict[str, float]
    measure: str
    before: float
    after: float


def _settings(failing: list[Any]) -> dict[str, float]:
    """The settings the failing findings give: collision_bias = 1 for ``bias``, a hundredth
    of the smallest shape for ``slop`` (a tenth of the finding's limit)."""
    from dumbbell.spaces.guard import SLOP_FRACTION, SLOP_SUGGESTED

    out = {}
    for f in failing:
        if f.kind == "bias":
            out["collision_bias"] = 1.0
        elif f.kind == "slop":
            out["collision_slop"] = f.limit * SLOP_SUGGESTED / SLOP_FRACTION
    return out


def advice(case: str, steps: int = ADVICE_STEPS) -> Advice:
    """The guard's advice on ``case`` and its effect (see the module docstring)."""
    from dumbbell import spaces

    name, kind = CASES[case]
    seen: dict[str, Any] = {}

    def first(space: Any, dt: float) -> None:
        seen["dt"] = dt
        seen["n"] = spaces.substeps(space, dt)
        seen["failing"] = spaces.check(space, dt, units=UNITS)

    run_example(name, 1, isolate=_isolate(kind), on_first=first)
    dt, n, failing = seen["dt"], seen["n"], seen["failing"]
    kinds = tuple(sorted({f.kind for f in failing}))
    settings = _settings(failing)
    runs = ((1, None), (n, settings))
    if any(k in SPRINGS for k in kinds):
        steps = min(steps, max(10, REFERENCE_STEPS // (4 * n)))
        err = []
        references: dict[tuple, tuple[list[float], list[float]]] = {}
        for m, setting in runs:
            # The reference of both runs is one run when the advice gives no setting (None
            # and {} apply nothing): made once.
            key = tuple(sorted((setting or {}).items()))
            if key not in references:
                references[key] = _series(case, steps, 4 * n, setting)
            ref, scale = references[key]
            e, _ = _series(case, steps, m, setting)
            diff = max(abs(a - b) for a, b in zip(e, ref, strict=True))
            err.append(diff / max(scale) if max(scale) > 0 else diff)
        return Advice(case, dt, n, kinds, settings, "energy error", err[0], err[1])
    if "tunnelling" in kinds or not kinds:
        depth = []
        for m, setting in runs:
            d, _ = _series(case, steps, m, setting, "overlap")
            depth.append(max(d, default=0.0))
        return Advice(case, dt, n, kinds, settings, "first-contact overlap / limit", depth[0],
                      depth[1])
    if "joint" in kinds:
        subjects = {f.subject for f in failing if f.kind == "joint"}
        drift = [_joint_drift(case, steps, m, subjects) for m, _ in runs]
        return Advice(case, dt, n, kinds, settings, "joint drift / scale a second", drift[0],
                      drift[1])
    gained = []
    for m, setting in runs:
        b, scale = _series(case, steps, m, setting, "balance")
        gained.append(max(0.0, max(b)) / max(scale) if max(scale) > 0 else max(0.0, max(b)))
    return Advice(case, dt, n, kinds, settings, "energy gained", gained[0], gained[1])


# --- the table -------------------------------------------------------------------------------


HEAD = ("| case | dt (s) | estimated peak (px/s) | real peak (px/s) | estimate / real | "
        "advice | measured | at the program's step | with the advice |")


def row(case: str, p: Peaks, a: Advice) -> str:
    """The table's row of ``case`` from what :func:`peaks` and :func:`advice` measured."""
    ratio = p.estimated / p.peak if p.peak > 0 else math.inf
    steps = [k for k in a.failing if k not in ("bias", "slop")]
    what = [f"{a.substeps} sub-steps ({', '.join(steps)})"] if a.substeps > 1 else []
    what += [f"{k} = {v:g}" for k, v in a.settings.items()]
    ratio_text = f"{ratio:.2f}" if math.isfinite(ratio) else "(at rest)"
    return (f"| {case} | {a.dt:.4g} | {p.estimated:.4g} | {p.peak:.4g} | {ratio_text} | "
            f"{'; '.join(what) or 'none'} | {a.measure} | {a.before:.3g} | {a.after:.3g} |")


def table() -> str:
    """The per-example table of docs/spaces-reference.md (Markdown)."""
    lines = [HEAD, "|---|---|---|---|---|---|---|---|---|"]
    lines += [row(case, peaks(case), advice(case)) for case in CASES]
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
