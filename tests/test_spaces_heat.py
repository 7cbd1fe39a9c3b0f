"""spaces.HeatCounter: zero on elastic frictionless spaces, the closed form of sliding
friction on a slope, the energy balance to the method's error, and the user's callbacks."""

from __future__ import annotations

import math

import pymunk
import pytest

from dumbbell import spaces


def _si(space: pymunk.Space) -> pymunk.Space:
    space.collision_bias = 1.0
    space.collision_slop = 1e-4
    return space


def _slope(mu: float, angle: float, spin: float = 0.0) -> tuple[pymunk.Space, pymunk.Body]:
    space = _si(pymunk.Space())
    space.gravity = (0.0, -9.81)
    c, s = math.cos(angle), math.sin(angle)
    ramp = pymunk.Poly(space.static_body, [(0, 0), (30 * c, -30 * s), (30 * c, -30 * s - 1),
                                           (0, -1)])
    ramp.friction = mu
    body = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.1)))
    box = pymunk.Poly.create_box(body, (0.2, 0.1))
    box.friction = 1.0  # pymunk multiplies the two shapes' friction: mu on the slope
    body.angle = -angle
    lift = 0.05 + (0.2 if spin else 0.0)
    body.position = (1.0 * c + lift * s, -1.0 * s + lift * c)
    body.angular_velocity = spin
    space.add(ramp, body, box)
    return space, body


def test_zero_on_elastic_frictionless_spaces():
    # Billiards without gravity in a closed box, and a ball bouncing on a floor with gravity.
    space = _si(pymunk.Space())
    for a, b in (((-1, -1), (1, -1)), ((1, -1), (1, 1)), ((1, 1), (-1, 1)), ((-1, 1), (-1, -1))):
        wall = pymunk.Segment(space.static_body, a, b, 0.05)
        wall.elasticity, wall.friction = 1.0, 0.0
        space.add(wall)
    for i, (x, y, vx, vy) in enumerate([(-0.5, 0.0, 3.0, 0.7), (0.5, 0.1, -2.0, 0.3),
                                        (0.0, 0.6, 0.4, -2.5), (0.1, -0.5, 1.1, 1.9)]):
        body = pymunk.Body(1.0 + i, math.inf)
        body.position, body.velocity = (x, y), (vx, vy)
        ball = pymunk.Circle(body, 0.1)
        ball.elasticity, ball.friction = 1.0, 0.0
        space.add(body, ball)
    heat = spaces.HeatCounter(space)
    e0 = spaces.energy(space).E
    spaces.step(space, 5.0, substeps=5000)
    assert heat.steps > 50  # it saw the impacts
    assert abs(heat.total) < 1e-12 * e0
    assert spaces.energy(space).E == pytest.approx(e0, rel=1e-12)

    space = _si(pymunk.Space())
    space.gravity = (0.0, -9.81)
    floor = pymunk.Poly(space.static_body, [(-5, 0), (5, 0), (5, -1), (-5, -1)])
    floor.elasticity, floor.friction = 1.0, 0.0
    body = pymunk.Body(1.0, math.inf)
    body.position = (0.1, 1.0)
    ball = pymunk.Circle(body, 0.05)
    ball.elasticity, ball.friction = 1.0, 0.0
    space.add(floor, body, ball)
    heat = spaces.HeatCounter(space)
    spaces.step(space, 3.0, substeps=3000)
    assert heat.steps >= 3 and abs(heat.total) < 1e-12 * spaces.energy(space).E


@pytest.mark.parametrize("mu, angle", [(0.3, math.radians(30)), (0.5, math.radians(40))])
def test_sliding_box_heat_is_mu_n_times_distance(mu, angle):
    space, body = _slope(mu, angle)
    start = body.position
    heat = spaces.HeatCounter(space)
    spaces.step(space, 1.0, substeps=10_000)
    slid = (body.position - start).length
    assert abs(body.angular_velocity) < 1e-9  # it slid flat, no tumbling
    assert heat.total == pytest.approx(mu * 1.0 * 9.81 * math.cos(angle) * slid, rel=1e-3)


def test_slope_balance_closes_to_the_method_error():
    # Sliding and tumbling: E(0) - E(t) - heat is the step's error, first order in dt.
    residual = {}
    for n in (1000, 10_000):
        space, _ = _slope(0.4, math.radians(30), spin=-8.0)
        heat = spaces.HeatCounter(space)
        e0 = spaces.energy(space).E
        spaces.step(space, 2.0, substeps=n)
        lost = e0 - spaces.energy(space).E
        assert lost > 5.0 and heat.total > 5.0
        residual[n] = lost - heat.total
        assert abs(residual[n]) < 20.0 / n * heat.total
    assert 5 < residual[1000] / residual[10_000] < 20


