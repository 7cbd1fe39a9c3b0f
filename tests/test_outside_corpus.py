"""dumbbell.spaces on programs written here the way pymunk users write them (issue 28's
corpus: tests/outside_corpus.py, measured through tests/outside_tape.py): for each program,
its energy terms against a hand computation; the ledger counting over the whole run and
closing, or naming why not; each ``program``, ``entered``, ``left`` and callback term
against what the program did, measured by hand just before and just after it; the recorder
drawing y as the program's window does, every dynamic body at least 4 px or named; the
guard with a row for every constraint; the heat counter against the ledger's contact terms.
Then, on the same programs: the tools leaving the motion alone, each pair's push apart as
dt changes, sub-steps that keep the program's forces, and the guard reading centres of
gravity, not origins."""

from __future__ import annotations

import json
import math
import re
import types

import numpy as np
import pymunk
import pytest

from .outside_corpus import PROGRAMS, run
from .outside_tape import hand_energy, recentred
from .recorder_corpus import body_size, extent, frame, picture, scene_mask

NAMES = list(PROGRAMS)
#: Kinds of terms that say what a program did (between steps or from a callback).
DONE = ("program", "entered", "left", "unattributed")
#: spaces.energy against the hand computation, relative to the size of each sum (the sum
#: of its parts' absolute values): a few roundings (the worst measured 6.0e-16).
HAND = 2e-15
#: Each term against what the program did, measured, relative to the ledger's scale
#: (issue 28 asks 1e-9; the worst measured is 2.4e-16).
TERMS = 1e-12
#: Drawn at least this many pixels across (issue 28).
MIN_PX = 4

