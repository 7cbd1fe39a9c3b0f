"""Stepping a pymunk space in sub-steps: :func:`step` (one frame) and :class:`Driver` (frames
at a fixed step, in the guard's sub-steps unless told).

A frame of ``dt`` is ``substeps`` steps of ``dt / substeps``. What the program set for the
frame acts over all of it, as it would in one step: pymunk clears ``Body.force`` and
``Body.torque`` after every step (its velocity update does), so the forces and torques set
before the frame (directly, or added by ``apply_force_at_world_point`` and
``apply_force_at_local_point``) are set again before each later sub-step. A body whose
custom ``velocity_func`` does not call pymunk's update keeps its force anyway and is left
alone; a force a callback sets inside a sub-step (pymunk keeps it for the next step) is added
on top. The state is checked finite before the first frame and after each (one
``pymunk.batch`` read): a state that stops being finite stops the stepping with a
DumbbellError naming the body, the value and the frame.
"""

from __future__ import annotations

import math
import os
from typing import Any, NamedTuple

import numpy as np

from ..errors import DumbbellError, UsageError
from ..model import args
from ._scan import batch, scan
from .estimates import state_problem, step_dt
from .guard import MAX_STEPS, TOLERANCE, _advise, _check, _refuse

__all__ = ["Driver", "step"]


def step(space: Any, dt: float, substeps: int = 1) -> None:
    """Advance ``space`` by one frame of ``dt`` (s) in ``substeps`` equal steps. The forces
    and torques the program set for the frame (``Body.force``, ``Body.torque``, what
    ``apply_force_at_world_point`` and ``apply_force_at_local_point`` added) act in every
    sub-step, as they act over the whole frame without sub-steps (pymunk clears them after
    each step). A state that is not finite is refused before the frame and named after it
    (a DumbbellError).

    Parameters
    ----------
    space : pymunk.Space
        The space.
    dt : float
        The frame's step (the space's time unit).
    substeps : int, default 1
        Equal sub-steps.

    Raises
    ------
    UsageError
        An argument that is not allowed.
    DumbbellError
        A state that is not finite, before the frame or after it.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball thrown straight up
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(1.0, 1.0)
    >>> ball.velocity = (0.0, 5.0)                  # thrown up at 5 m/s
    >>> space.add(ball)
    >>> spaces.step(space, 0.1, substeps=10)        # 10 steps of 0.01 s
    >>> round(ball.velocity.y, 6)                   # m/s: 5 - 9.8 * 0.1
    4.02
    >>> round(ball.position.y, 6)      # m: each 0.01 s moves at the speed it starts with
    0.4559
    """
    space = args.space(space)
    substeps = args.whole(substeps, "substeps", "sub-steps", hi=MAX_STEPS)
    h = _frame_step(dt, substeps)
    _frames(space, _Frames(h, substeps, 1))


def _frame_step(dt: Any, substeps: int) -> float:
    """The sub-step of a frame of ``dt`` (s): ``dt`` checked at the border (a finite number
    > 0 and at most :data:`.estimates.MAX_DT`), divided by ``substeps``."""
    dt = step_dt(dt)
    if not dt / substeps > 0:
        raise UsageError(f"dt = {args.show(dt)}: must be long enough to divide into "
                         f"{substeps:,} sub-steps that are not 0 s", param="dt")
    return dt / substeps


class _Frames(NamedTuple):
    """Frames to step: sub-step ``h`` (s), ``substeps`` of it a frame, ``count`` frames, the
    first numbered ``first`` + 1 (for messages; ``dt`` = h * substeps)."""

    h: float
    substeps: int
    count: int
    first: int = 0


def _frames(space: Any, frames: _Frames) -> None:
    """Step ``frames``: the program's forces of each frame kept over its sub-steps
    (:func:`_pushes`), the state checked finite before the first frame and after each."""
    step_ = space.step
    h, n = frames.h, frames.substeps
    problem = _not_finite(space)
    if problem is not None:
        raise UsageError(f"space: {problem[0]}: {problem[1]}", param="space")
    try:
        for k in range(frames.count):
            pushes = _pushes(space) if n > 1 else []
            step_(h)
            for _ in range(n - 1):
                if pushes:
                    _push_again(pushes)
                step_(h)
            problem = _not_finite(space)
            if problem is not None:
                _blown(problem, frames, k)
    except AssertionError as exc:
        import traceback

        if not traceback.extract_tb(exc.__traceback__)[-1].filename.endswith(
                os.path.join("pymunk", "space.py")):
            raise  # a callback's own assertion is the user's
        raise UsageError(f"space: {' '.join(str(exc).split())}", param="space") from None


def _blown(problem: tuple[str, str, float], frames: _Frames, k: int) -> None:
    """Raise the verdict on a state that stopped being finite in frame ``k`` of ``frames``: a
    DumbbellError naming the body, the value and the frame, with ``frames_done``."""
    who, what, _ = problem
    number = frames.first + k + 1
    dt = frames.h * frames.substeps
    when = (f"after frame {number} (t = {(number - 1) * dt:.6g} s to {number * dt:.6g} s"
            + (f", {frames.substeps} sub-steps of {frames.h:.4g} s" if frames.substeps > 1
               else "") + ")")
    what = what.split(" is not a finite number")[0]
    error = DumbbellError(f"space: {who}: {what} {when}: the state stopped being finite in that "
                          "frame, and stepping stopped there: a step too long for something "
                          "stiff or fast (spaces.report names it), or a value the program set")
    error.frames_done = k + 1  # type: ignore[attr-defined]
    raise error