def test_users_callbacks_still_fire():
    space = _si(pymunk.Space())
    space.gravity = (0.0, -9.81)
    floor = pymunk.Segment(space.static_body, (-5, 0), (5, 0), 0.1)
    floor.collision_type = 1
    floor.elasticity, floor.friction = 0.5, 0.5
    body = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    body.position = (0.0, 1.0)
    ball = pymunk.Circle(body, 0.1)
    ball.collision_type = 2
    ball.elasticity, ball.friction = 1.0, 1.0
    space.add(floor, body, ball)
    fired: dict[str, list] = {"begin": [], "post": [], "wild": []}
    space.on_collision(1, 2, begin=lambda a, s, d: fired["begin"].append(d),
                       post_solve=lambda a, s, d: fired["post"].append(d), data="mine")
    space.on_collision(None, None, post_solve=lambda a, s, d: fired["wild"].append(d),
                       data="wild data")
    heat = spaces.HeatCounter(space)
    spaces.step(space, 1.0, substeps=1000)
    assert heat.attached and heat.total > 0
    assert fired["begin"] and set(fired["begin"]) == {"mine"}
    assert len(fired["post"]) == len(fired["wild"]) == heat.steps
    assert set(fired["wild"]) == {"wild data"}
    heat.detach()
    counted, calls = heat.total, len(fired["wild"])
    body.position, body.velocity = (0.0, 1.0), (0.0, 0.0)
    spaces.step(space, 1.0, substeps=1000)
    assert heat.total == counted and not heat.attached
    assert len(fired["wild"]) > calls and len(fired["post"]) == len(fired["wild"])


def test_sliding_heat_holds_when_dt_changes_between_steps():
    # pymunk scales the impulses it carries over by dt / previous dt.
    mu, angle = 0.3, math.radians(30)
    space, body = _slope(mu, angle)
    start = body.position
    heat = spaces.HeatCounter(space)
    for i in range(4000):
        space.step(1e-4 if i % 3 else 4e-4)
    slid = (body.position - start).length
    assert heat.total == pytest.approx(mu * 1.0 * 9.81 * math.cos(angle) * slid, rel=1e-3)


def _handler_state(space: pymunk.Space):
    # What a program sees of the wildcard handler: its callbacks and data (a handler with
    # none behaves as no handler; pymunk offers no way to remove one). Its class is never
    # swapped.
    from pymunk._collision_handler import CollisionHandler

    h = space._handlers.get((None, None))
    if h is None:
        return None
    assert type(h) is CollisionHandler
    state = h.begin, h.pre_solve, h.post_solve, h.separate, dict(h.data)
    return None if state == (None, None, None, None, {}) else state


@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
@pytest.mark.parametrize("users", [False, True])
def test_counters_detach_in_any_order_and_leave_the_handler_as_it_was(order, users):
    space, _ = _slope(0.3, math.radians(30))
    if users:
        space.on_collision(None, None, pre_solve=lambda a, s, d: None, data="theirs")
    before = _handler_state(space)
    counters = [spaces.HeatCounter(space), spaces.HeatCounter(space)]
    spaces.step(space, 0.5, substeps=500)
    assert counters[0].total == counters[1].total > 0
    counters[order[0]].detach()
    assert counters[order[1]].attached and not counters[order[0]].attached
    spaces.step(space, 0.2, substeps=200)
    assert counters[order[1]].total > counters[order[0]].total
    counters[order[1]].detach()
    assert _handler_state(space) == before
    assert not any(c.attached for c in counters)


def test_copy_and_pickle_with_a_counter_attached():
    import copy
    import pickle

    space, _ = _slope(0.3, math.radians(30))
    seen = []
    space.on_collision(None, None, post_solve=_note, data=seen)
    heat = spaces.HeatCounter(space)
    spaces.step(space, 0.2, substeps=200)
    for other in (space.copy(), copy.deepcopy(space), pickle.loads(pickle.dumps(space))):
        h = other._handlers[(None, None)]
        # The copy has the callbacks the space had before the counter, and no counter.
        assert h.post_solve is _note and h.pre_solve is None and "_dumbbell_heat" not in \
            other.__dict__
        spaces.step(other, 0.1, substeps=100)
    counted = heat.total
    spaces.step(space, 0.2, substeps=200)
    assert heat.attached and heat.total > counted
    clone = pickle.loads(pickle.dumps(heat))  # a copy of the counter keeps its count only
    assert clone.total == heat.total and not clone.attached


def _note(arbiter, space, data):
    data.append(1)