#: What each program must have done in its run (kind, source prefix), so that the checks
#: of its terms are not vacuous.
DID = {
    "pool_table": [("program", "program: body 0"), ("left", "body ")],
    "car": [("program", "program: body ")],
    "ragdoll": [("program", "program: body ")],
    "cloth": [("entered", "body "), ("program", "program: constraints added or removed"),
              ("program", "program: springs stretched by moved bodies"),
              ("program", "program: body ")],
    "gas": [("program", "program: body "), ("entered", "body "), ("left", "body ")],
    "bumpers": [("entered", "body "), ("left", "body "), ("unattributed", "body ")],
    "spawner": [("entered", "body "), ("left", "body "), ("program", "program: body "),
                ("program", "program: constraints added or removed")],
    "planet": [("program", "program: body 0"), ("entered", "body 30")],
    "planet_declared": [("program", "program: body 0"), ("entered", "body 30")],
    "conveyor": [("entered", "body "), ("left", "body ")],
    "chain": [("program", "program: body ")],
    "hammer": [("program", "program: body 0")],
    "frame_drops": [("entered", "body ")],
    "ship": [("entered", "body "), ("left", "body ")],
    "ship_substeps": [("entered", "body "), ("left", "body ")],
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = run(name, tmp_path_factory.mktemp(name))
        return cache[name]

    return get


@pytest.fixture(scope="module")
def guarded(runs):
    """Each program's guard, taken once at the end of its run: ``spaces.survey``'s rows
    and ``spaces.report``'s text, shared by the tests that read them. The joints' rows are
    measured on copies of the space (the costly part): the report is written from the
    advice the survey just took of the same space, unchanged, at the same dt (the guard's
    ``_advise``, the one computation both make, is deterministic)."""
    from dumbbell import spaces
    from dumbbell.spaces import guard

    cache = {}
    advise = guard._advise

    def get(name):
        if name not in cache:
            tape = runs(name)
            unit = tape.units[0]
            taken = []

            def once(*args):
                if not taken:
                    taken.append((args, advise(*args)))
                assert taken[0][0] == args
                return taken[0][1]

            with pytest.MonkeyPatch.context() as mp:
                mp.setattr(guard, "_advise", once)
                cache[name] = (spaces.survey(tape.space, tape.dt, units=unit),
                               spaces.report(tape.space, tape.dt, units=unit))
            assert len(taken) == 1
        return cache[name]

    return get


def _by_source(balance, kinds=DONE) -> dict[tuple[str, str], float]:
    out: dict[tuple[str, str], float] = {}
    for t in balance.terms:
        if t.kind in kinds:
            out[(t.kind, t.source)] = out.get((t.kind, t.source), 0.0) + t.energy
    return out


@pytest.mark.parametrize("name", NAMES)
def test_energy_terms_are_the_hand_computation(name, runs):
    tape = runs(name)
    assert len(tape.checkpoints) >= 2
    for cp in tape.checkpoints:
        hand, lib = cp.hand, cp.lib
        for term in ("K_trans", "K_rot", "U_g", "U_spring", "E"):
            h, got = getattr(hand, term), getattr(lib, term)
            assert abs(got - h) <= HAND * hand.size[term] + 1e-300, (cp.step, term, got, h)
        for k in (0, 1):
            assert abs(lib.momentum[k] - hand.momentum[k]) <= HAND * hand.size["momentum"]
        if hand.mass:
            k_cm = 0.5 * (hand.momentum[0] ** 2 + hand.momentum[1] ** 2) / hand.mass
            assert abs(lib.K_cm - k_cm) <= HAND * hand.size["K_trans"] + 1e-300
    moving = [cp for cp in tape.checkpoints if cp.hand.K_trans > 0]
    assert moving, "nothing moved: the comparison says nothing"


@pytest.mark.parametrize("name", NAMES)
def test_the_ledger_counts_over_the_whole_run(name, runs):
    tape = runs(name)
    b = tape.balance
    assert "ledger" not in dict(b.unaccounted), dict(b.unaccounted).get("ledger")
    assert b.steps == len(tape.dts)
    assert b.t == pytest.approx(math.fsum(tape.dts), rel=1e-12)
    # Its E(t) is the space's energy by hand at the end (the declared field's included).
    end = tape.checkpoints[-1]
    assert end.step == len(tape.dts)
    assert abs(b.E - end.hand.E_total) <= 1e-14 * b.scale


def _expected_unaccounted(tape) -> tuple[set[str], set[str]]:
    """The sources the ledger must name as unaccounted, and those it may (at the edge of
    its tolerance): what the program changed by more than the tolerance of the scale, and
    bodies with a velocity_func whose potential was not declared."""
    b = tape.balance
    limit = b.tolerance * b.scale
    must, may = set(), set()
    for (kind, source), value in tape.events.items():
        if kind in ("program", "unattributed"):
            if abs(value) > 2 * limit:
                must.add(source)
            elif abs(value) > 0.5 * limit:
                may.add(source)
    if not tape.declared:
        for body in tape.kept:
            if body.velocity_func in tape.velocity_funcs:
                must.add(tape.labels[id(body)])
    return must, may


@pytest.mark.parametrize("name", NAMES)
def test_the_ledger_closes_or_names_the_cause(name, runs):
    tape = runs(name)
    b = tape.balance
    assert type(b.complete) is bool
    json.dumps({"complete": b.complete, "E": b.E, "closure": b.closure})
    assert b.relative_closure <= 1e-6 and b.worst_step <= 1e-6
    must, may = _expected_unaccounted(tape)
    named = set(dict(b.unaccounted))
    assert must <= named, sorted(must - named)[:10]
    assert named <= must | may, sorted(named - must - may)[:10]
    assert b.complete is (not named)


@pytest.mark.parametrize("name", NAMES)
def test_what_the_program_did_is_each_term(name, runs):
    tape = runs(name)
    b = tape.balance
    assert tape.unannounced == [], "the program added bodies it did not measure"
    for kind, prefix in DID[name]:
        assert any(k == kind and s.startswith(prefix) for k, s in tape.events), (kind, prefix)
    found = _by_source(b)
    wrong = {}
    for key in found.keys() | tape.events.keys():
        ledger, measured = found.get(key, 0.0), tape.events.get(key, 0.0)
        if abs(ledger - measured) > TERMS * b.scale:
            wrong[key] = (ledger, measured)
    assert not wrong, (f"{len(wrong)} terms differ from what the program did (ledger, "
                       f"measured), scale {b.scale:.4g}: {dict(sorted(wrong.items())[:8])}")


@pytest.mark.parametrize("name", NAMES)
def test_the_heat_counter_is_the_ledger_s_contact_heat(name, runs):
    # The heat counter (each contact's impulses against the relative velocity at its point)
    # and the ledger (each pair's work in its account) count the same dissipation in two
    # ways: what the contacts took out, on every program, with its callbacks and bodies
    # coming and going. (The bumpers' post_solve callbacks, set for particular collision
    # types, kick and slow balls: what they do is the program's, not heat.)
    tape = runs(name)
    b = tape.balance
    contact = math.fsum(t.energy for t in b.terms if t.source.startswith("contact "))
    assert abs(tape.heat.total + contact) <= TERMS * b.scale, (tape.heat.total, -contact)


def _in_view(rec, body) -> bool:
    """Whether the body's origin is inside the recording's view."""
    x0, x1, y0, y1 = rec.view
    p = body.position
    return min(x0, x1) <= p.x <= max(x0, x1) and min(y0, y1) <= p.y <= max(y0, y1)


def _screen_height(tape, body) -> float:
    """How high a body is on the program's own screen (y up: its y; y down: -y)."""
    y = body.local_to_world(body.center_of_gravity).y
    return y if tape.y_up else -y


@pytest.mark.parametrize("name", NAMES)
def test_the_recorder_draws_y_as_the_window_does(name, runs):
    tape = runs(name)
    rec, space = tape.rec, tape.space
    _, _, bottom, top = rec.view
    assert (top > bottom) == tape.y_up, (rec.view, getattr(rec, "orientation", None))
    # On the pixels: of two parts (moving bodies, static shapes) one above the other on the
    # program's screen, the higher one is drawn higher in the picture.
    parts = []  # (bottom, top, kind, index): heights on the program's screen
    for i, b in enumerate(space.bodies):
        if b.body_type != pymunk.Body.STATIC and b.shapes and _in_view(rec, b):
            parts.append((*_screen_span(tape, [s.cache_bb() for s in b.shapes]), "body", i))
    for i, s in enumerate(space.shapes):
        if s.body.body_type == pymunk.Body.STATIC and not s.sensor:
            bb = s.cache_bb()
            middle = pymunk.Vec2d((bb.left + bb.right) / 2, (bb.bottom + bb.top) / 2)
            if _in_view(rec, types.SimpleNamespace(position=middle)):
                parts.append((*_screen_span(tape, [bb]), "static", i))
    hi = max(parts)                          # its lowest point the highest
    lo = min(parts, key=lambda p: p[1])      # its highest point the lowest
    assert hi[0] > lo[1], "no part is above another on the program's screen"
    rows = []
    for _, _, kind, i in (hi, lo):
        mask = picture(space, rec, **{"bodies" if kind == "body" else "statics": [i]})
        assert mask.any()
        rows.append(np.median(np.nonzero(mask)[0]))
    assert rows[0] < rows[1]


def _screen_span(tape, boxes) -> tuple[float, float]:
    """The lowest and highest points of boxes on the program's own screen (heights)."""
    lo, hi = min(bb.bottom for bb in boxes), max(bb.top for bb in boxes)
    return (lo, hi) if tape.y_up else (-hi, -lo)


def _named(note: str, label: str) -> bool:
    return re.search(rf"(?<![\w#]){re.escape(label)}(?!\d)", note) is not None


@pytest.mark.parametrize("name", NAMES)
def test_every_dynamic_body_is_drawn_4_px_or_named(name, runs):
    tape = runs(name)
    rec, space = tape.rec, tape.space
    note = getattr(rec, "note", None) or ""
    listed = list(space.bodies)
    dynamic = [i for i, b in enumerate(listed) if b.body_type == pymunk.Body.DYNAMIC and b.shapes]
    shown = scene_mask(frame(rec.path, -1), rec)
    # Out of the picture at the end: named (the note lists the first few and how many more).
    out = [tape.labels[id(listed[i])] for i in dynamic if not _in_view(rec, listed[i])]
    unnamed = [label for label in out if not _named(note, label)]
    more = [int(n) for n in re.findall(r"and (\d+) more", note)]
    assert len(unnamed) <= sum(more), (unnamed[:8], note)
    # In the picture: the smallest bodies, each drawn alone through the same view, are 4 px
    # across on their pixels (and are what the frame shows there), or named.
    visible = sorted((i for i in dynamic if _in_view(rec, listed[i])),
                     key=lambda i: body_size(listed[i]))
    assert visible
    for i in visible[:3]:
        alone = picture(space, rec, bodies=[i])
        assert alone.sum() > 0
        assert (alone & shown).sum() >= 0.9 * alone.sum()
        label = tape.labels[id(listed[i])]
        assert extent(alone) >= MIN_PX or _named(note, label), (
            f"{label} drawn {extent(alone):g} px across, and the note does not name it: "
            f"{note!r}")


WITH_CONSTRAINTS = [n for n in NAMES if n not in ("gas", "bumpers", "planet", "planet_declared",
                                                   "conveyor", "frame_drops", "ship",
                                                   "ship_substeps")]


@pytest.mark.parametrize("name", WITH_CONSTRAINTS)
def test_the_guard_has_a_row_for_every_constraint(name, runs, guarded):
    tape = runs(name)
    space = tape.space
    assert space.constraints
    survey, text = guarded(name)
    rows = {f.subject: f for f, _ in survey}
    names = [f"{type(c).__name__} {j}" for j, c in enumerate(space.constraints)]
    missing = [n for n in names if n not in rows]
    assert not missing, f"{len(missing)} of {len(names)} constraints have no row: {missing[:6]}"
    # The report (which lists a few rows of each kind and sums up the rest) names every
    # kind of constraint, and says "nothing to fix" only where every row was checked.
    for kind in {type(c).__name__ for c in space.constraints}:
        assert re.search(rf"\b{kind} \d+", text), kind
    unchecked = [n for n in names if not getattr(rows[n], "checked", True)]
    if unchecked:
        assert "nothing to fix" not in text or "not checked" in text


def _motion(space) -> list[tuple[float, ...]]:
    return [(*b.position, *b.velocity, b.angle, b.angular_velocity) for b in space.bodies]


@pytest.mark.parametrize("name", ["pool_table", "bumpers", "spawner", "ship"])
def test_the_tools_leave_the_program_s_motion_alone(name, runs, tmp_path):
    # Issue 28: the ledger, heat counter and recorder attached together leave a program
    # alone: the same program run bare ends bit for bit where it ends with them, with its
    # post-step callbacks (the pockets, the crates), collision callbacks for particular
    # types (the bumpers' kick and mud, which the heat counter runs before), bodies and
    # joints added and removed every few frames, and per-frame forces and torques (the
    # ship's thrusters).
    bare = run(name, tmp_path, tools=False)
    tape = runs(name)
    assert bare.dts == tape.dts
    assert bare.events == tape.events
    assert _motion(bare.space) == _motion(tape.space)


def test_the_hand_computation_is_the_textbook_s():
    # The hand energy on a space small enough to write out: a 2 kg body with its centre of
    # gravity 0.5 m off its origin, turned 90 degrees, moving and spinning, under a slanted
    # gravity, on a spring to the static body.
    space = pymunk.Space()
    space.gravity = (1.0, -9.0)
    body = pymunk.Body(2.0, 3.0)
    body.center_of_gravity = (0.5, 0.0)
    body.angle = math.pi / 2  # (pymunk turns a body about its centre of gravity)
    body.position = (1.0, 2.0)
    body.velocity, body.angular_velocity = (3.0, 4.0), 2.0
    spring = pymunk.DampedSpring(space.static_body, body, (0.0, 0.0), (0.5, 0.0), 1.0, 10.0, 0)
    space.add(body, spring)
    h = hand_energy(space)
    cog = (1.0, 2.5)  # the origin plus (0.5, 0) turned by 90 degrees
    assert h.K_trans == pytest.approx(0.5 * 2.0 * 25.0, rel=1e-15)
    assert h.K_rot == pytest.approx(0.5 * 3.0 * 4.0, rel=1e-15)
    assert h.U_g == pytest.approx(-2.0 * (1.0 * cog[0] - 9.0 * cog[1]), rel=1e-15)
    assert h.U_spring == pytest.approx(0.5 * 10.0 * (math.hypot(*cog) - 1.0) ** 2, rel=1e-14)


def _pair(balance, kind: str, a: str, b: str) -> float:
    """The term of pair (a, b) of ``kind`` ('contact', 'pushed apart'), in either order."""
    found = [t.energy for t in balance.terms
             if t.source in (f"{kind} {a} / {b}", f"{kind} {b} / {a}")]
    return math.fsum(found)


def test_pushed_apart_is_gravity_s_part_of_each_push_as_dt_changes(runs):
    # Owed by issue 28: the split between a pair's "pushed apart" term and "position
    # correction" when dt changes from step to step. The frame_drops program steps by its
    # measured frame time (16, 17, 33 and 50 ms), with balls placed sunk into the floor and
    # balls dropped on it, each touching only the floor. pymunk moves a centre of gravity by
    # (v + v_bias) dt, so the harness measures each step's push, c1 - c0 - v0 dt, from the
    # bodies' public state before and after the step; gravity's part of its energy,
    # -m g . push, summed over the run, is the ball-floor pair's "pushed apart" term. With
    # no spring or field, "position correction" (their part) is nothing.
    tape = runs("frame_drops")
    b = tape.balance
    assert len(set(tape.dts)) >= 3 and max(tape.dts) / min(tape.dts) >= 3
    # The measurement is right: a ball sunk d into the floor ends up resting on it with
    # pymunk's slop of overlap left, raised by d - slop: m g (d - slop).
    for label, sunk in (("body 0", 8.0), ("body 1", 3.0), ("body 2", 12.0)):
        assert tape.pushes[label] == pytest.approx(900.0 * (sunk - 0.1), rel=1e-6)
    wrong = {}
    for label, pushed in tape.pushes.items():
        got = _pair(b, "pushed apart", label, "static body")
        if abs(got - pushed) > TERMS * b.scale:
            wrong[label] = (got, pushed)
    assert not wrong, f"(ledger, measured), scale {b.scale:.4g}: {wrong}"
    rest = math.fsum(t.energy for t in b.terms if t.source == "position correction")
    assert abs(rest) <= TERMS * b.scale


def test_sub_steps_keep_the_program_s_forces(runs):
    # Issue 28, item 4, on a program: the ship's thrusters and torque are set once per frame;
    # the player who applies the guard's advice (spaces.step with 6 sub-steps) must see the
    # ship reach the velocity and spin it reaches without it. With nothing else acting on
    # the ship (no contact, no gravity), each frame's change of velocity is F dt / m either
    # way, so the two agree to rounding; so do the bullets it fires (the ship's velocity
    # plus 600 px/s).
    plain, advised = runs("ship"), runs("ship_substeps")
    assert len(advised.dts) == 6 * len(plain.dts)
    for a, b in zip(plain.space.bodies, advised.space.bodies, strict=True):
        assert (a.velocity - b.velocity).length <= 1e-9 * max(a.velocity.length, 1.0)
        assert abs(a.angular_velocity - b.angular_velocity) <= 1e-9 * max(
            abs(a.angular_velocity), 1e-3)


@pytest.mark.parametrize("name", ["ragdoll", "hammer", "chain", "car", "ship"])
def test_the_guard_reads_centres_of_gravity_not_origins(name, runs, guarded):
    # Owed by issue 28: the guard's fall and tunnelling estimates must use a body's centre
    # of gravity, not its origin (`position`). These programs' bodies have their origin away
    # from their centre of gravity (limbs at their upper joint, a hammer at its grip, a
    # ship at its nose): the same world built with every origin at the centre of gravity
    # must get the same estimates, rows and energy.
    from dumbbell import spaces

    tape = runs(name)
    space, dt, unit = tape.space, tape.dt, tape.units[0]
    moved = recentred(space)
    offsets = [b.center_of_gravity.length for b in space.bodies if b.body_type == 0]
    assert max(offsets) > 0.05 * max(body_size(b) for b in space.bodies if b.shapes)
    before, after = spaces.energy(space), spaces.energy(moved)
    for term in ("K_trans", "K_rot", "U_g", "U_spring", "E"):
        size = abs(getattr(before, term)) + before.K_trans + before.K_rot
        assert abs(getattr(after, term) - getattr(before, term)) <= 1e-12 * size, term
    length = max(max(abs(v) for v in bb) for bb in (s.cache_bb() for s in space.shapes))
    for r0, r1 in zip(spaces.reach(space, dt, units=unit), spaces.reach(moved, dt, units=unit),
                      strict=True):
        assert r0.subject == r1.subject
        for field_name in ("speed", "now", "fall"):
            v0, v1 = getattr(r0, field_name), getattr(r1, field_name)
            assert v1 == pytest.approx(v0, rel=1e-6, abs=1e-9 * length), (r0, r1)
        assert (r0.level is None) == (r1.level is None)
        if r0.level is not None:
            assert r1.level == pytest.approx(r0.level, rel=1e-6, abs=1e-9 * length), (r0, r1)
    rows0 = {(f.kind, f.subject): f.value for f, _ in guarded(name)[0]}
    rows1 = {(f.kind, f.subject): f.value for f, _ in spaces.survey(moved, dt, units=unit)}
    assert rows0.keys() == rows1.keys()
    for key, value in rows0.items():
        if key[0] in ("tunnelling", "spring", "rotary-spring", "spring-network"):
            assert rows1[key] == pytest.approx(value, rel=1e-6, abs=1e-12), key