def _not_finite(space: Any) -> tuple[str, str, float] | None:
    """The first body whose position, angle, velocity or spin is not finite, as
    :func:`~.estimates.state_problem` names it; None when all are (one ``pymunk.batch``
    read of the whole space; the space is scanned only to name a body)."""
    fields = ("POSITION", "ANGLE", "VELOCITY", "ANGULAR_VELOCITY")
    _, rows = batch(space, fields)
    if np.isfinite(rows).all():
        return None
    return state_problem(scan(space)) or ("a body", "its state is not a finite number", math.nan)


class _Push:
    """A dynamic body the program pushes this frame: its ``force`` and ``torque`` as the
    program left them before the frame, and what the guard last set (``set_force``,
    ``set_torque``)."""

    __slots__ = ("body", "force", "set_force", "set_torque", "torque")

    def __init__(self, body: Any, force: Any, torque: float) -> None:
        self.body, self.force, self.torque = body, force, torque
        self.set_force, self.set_torque = force, torque


def _pushes(space: Any) -> list[_Push]:
    """The dynamic bodies with a force or torque set for this frame (none: one batch read)."""
    import pymunk

    ids, rows = batch(space, ("FORCE", "TORQUE"))
    pushed = np.flatnonzero((rows != 0.0).any(axis=1))
    if len(pushed) == 0:
        return []
    by_id = {b.id: b for b in space.bodies}
    out = []
    for j in pushed:
        body = by_id.get(int(ids[j]))
        if body is not None and body.body_type == pymunk.Body.DYNAMIC:
            out.append(_Push(body, pymunk.Vec2d(rows[j, 0], rows[j, 1]), float(rows[j, 2])))
    return out


def _push_again(pushes: list[_Push]) -> None:
    """Before a sub-step after the first: each pushed body's force and torque again. pymunk's
    own velocity update clears them after each step; a custom ``velocity_func`` that does not
    call it leaves them as they were, and they are left alone. What a callback added in the
    sub-step before (pymunk keeps it for the next step) is kept on top."""
    for p in pushes:
        body = p.body
        force, torque = body.force, body.torque
        if force == p.set_force and torque == p.set_torque:
            continue
        body.force = p.set_force = p.force + force
        body.torque = p.set_torque = p.torque + torque


class Driver:
    """Steps a space at a fixed frame step ``dt`` (s) in whole sub-steps: ``substeps`` given,
    or None for the guard's suggestion at the start (``speeds`` and ``tolerance`` as in
    :func:`survey`). ``t`` (s) counts whole frames, so it does not drift with rounding.

    Parameters
    ----------
    space : pymunk.Space
        The space.
    dt : float
        The frame step (the space's time unit).
    substeps : int or None, default None
        Sub-steps per frame; None: the guard's suggestion.
    speeds : {'both', 'state', 'energy'}, default 'both'
        As in :func:`survey`.
    tolerance : float, default 0.01
        As in :func:`survey`.

    Raises
    ------
    UsageError
        An argument :func:`survey` refuses, a ``dt`` over 1e6 s (no step a space can take),
        ``substeps`` not a whole number >= 1, or (``substeps`` None) a space the guard
        suggests no step for.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # two 1 kg balls on a 400 N/m spring
    >>> a, b = pymunk.Body(1.0, 1e-3), pymunk.Body(1.0, 1e-3)
    >>> b.position = (1.0, 0.0)
    >>> space.add(a, b, pymunk.DampedSpring(a, b, (0, 0), (0, 0), 0.8, 400.0, 0.0))
    >>> driver = spaces.Driver(space, 1 / 60)       # the guard's sub-steps: w = sqrt(800)
    >>> driver.step(5)
    >>> driver
    Driver(dt=0.0166667 s, substeps=48, frames=5, t=0.0833333 s)
    """

    def __init__(self, space: Any, dt: float, substeps: int | None = None,
                 speeds: str = "both", tolerance: float = TOLERANCE) -> None:
        self.space, self.dt, speeds, tolerance, unit = _check(space, dt, speeds, tolerance)
        _frame_step(self.dt, 1)
        if substeps is None:
            substeps = _refuse(_advise(self.space, self.dt, speeds, tolerance, unit))
        self.substeps = args.whole(substeps, "substeps", "sub-steps", hi=MAX_STEPS)
        self.h = self.dt / self.substeps
        self.frames = 0

    @property
    def t(self) -> float:
        """Time stepped so far (s)."""
        return self.frames * self.dt

    def __repr__(self) -> str:
        return (f"Driver(dt={self.dt:.6g} s, substeps={self.substeps}, frames={self.frames}, "
                f"t={self.t:.6g} s)")

    def step(self, frames: int = 1) -> None:
        """Advance ``frames`` frames.

        Parameters
        ----------
        frames : int, default 1
            How many.

        Raises
        ------
        UsageError
            A number of frames that is not allowed.
        DumbbellError
            A state that is not finite (naming the body).
        """
        frames = args.whole(frames, "frames", "frames", lo=0, hi=MAX_STEPS // self.substeps)
        if frames:
            try:
                _frames(self.space, _Frames(self.h, self.substeps, frames, self.frames))
            except DumbbellError as e:
                self.frames += getattr(e, "frames_done", 0)
                raise
        self.frames += frames