def test_replacing_its_callback_warns_once_and_says_so():
    space, _ = _slope(0.3, math.radians(30))
    heat = spaces.HeatCounter(space)
    spaces.step(space, 0.2, substeps=200)
    assert "_dumbbell_heat" not in space.__dict__  # nothing stored on the space
    space.on_collision(None, None, post_solve=_note, data=[])
    with pytest.warns(RuntimeWarning, match="wildcard post_solve callback was replaced "
                                            r"\(by _note\) after \d+ contact-steps"):
        spaces.step(space, 0.01, substeps=10)  # noticed at the next contact it would count
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once: no second warning
        space.on_collision(None, None, post_solve=_note, data=[])
        counted = heat.total
        spaces.step(space, 0.2, substeps=200)
    assert not heat.attached and "replaced" in heat.stopped and heat.total == counted
    heat.detach()
    assert space._handlers[(None, None)].post_solve is _note


def test_a_counter_dropped_without_detach_gives_the_handler_back():
    import gc

    space, _ = _slope(0.3, math.radians(30))
    before = _handler_state(space)
    heat = spaces.HeatCounter(space)
    spaces.step(space, 0.1, substeps=100)
    del heat
    gc.collect()
    assert _handler_state(space) == before


@pytest.mark.parametrize("before", [True, False])
def test_a_velocity_set_in_a_typed_post_solve_is_not_heat(before):
    # pymunk calls a post_solve set for particular collision types before the wildcard one
    # the counter listens on (the outside corpus's bumpers: a kick and a mud strip). A 1 kg
    # ball meets a frictionless floor with e = 0 at 10 m/s; the program's post_solve then
    # sets its velocity to (3, 4). By hand: the contact's impulse 10 N s stops the normal
    # motion (u from -10 to 0), heat 1/2 1 10^2 = 50 J, whatever the program does after it;
    # the kick (1/2 1 5^2 = 12.5 J, then the ball flies off) is the program's, not heat.
    # The handler set before the counter attaches, or after.
    space = _si(pymunk.Space())
    floor = pymunk.Segment(space.static_body, (-5, 0), (5, 0), 0.0)
    floor.collision_type, floor.elasticity, floor.friction = 2, 0.0, 0.0
    ball = pymunk.Body(1.0, 1.0)
    ball.position, ball.velocity = (0.0, 0.2), (0.0, -10.0)
    shape = pymunk.Circle(ball, 0.1)
    shape.collision_type, shape.elasticity, shape.friction = 1, 0.0, 0.0
    space.add(floor, ball, shape)
    calls = []

    def kick(arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        calls.append(data)
        if arbiter.is_first_contact:
            arbiter.shapes[0].body.velocity = (3.0, 4.0)

    def handler() -> None:
        space.on_collision(1, 2, post_solve=kick, data="mine")

    if before:
        handler()
    counter = spaces.HeatCounter(space)
    ledger = spaces.Ledger(space)
    if not before:
        handler()
    for _ in range(20):
        space.step(0.005)
    assert calls and set(calls) == {"mine"}   # the callback fired, with its data
    assert ball.velocity.y > 0 and ball.position.y > 0.2
    assert counter.total == pytest.approx(50.0, rel=1e-12)
    unattributed = {t.source: t.energy for t in ledger.balance().terms
                    if t.kind == "unattributed"}
    assert unattributed == {"body 0": pytest.approx(12.5, rel=1e-12)}
    counter.detach()
    assert space._handlers[(1, 2)].post_solve is kick  # given back as it was


def test_a_typed_post_solve_neither_drops_nor_doubles_a_contact():
    # pymunk calls a typed post_solve, then the wildcard one, for the same arbiter; the
    # counters count it once, in the first. A no-op typed handler changes nothing, bit for bit.
    totals = []
    for typed in (False, True):
        space, _ = _slope(0.3, math.radians(30), spin=-8.0)
        if typed:
            for shape in space.shapes:
                shape.collision_type = 1 if shape.body is space.static_body else 2
            space.on_collision(1, 2, post_solve=lambda a, s, d: None)
        heat = spaces.HeatCounter(space)
        spaces.step(space, 0.5, substeps=500)
        totals.append((heat.total, heat.steps))
    assert totals[0] == totals[1] and totals[0][1] > 100


def test_a_step_whose_end_was_cut_short_is_forgotten():
    # A post-step callback that raises before the counter's runs leaves the counter's record
    # of that step in place (pymunk keeps the callbacks it did not run for the next step);
    # the next step starts afresh, and the count is the one of an uninterrupted run.
    totals = []
    for cut in (False, True):
        space, _ = _slope(0.3, math.radians(30), spin=-8.0)
        raised: list[object] = []

        def cut_short(space: pymunk.Space, key: object, raised: list = raised) -> None:
            if key not in raised:  # once: pymunk runs it again at the next step's end
                raised.append(key)
                raise KeyboardInterrupt

        heat = spaces.HeatCounter(space)
        for i in range(500):
            if cut and i % 7 == 3:
                space.add_post_step_callback(cut_short, i)
                with pytest.raises(KeyboardInterrupt):
                    space.step(1e-3)
            else:
                space.step(1e-3)
        totals.append((heat.total, heat.steps))
    assert totals[0] == totals[1] and totals[0][1] > 100
