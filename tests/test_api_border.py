"""Every public function checks its arguments at the border (docs/hardening.md, class 7).

The public callables are found, not listed: every name in ``__all__`` of :data:`PACKAGES` and
of their public submodules, and every public method of the public classes. :data:`VALID`
holds one set of valid arguments for each. Each argument in turn is replaced by each of
:data:`HOSTILE` while the others stay valid: the call must either succeed or raise a
``DumbbellError`` whose message names that argument; any other exception fails the test.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import io
import math
import pkgutil
import re
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from dumbbell import DumbbellError

#: Packages whose ``__all__`` (and their public submodules' ``__all__``) is the public API.
PACKAGES = ("dumbbell.model", "dumbbell.solvers", "dumbbell.spaces", "dumbbell.examples",
            "dumbbell.plot", "dumbbell.analysis", "dumbbell.io", "dumbbell.animation")
#: Packages whose own ``__all__`` counts, but not their submodules'.
TOP = ("dumbbell", "dumbbell.frames", "dumbbell.parallel", "dumbbell.progress")
#: Packages not walked: the compiled loops, which import numba and are called by the solver
#: classes only (which check the arguments first).
INTERNAL = ("dumbbell.solvers.kernels",)
#: Classes whose methods are a contract only (they raise NotImplementedError); every
#: registered subclass's are covered (:func:`_solver_rows`).
CONTRACTS = ("dumbbell.solvers.base.Solver", "dumbbell.solvers.stepping.Stepper")
#: The methods of the solver contract a registered solver has, its own or its family's.
SOLVER_METHODS = ("supports", "solve", "check_work", "truth_for", "catch_depth", "kernel",
                  "swing")

#: Values that are wrong for nearly every argument.
HOSTILE = (None, "text", [1, 2], float("nan"), -1, object())


def _modules() -> list[types.ModuleType]:
    out = [importlib.import_module(name) for name in TOP]
    for name in PACKAGES:
        package = importlib.import_module(name)
        out.append(package)
        for info in pkgutil.walk_packages(package.__path__, prefix=f"{name}."):
            if info.name.startswith(INTERNAL):
                continue
            if not any(part.startswith("_") for part in info.name.split(".")):
                out.append(importlib.import_module(info.name))
    return out


def _own_methods(cls: type) -> dict[str, tuple[Callable[..., Any], bool]]:
    """Public methods a class defines itself, each with whether it is called on an instance
    (False: a static or class method, called on the class): not dataclass or builtin
    machinery, and not overrides of a base class's methods from outside the package (a
    protocol others call, as pymunk calls a SpaceDebugDrawOptions' draw_circle)."""
    out = {}
    for name, value in vars(cls).items():
        if name.startswith("_") and name != "__getitem__":
            continue
        if isinstance(value, staticmethod | classmethod):
            fn, bound = getattr(cls, name), False
        elif inspect.isfunction(value):
            fn, bound = value, True
        else:
            continue
        if any(hasattr(base, name) for base in cls.__mro__[1:]
               if not base.__module__.startswith("dumbbell")):
            continue
        out[name] = (fn, bound)
    return out


@functools.cache
def public() -> dict[str, Any]:
    """Qualified name -> the public callable (a function, a class or a class's method)."""
    found: dict[str, Any] = {}
    for module in _modules():
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if isinstance(obj, types.ModuleType) or not callable(obj):
                continue
            qualname = getattr(obj, "__qualname__", name)
            key = f"{obj.__module__}.{name if '<' in qualname else qualname}"
            if inspect.isclass(obj) and issubclass(obj, BaseException):
                continue  # an exception takes any message
            found.setdefault(key, obj)
            if inspect.isclass(obj) and key not in CONTRACTS:
                for method, (fn, bound) in _own_methods(obj).items():
                    if _parameters(fn)[1 if bound else 0:]:
                        found.setdefault(f"{key}.{method}", fn)
    for cls in _solvers():
        # A solver's contract methods, inherited from its family or not (called on the class).
        key = f"{cls.__module__}.{cls.__qualname__}"
        for method in SOLVER_METHODS:
            if hasattr(cls, method):
                found.setdefault(f"{key}.{method}", getattr(cls, method))
    return found


def _solvers() -> list[type]:
    """The registered solver classes, found in the registry, not listed here."""
    return list(importlib.import_module("dumbbell.solvers").METHODS.values())


def _parameters(fn: Any) -> list[str]:
    """Names of the parameters a caller can give (no *args or **kwargs)."""
    try:
        signature = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    return [p.name for p in signature.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


# --- valid arguments -----------------------------------------------------------------------


class Fixtures:
    """Small valid objects, built on first use; ``fresh`` ones are built anew at each call
    (they change when used)."""

    def __init__(self, tmp: Path):
        self.tmp = tmp

    # scenes and runs -----------------------------------------------------------------------
    @functools.cached_property
    def scene_file(self) -> Path:
        """A short textbook scene (0.05 s, 500 steps) alone in its folder."""
        from tests.hostile import short_scene

        folder = self.tmp / "cases"
        folder.mkdir()
        return short_scene(folder)

    @functools.cached_property
    def scene(self) -> Any:
        from dumbbell import load_scene

        return load_scene(self.scene_file)

    @functools.cached_property
    def options(self) -> Any:
        """Run options of a short run (20 ms at 1 ms steps)."""
        from dumbbell.solvers import RunOptions

        return RunOptions(1e-3, 0.02, 1, True)

    @functools.cached_property
    def traj(self) -> Any:
        import dumbbell

        return dumbbell.simulate(self.scene, "exact", t_end=0.5, dt=1e-2, every=1)

    @functools.cached_property
    def scene_2d(self) -> Any:
        from dumbbell import load_scene
        from tests.conftest import SCENES

        return load_scene(SCENES / "tilted-2d.toml").with_values({"run.t_end": 0.3})

    @functools.cached_property
    def rigid_2d(self) -> Any:
        from dumbbell import load_scene
        from tests.conftest import SCENES

        return load_scene(SCENES / "rigid-2d.toml")

    @functools.cached_property
    def topple_scene(self) -> Any:
        from dumbbell import load_scene
        from tests.conftest import SCENES

        return load_scene(SCENES / "topple-2d.toml")

    @functools.cached_property
    def traj_2d(self) -> Any:
        """The rigid 2D dumbbell through its first impact (exact, 1 ms samples)."""
        import dumbbell

        return dumbbell.simulate(self.rigid_2d, "exact", t_end=0.6, dt=1e-3)

    @functools.cached_property
    def comparison(self) -> Any:
        import dumbbell

        return dumbbell.compare(self.scene, solvers=["euler-cromer"], dts=[1e-3], window=0.02,
                                t_end=0.05)

    @functools.cached_property
    def bench_result(self) -> Any:
        import dumbbell

        return dumbbell.bench(self.scene, solvers=["euler-cromer"], dts=[1e-3, 5e-4, 2.5e-4],
                              window=0.02,
                              repeat=1, t_end=0.05)

    @functools.cached_property
    def sweep_result(self) -> Any:
        import dumbbell

        return dumbbell.sweep(self.scene, {"k": [100.0, 200.0], "dt": [1e-3, 5e-4]},
                              t_end=0.02)

    @functools.cached_property
    def series(self) -> Any:
        from dumbbell.analysis.rotation import series

        return series(self.scene_2d, dt=1e-4, t_end=0.05)

    @functools.cached_property
    def restitution(self) -> Any:
        from dumbbell.analysis.restitution import restitution

        return restitution(self.rigid_2d, [10.0, 20.0], stiffnesses=(), dt=1e-3)

    @functools.cached_property
    def topple_cf(self) -> Any:
        from dumbbell.analysis.topple import closed_form

        return closed_form(self.topple_scene)

    @functools.cached_property
    def topple_traj(self) -> Any:
        import dumbbell

        return dumbbell.simulate(self.topple_scene, "pymunk", dt=1e-3, every=1)

    @functools.cached_property
    def topple_measure(self) -> Any:
        from dumbbell.analysis.topple import measure

        return measure(self.topple_traj)

    @functools.cached_property
    def contact(self) -> Any:
        from dumbbell.analysis.contact import about_contact

        return about_contact(self.traj_2d)

    @functools.cached_property
    def maps(self) -> dict[str, list[Any]]:
        """Stability-map rows of one made-up solver: stable up to w*dt = 2."""
        from dumbbell.analysis.stability import MAP_RATIOS, MAP_WDT
        from dumbbell.analysis.sweep import PointResult

        return {"made-up": [PointResult(values=(("bodies.A.mass", 0.1 / r),), w_dt=h,
                                        verdict="ok" if h < 2 else "unstable",
                                        t_fail=None if h < 2 else 0.1,
                                        max_rel_energy_error=h / 4 if h < 2 else math.nan,
                                        reason="" if h < 2 else "made up")
                            for h in MAP_WDT for r in MAP_RATIOS]}

    @functools.cached_property
    def run(self) -> Any:
        """Euler-Cromer sampled at :attr:`traj`'s times (every 10 ms)."""
        import dumbbell

        return dumbbell.simulate(self.scene, "euler-cromer", dt=1e-3, t_end=0.5, every=10)

    @functools.cached_property
    def stability_result(self) -> Any:
        import dumbbell

        return dumbbell.stability(self.scene_file.parent, solvers=["euler-cromer"], workers=1)

    @functools.cache  # noqa: B019 - one figure per count for the whole test: hostile calls
    def ax(self, count: int = 1) -> Any:  # stop before drawing, valid ones draw over it
        """A figure's axes: one, or a list of ``count``."""
        import matplotlib.pyplot as plt

        axes = plt.subplots(count, 1)[1]
        return axes if count == 1 else list(axes)

    # pymunk ---------------------------------------------------------------------------------
    def space(self) -> Any:
        """A ball above a floor, on a spring to a second ball."""
        import pymunk

        space = pymunk.Space()
        space.gravity = (0.0, -9.81)
        floor = pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.05)
        floor.elasticity = 1.0
        a = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.05))
        a.position = (0.0, 0.5)
        b = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.05))
        b.position = (0.0, 0.8)
        shapes = [pymunk.Circle(a, 0.05), pymunk.Circle(b, 0.05)]
        for s in shapes:
            s.elasticity = 1.0
        spring = pymunk.DampedSpring(a, b, (0, 0), (0, 0), 0.3, 100.0, 0.0)
        space.add(floor, a, b, *shapes, spring)
        return space

    def heat(self, space: Any = None) -> Any:
        from dumbbell import spaces

        return spaces.HeatCounter(space if space is not None else self.space())

    def recorder(self, space: Any = None) -> Any:
        from dumbbell import spaces

        return spaces.Recorder(space if space is not None else self.space(),
                               self.tmp / "rec.gif", fps=10, size="64x64")

    @functools.cached_property
    def space_energy(self) -> Any:
        from dumbbell import spaces

        return spaces.energy(self.space())

    @functools.cached_property
    def balance(self) -> Any:
        from dumbbell import spaces

        space = self.space()
        ledger = spaces.Ledger(space)
        for _ in range(40):
            space.step(0.01)
        return ledger.balance()

    @functools.cached_property
    def finding(self) -> Any:
        from dumbbell import spaces

        return spaces.check(self.space(), 1.0)[0]


def _arity(*values: Any) -> int:
    """How many arguments it was given (a job for ordered_map that takes anything)."""
    return len(values)


def fields(record: Any) -> dict[str, Any]:
    """The constructor arguments that rebuild a dataclass record."""
    return {f.name: getattr(record, f.name) for f in dataclasses.fields(record) if f.init}


#: Qualified name -> f -> keyword arguments that are valid (and cheap).
VALID: dict[str, Callable[[Fixtures], dict[str, Any]]] = {
    # dumbbell
    "dumbbell.model.scene.load_scene": lambda f: {"path": f.scene_file},
    "dumbbell.model.scene.Scene": lambda f: fields(f.scene),
    "dumbbell.model.scene.Scene.with_values": lambda f: {"values": {"spring.stiffness": 300.0}},
    # dumbbell.model
    "dumbbell.model.energy.angular_momentum_cm": lambda f: {"scene": f.rigid_2d,
                                                           "state": dict(f.traj_2d.state)},
    "dumbbell.model.energy.heat": lambda f: {
        "scene": f.scene, "t": f.traj.t, "state": dict(f.traj.state), "events": f.traj.events},
    "dumbbell.model.energy.partition": lambda f: {
        "scene": f.scene, "t": f.traj.t, "state": dict(f.traj.state), "events": f.traj.events},
    "dumbbell.model.scene.scene_from_dict": lambda f: {"data": f.scene.to_dict(),
                                                      "source": "x.toml"},
    "dumbbell.model.scene.scenes_dir": lambda f: {},
    # dumbbell.solvers: the registered classes' contract methods are found (:func:`_solver_rows`)
    "dumbbell.solvers.kernels.Kernel": lambda f: {
        "step": _module("dumbbell.solvers.kernels.euler_cromer").step,
        "floor": "flip", "start": None, "through_at_radius": False},
    "dumbbell.solvers.stepping.Stepper": lambda f: {},
    "dumbbell.solvers.exact_rigid.first_impact_state": lambda f: {
        "tilt": 30.0, "elasticity": 0.5, "mA": 0.1, "mB": 0.2, "length": 0.2, "height": 1.0,
        "g": 9.8},
    "dumbbell.solvers.simulate": lambda f: {
        "scene": f.scene, "solver": "exact", "dt": 1e-2, "t_end": 0.05, "every": 1,
        "quiet": True, "max_samples": 1000},
    "dumbbell.solvers.available": lambda f: {},
    "dumbbell.solvers.base.RunOptions": lambda f: {"dt": 1e-3, "t_end": 1.0, "every": 1,
                                                  "quiet": True},
    "dumbbell.solvers.base.Solver": lambda f: {},
    "dumbbell.solvers.base.RunOptions.sample_times": lambda f: {"count": 3},
    "dumbbell.model.trajectory.Trajectory": lambda f: fields(f.traj),
    "dumbbell.model.trajectory.Trajectory.first_impact": lambda f: {"body": "B"},
    "dumbbell.model.trajectory.Trajectory.to_csv": lambda f: {"path": f.tmp / "traj.csv"},
    "dumbbell.model.trajectory.Trajectory.__getitem__": lambda f: {"name": "E"},
    "dumbbell.model.trajectory.Impact": lambda f: fields(f.traj.events[0]),
    "dumbbell.model.trajectory.Verdict": lambda f: fields(f.traj.verdict),
    "dumbbell.model.trajectory.Contact": lambda f: {"t_start": 0.1, "t_end": 0.2, "body": "A"},
    "dumbbell.animation.render.render_gif": lambda f: {
        "traj": f.traj, "path": None, "quiet": True, "fps": 10, "size": "64x64",
        "strip": True, "t_end": 0.2, "timing": {}, "max_frames": 100},
    "dumbbell.animation.render.Gif": lambda f: {"data": b"GIF89a"},
    "dumbbell.animation.render.Gif.save": lambda f: {"path": f.tmp / "g.gif"},
    "dumbbell.animation.player.player": lambda f: {
        "source": f.traj, "fps": 10, "size": "64x64", "strip": True, "t_end": 0.2,
        "labels": ["x"], "max_samples": 1000},
    "dumbbell.animation.player.Player": lambda f: {"html_text": "<p>x</p>", "size": (64, 64)},
    "dumbbell.animation.player.Player.save": lambda f: {"path": f.tmp / "p.html"},
    "dumbbell.analysis.api.compare": lambda f: {
        "scene": f.scene, "solvers": ["euler-cromer"], "dts": [1e-3], "window": 0.02,
        "t_end": 0.02, "quiet": True},
    "dumbbell.analysis.api.bench": lambda f: {
        "scene": f.scene, "solvers": ["euler-cromer"], "dts": [1e-3], "window": 0.02,
        "repeat": 1, "t_end": 0.02, "budget": 10.0, "spacing": None, "quiet": True},
    "dumbbell.analysis.api.sweep": lambda f: {
        "scene": f.scene, "grid": {"k": [100.0, 200.0]}, "solver": "euler-cromer",
        "t_end": 0.02, "workers": 1, "scheduler": None, "quiet": True},
    "dumbbell.analysis.api.stability": lambda f: {
        "cases": f.scene_file.parent, "solvers": ["euler-cromer"], "workers": 1,
        "quiet": True},
    # dumbbell.analysis.bench
    "dumbbell.analysis.bench_result.BenchResult": lambda f: fields(f.bench_result),
    "dumbbell.analysis.bench_result.BenchResult.speedups": lambda f: {"target": 1e-3},
    "dumbbell.analysis.bench_result.Fit": lambda f: {"solver": "verlet", "order": 2.0,
                                              "log10_c": 1.0, "dts": [1e-3, 1e-4]},
    "dumbbell.analysis.bench_result.Point": lambda f: fields(f.bench_result.points[0]),
    # dumbbell.analysis.compare
    "dumbbell.analysis.compare.Comparison": lambda f: fields(f.comparison),
    "dumbbell.analysis.compare.Row": lambda f: fields(f.comparison.rows[0]),
    "dumbbell.analysis.compare.Timing": lambda f: {"seconds": 0.01, "warm_up": 0.5, "runs": 3},
    # dumbbell.analysis.contact
    "dumbbell.analysis.contact.ContactMomentum": lambda f: fields(f.contact),
    "dumbbell.analysis.contact.about_contact": lambda f: {"traj": f.traj_2d, "index": 0,
                                                         "window": 0.01},
    # dumbbell.analysis.restitution
    "dumbbell.analysis.restitution.Bounce": lambda f: {
        "e_first": 0.9, "e_cluster": 0.8, "impacts": 2, "share_first": 0.1,
        "share_cluster": 0.2},
    "dumbbell.analysis.restitution.RestitutionResult": lambda f: fields(f.restitution),
    "dumbbell.analysis.restitution.bounce": lambda f: {"traj": f.traj_2d, "gap": 0.05},
    "dumbbell.analysis.restitution.e_eff_rigid": lambda f: {"theta_deg": [0.0, 30.0],
                                                           "e": 1.0, "q": 1.0},
    "dumbbell.analysis.restitution.restitution": lambda f: {
        "scene": f.rigid_2d, "thetas": [10.0], "stiffnesses": (), "dt": 1e-3,
        "progress": lambda: None},
    # dumbbell.analysis.rotation
    "dumbbell.analysis.rotation.Series": lambda f: fields(f.series),
    "dumbbell.analysis.rotation.series": lambda f: {
        "scene": f.scene_2d, "solver": "pymunk", "dt": 1e-4, "t_end": 0.02,
        "stiffnesses": (200.0,)},
    # dumbbell.analysis.stability
    "dumbbell.analysis.stability.StabilityResult": lambda f: fields(f.stability_result),
    "dumbbell.analysis.stability.StabilityRow": lambda f: fields(f.stability_result.rows[0]),
    # dumbbell.analysis.sweep
    "dumbbell.analysis.sweep.Axis": lambda f: fields(f.sweep_result.axes[0]),
    "dumbbell.analysis.sweep.PointResult": lambda f: fields(f.sweep_result.rows[0]),
    "dumbbell.analysis.sweep.SweepResult": lambda f: fields(f.sweep_result),
    # dumbbell.analysis.topple
    "dumbbell.analysis.topple.ToppleClosedForm": lambda f: fields(f.topple_cf),
    "dumbbell.analysis.topple.ToppleClosedForm.alpha": lambda f: {"theta": [0.1, 0.5]},
    "dumbbell.analysis.topple.ToppleClosedForm.angle_curve": lambda f: {"n": 5},
    "dumbbell.analysis.topple.ToppleClosedForm.normal_force": lambda f: {"theta": 0.3},
    "dumbbell.analysis.topple.ToppleClosedForm.omega": lambda f: {"theta": np.array([0.2])},
    "dumbbell.analysis.topple.ToppleMeasure": lambda f: fields(f.topple_measure),
    "dumbbell.analysis.topple.closed_form": lambda f: {"scene": f.topple_scene},
    "dumbbell.analysis.topple.measure": lambda f: {"traj": f.topple_traj},
    # dumbbell.io
    "dumbbell.io.bench.markdown": lambda f: {"result": f.bench_result},
    "dumbbell.io.bench.write_all": lambda f: {"result": f.bench_result, "out": f.tmp / "b"},
    "dumbbell.io.compare.write": lambda f: {"result": f.comparison, "out": f.tmp / "c"},
    "dumbbell.io.compare.text": lambda f: {"result": f.comparison},
    "dumbbell.io.restitution.markdown": lambda f: {"result": f.restitution},
    "dumbbell.io.restitution.write_csv": lambda f: {"result": f.restitution,
                                                    "path": f.tmp / "r.csv"},
    "dumbbell.io.stability.markdown": lambda f: {"result": f.stability_result},
    "dumbbell.io.stability.write": lambda f: {"result": f.stability_result, "out": f.tmp / "s"},
    "dumbbell.io.sweep.write_csv": lambda f: {"result": f.sweep_result, "path": f.tmp / "s.csv"},
    "dumbbell.io.trajectory.dump_csv": lambda f: {"traj": f.traj, "stream": io.StringIO()},
    "dumbbell.io.trajectory.events_csv": lambda f: {"traj": f.traj},
    "dumbbell.io.trajectory.write_csv": lambda f: {"traj": f.traj, "path": f.tmp / "t.csv"},
    "dumbbell.io.trajectory.write_events": lambda f: {"traj": f.traj, "path": f.tmp / "e.csv"},
    # dumbbell.plot
    "dumbbell.plot.trajectory.positions": lambda f: {"traj": f.traj, "ax": f.ax(), "window": 0.3},
    "dumbbell.plot.trajectory.kinetic": lambda f: {"traj": f.traj, "ax": f.ax(), "window": 0.3},
    "dumbbell.plot.trajectory.potential": lambda f: {"traj": f.traj, "ax": f.ax(), "window": 0.3},
    "dumbbell.plot.trajectory.energy": lambda f: {"traj": f.traj_2d, "ax": f.ax(),
                                                  "window": 0.6},
    "dumbbell.plot.compare.compare": lambda f: {"result": f.comparison, "ax": f.ax()},
    "dumbbell.plot.compare.compare_positions": lambda f: {"result": f.comparison, "ax": f.ax()},
    "dumbbell.plot.compare.compare_energy": lambda f: {"result": f.comparison, "ax": f.ax()},
    "dumbbell.plot.bench.work_precision": lambda f: {"result": f.bench_result, "ax": f.ax()},
    "dumbbell.plot.bench.convergence": lambda f: {"result": f.bench_result, "ax": f.ax()},
    "dumbbell.plot.maps.sweep_map": lambda f: {"result": f.sweep_result, "ax": f.ax()},
    "dumbbell.plot.maps.stability_map": lambda f: {"maps": f.maps},
    "dumbbell.plot.rotation.rotation": lambda f: {"s": f.series, "ax": f.ax()},
    "dumbbell.plot.rotation_chapter.restitution": lambda f: {"result": f.restitution,
                                                             "ax": f.ax(3)},
    "dumbbell.plot.rotation_chapter.topple": lambda f: {
        "cf": f.topple_cf, "measured": f.topple_measure, "ax": f.ax(3), "solver": "pymunk"},
    "dumbbell.plot.rotation_chapter.contact_momentum": lambda f: {
        "cm": f.contact, "ax": f.ax(), "solver": "exact"},
    # dumbbell.spaces.accounting
    "dumbbell.spaces.accounting.energy": lambda f: {"space": f.space(), "about": (0.0, 0.0)},
    "dumbbell.spaces.accounting.SpaceEnergy": lambda f: fields(f.space_energy),
    "dumbbell.spaces.accounting.BodyEnergy": lambda f: fields(f.space_energy.bodies[0]),
    "dumbbell.spaces.accounting.SpringEnergy": lambda f: fields(f.space_energy.springs[0]),
    "dumbbell.spaces._what_counts.Skipped": lambda f: {"subject": "body 0", "reason": "static"},
    # dumbbell.spaces.guard
    "dumbbell.spaces.guard.check": lambda f: {"space": f.space(), "dt": 1e-3, "speeds": "both",
                                              "tolerance": 0.01, "units": "m"},
    "dumbbell.spaces.guard.survey": lambda f: {"space": f.space(), "dt": 1e-3,
                                               "speeds": "state", "tolerance": math.inf,
                                               "units": None},
    "dumbbell.spaces.guard.substeps": lambda f: {"space": f.space(), "dt": 1e-2,
                                                 "speeds": "energy", "tolerance": 0.1,
                                                 "units": "m"},
    "dumbbell.spaces.guard.suggest_dt": lambda f: {"space": f.space(), "dt": 1e-2,
                                                   "speeds": "both", "tolerance": 0.01,
                                                   "units": "m"},
    "dumbbell.spaces.guard.report": lambda f: {"space": f.space(), "dt": 1e-2, "speeds": "both",
                                               "tolerance": 0.01, "units": "px"},
    "dumbbell.spaces._springs_dt.energy_swing": lambda f: {"w_dt": 0.5},
    "dumbbell.spaces.estimates.reach": lambda f: {"space": f.space(), "dt": 1e-3, "units": "m"},
    "dumbbell.spaces.estimates.Reach": lambda f: fields(
        importlib.import_module("dumbbell.spaces").reach(f.space(), 1e-3)[0]),
    "dumbbell.spaces.stepping.step": lambda f: {"space": f.space(), "dt": 1e-2, "substeps": 2},
    "dumbbell.spaces._springs_dt.spring_omega": lambda f: {
        "spring": next(iter(f.space().constraints))},
    "dumbbell.spaces.guard.shape_size": lambda f: {"shape": next(iter(f.space().shapes))},
    "dumbbell.spaces._finding.Finding": lambda f: fields(f.finding),
    "dumbbell.spaces.stepping.Driver": lambda f: {"space": f.space(), "dt": 1e-2, "substeps": None,
                                               "speeds": "both", "tolerance": math.inf},
    "dumbbell.spaces.stepping.Driver.step": lambda f: {"frames": 2},
    # dumbbell.spaces.heat, recorder
    "dumbbell.spaces.heat.HeatCounter": lambda f: {"space": f.space()},
    # dumbbell.spaces.ledger, balance
    "dumbbell.spaces.ledger.Ledger": lambda f: {"space": f.space(), "tolerance": 1e-6},
    "dumbbell.spaces.ledger.Ledger.declare_potential": lambda f: {
        "target": list(f.space().bodies), "potential": lambda x, y, m: 0.0 * x,
        "name": "field"},
    "dumbbell.spaces.balance.Balance": lambda f: fields(f.balance),
    "dumbbell.spaces.balance.Balance.sources": lambda f: {"kind": "contact", "at_least": 0.0},
    "dumbbell.spaces.balance.Balance.table": lambda f: {"top": 4},
    "dumbbell.spaces.balance.Term": lambda f: fields(f.balance.terms[0]),
    "dumbbell.spaces.recorder.Recorder": lambda f: _recorder_args(f),
    "dumbbell.spaces.recorder.Recorder.capture": lambda f: {"t": None},
    "dumbbell.spaces._draw.PaletteDrawOptions": lambda f: {},
    "dumbbell.spaces._draw.PaletteDrawOptions.capture": lambda f: {"space": f.space()},
    "dumbbell.spaces._draw.PaletteDrawOptions.ink_of": lambda f: {
        "body": next(iter(f.space().bodies))},
    "dumbbell.spaces.recorder.draw_options": lambda f: {},
}


def _solver_rows() -> dict[str, Callable[[Fixtures], dict[str, Any]]]:
    """Valid arguments of every registered solver class and of its contract methods: a
    scene it can run (the first of a 1D, a 2D spring and a rigid 2D scene), the run options,
    and for one that estimates its own error, no second run."""

    def scene_for(cls: type) -> Callable[[Fixtures], Any]:
        def scene(f: Fixtures) -> Any:
            return next(s for s in (f.scene, f.scene_2d, f.rigid_2d)
                        if cls._supports(s) is None)
        return scene

    rows: dict[str, Callable[[Fixtures], dict[str, Any]]] = {}
    for cls in _solvers():
        key, scene = f"{cls.__module__}.{cls.__qualname__}", scene_for(cls)
        extra = {"estimate_error": False} if cls.estimates_error else {}
        for method in ("supports", "truth_for", "catch_depth"):
            rows[f"{key}.{method}"] = lambda f, scene=scene: {"scene": scene(f)}
        rows[f"{key}.solve"] = (lambda f, scene=scene, extra=extra:
                                {"scene": scene(f), "options": f.options, **extra})
        rows[f"{key}.check_work"] = lambda f, scene=scene: {"scene": scene(f),
                                                            "options": f.options}
        if hasattr(cls, "kernel"):
            rows[f"{key}.kernel"] = (lambda f, scene=scene:
                                     {"dimensions": scene(f).system.dimensions})
        rows[f"{key}.swing"] = lambda f: {"ratio": 1.5}
    return rows


VALID.update(_solver_rows())

#: Method case -> f -> the object whose method it is (fresh at each call).
OWNER: dict[str, Callable[[Fixtures], Any]] = {
    "dumbbell.spaces.stepping.Driver.step": lambda f: importlib.import_module("dumbbell.spaces").Driver(
        f.space(), 1e-2, 1),
    "dumbbell.spaces.ledger.Ledger.declare_potential": lambda f: importlib.import_module(
        "dumbbell.spaces").Ledger(f.space()),
    "dumbbell.spaces.balance.Balance.sources": lambda f: f.balance,
    "dumbbell.spaces.balance.Balance.table": lambda f: f.balance,
    "dumbbell.model.scene.Scene.with_values": lambda f: f.scene,
    "dumbbell.solvers.base.RunOptions.sample_times":
        lambda f: importlib.import_module("dumbbell.solvers").RunOptions(1e-3, 1.0, 10),
    "dumbbell.spaces.recorder.Recorder.capture": lambda f: f.recorder(),
    "dumbbell.spaces._draw.PaletteDrawOptions.capture":
        lambda f: importlib.import_module("dumbbell.spaces").draw_options(),
    "dumbbell.spaces._draw.PaletteDrawOptions.ink_of":
        lambda f: importlib.import_module("dumbbell.spaces").draw_options(),
    "dumbbell.model.trajectory.Trajectory.first_impact": lambda f: f.traj,
    "dumbbell.model.trajectory.Trajectory.to_csv": lambda f: f.traj,
    "dumbbell.model.trajectory.Trajectory.__getitem__": lambda f: f.traj,
    "dumbbell.animation.render.Gif.save": lambda f: __import__("dumbbell").Gif(b"GIF89a"),
    "dumbbell.animation.player.Player.save": lambda f: __import__("dumbbell").Player("<p></p>"),
    "dumbbell.analysis.bench_result.BenchResult.speedups": lambda f: f.bench_result,
    "dumbbell.analysis.topple.ToppleClosedForm.alpha": lambda f: f.topple_cf,
    "dumbbell.analysis.topple.ToppleClosedForm.angle_curve": lambda f: f.topple_cf,
    "dumbbell.analysis.topple.ToppleClosedForm.normal_force": lambda f: f.topple_cf,
    "dumbbell.analysis.topple.ToppleClosedForm.omega": lambda f: f.topple_cf,
}


def test_every_public_module_declares_its_api():
    assert [m.__name__ for m in _modules() if not hasattr(m, "__all__")] == []


#: The documents of the public API: every public callable is named in code in one of them.
API_DOCS = ("docs/api.md", "docs/spaces.md", "docs/spaces-reference.md")


def _code_in(path: Path) -> str:
    """The code of a Markdown file: its fenced blocks and its inline code spans."""
    text = path.read_text(encoding="utf-8")
    blocks = re.findall(r"^```[^\n]*\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)
    prose = re.sub(r"^```[^\n]*\n.*?^```", "", text, flags=re.MULTILINE | re.DOTALL)
    return "\n".join(blocks + re.findall(r"`([^`\n]+)`", prose))


def test_every_public_callable_is_documented():
    """Each public callable's name (a method's too) stands in code in docs/api.md,
    docs/spaces.md or docs/spaces-reference.md; ``__getitem__`` is documented as ``traj[name]``."""
    root = Path(__file__).resolve().parent.parent
    code = "\n".join(_code_in(root / doc) for doc in API_DOCS)
    names = {key.rsplit(".", 1)[1] for key in public()} - {"__getitem__"}
    assert sorted(n for n in names if not re.search(rf"\b{re.escape(n)}\b", code)) == []
    assert "traj[" in code


def test_every_public_callable_has_valid_arguments():
    found = set(public())
    assert sorted(found - set(VALID)) == [], "public callables without a row in VALID"
    assert sorted(set(VALID) - found) == [], "rows in VALID that are not public callables"


def _target(key: str, f: Fixtures) -> Any:
    if key in OWNER:
        return getattr(OWNER[key](f), key.rsplit(".", 1)[1])
    return public()[key]


def names(message: str, name: str, value: Any) -> bool:
    """True when ``message`` names the argument ``name``; a path given as a str may be named
    by itself instead, as every message about a file starts ('text: no such scene file')."""
    return name in message or (isinstance(value, str) and message.startswith(f"{value}:"))


def _close_figures() -> None:
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


@pytest.mark.parametrize("key", sorted(VALID))
def test_hostile_arguments_are_refused_naming_them(key, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a hostile "text" path is written here, if accepted
    f = Fixtures(tmp_path)
    params = _parameters(_target(key, f))
    _target(key, f)(**VALID[key](f))  # the row itself is valid
    _close_figures()
    failures = []
    for name in params:
        for bad in HOSTILE:
            kwargs = VALID[key](f)
            kwargs[name] = bad
            try:
                _target(key, f)(**kwargs)
            except DumbbellError as exc:
                if not names(str(exc), name, bad):
                    failures.append(f"{name}={bad!r}: {type(exc).__name__} does not name "
                                    f"{name!r}: {exc}")
                elif "\n" in str(exc):
                    failures.append(f"{name}={bad!r}: more than one line: {exc!r}")
            except Exception as exc:  # noqa: BLE001 - the point: no other exception may escape
                failures.append(f"{name}={bad!r}: {type(exc).__name__}: {exc}")
            finally:
                _close_figures()
    assert not failures, f"{key}:\n" + "\n".join(failures)


# --- numpy scalars are numbers ---------------------------------------------------------------


def _numpy(value: Any) -> Any:
    """``value`` with every float as np.float32 and every int as np.int64 (bools kept), in
    lists and tuples too."""
    if isinstance(value, bool):
        return value
    if isinstance(value, float):
        return np.float32(value)
    if isinstance(value, int):
        return np.int64(value)
    if isinstance(value, list | tuple) and not hasattr(value, "_fields"):
        return type(value)(_numpy(v) for v in value)
    return value


def test_numpy_scalars_are_taken_wherever_numbers_are(tmp_path, monkeypatch):
    """Every row of VALID whose arguments hold numbers, called with np.float32 and np.int64
    in their place (in lists and tuples too): it must succeed."""
    monkeypatch.chdir(tmp_path)
    f = Fixtures(tmp_path)
    checked, failures = [], []
    for key in sorted(VALID):
        kwargs = VALID[key](f)
        numpy_kwargs = {name: _numpy(value) for name, value in kwargs.items()}
        if all(numpy_kwargs[n] is kwargs[n] for n in kwargs):
            continue  # no number among the arguments
        checked.append(key)
        try:
            _target(key, f)(**numpy_kwargs)
        except Exception as exc:  # noqa: BLE001 - any refusal of a number is the failure
            failures.append(f"{key}: {type(exc).__name__}: {exc}")
        finally:
            _close_figures()
    assert not failures, "\n".join(failures)
    assert len(checked) >= 75, checked


def test_numpy_scalars_give_what_the_equal_python_numbers_give(tmp_path):
    from dumbbell import spaces
    from dumbbell.analysis.restitution import e_eff_rigid, sign_change_deg
    from dumbbell.animation.render import delays_cs, sample_every

    f = Fixtures(tmp_path)
    dt = np.float32(1 / 60)
    assert spaces.suggest_dt(f.space(), dt) == spaces.suggest_dt(f.space(), float(dt))
    a, b = f.space(), f.space()
    spaces.step(a, dt, np.int64(3))
    spaces.step(b, float(dt), 3)
    assert [tuple(x.position) for x in a.bodies] == [tuple(x.position) for x in b.bodies]
    assert spaces.energy(a, about=np.array([0.5, 1.0])) == spaces.energy(b, about=(0.5, 1.0))
    e = np.float32(0.5)
    assert e_eff_rigid(np.float64(30.0), e, np.int64(1)) == e_eff_rigid(30.0, float(e), 1)
    assert sign_change_deg(e, np.int64(1)) == sign_change_deg(float(e), 1)
    assert f.topple_cf.omega(np.float32(0.3)) == f.topple_cf.omega(float(np.float32(0.3)))
    assert delays_cs(np.int64(7), np.int64(30)) == delays_cs(7, 30)
    assert sample_every(np.float32(1e-4), np.int64(25), np.float64(2.0)) == sample_every(
        float(np.float32(1e-4)), 25, 2.0)


# --- wrong kinds beyond the hostile values -------------------------------------------------


def _module(name: str) -> Any:
    return importlib.import_module(name)


def _pymunk() -> Any:
    import pymunk

    return pymunk


def _recorder_args(f: Fixtures) -> dict[str, Any]:
    """Valid arguments of every parameter of spaces.Recorder: its heat counter on its space."""
    space = f.space()
    return {"space": space, "path": f.tmp / "r.gif", "fps": 10, "energy": True,
            "size": "64x64", "strip": False, "heat": f.heat(space),
            "world": (-1.0, 1.0, -0.2, 1.0), "camera": "auto", "span": None, "y_up": None,
            "units": ("m", "kg", "s"), "reference": "start", "t0": 0.0, "title": "t",
            "about": (0.0, 0.0)}


WRONG_KINDS: dict[str, tuple[Callable[[Fixtures], Any], str]] = {
    "a Body for a space": (lambda f: importlib.import_module("dumbbell.spaces").energy(
        _pymunk().Body(1, 1)), "space"),
    "a Body for the heat counter's space": (lambda f: importlib.import_module("dumbbell.spaces").HeatCounter(
        _pymunk().Body(1, 1)), "space"),
    "a Space for a heat counter": (lambda f: importlib.import_module("dumbbell.spaces").Recorder(
        f.space(), f.tmp / "r.gif", heat=f.space()), "heat"),
    "a PinJoint for a spring": (lambda f: importlib.import_module("dumbbell.spaces.guard").spring_omega(
        _pymunk().PinJoint(_pymunk().Body(1, 1), _pymunk().Body(1, 1))), "spring"),
    "a Body for a shape": (lambda f: importlib.import_module("dumbbell.spaces").shape_size(
        _pymunk().Body(1, 1)), "shape"),
    "endless frames": (lambda f: importlib.import_module("dumbbell.spaces").Driver(
        f.space(), 1e-3, 1).step(10**12), "frames"),
    "a step needing endless sub-steps": (lambda f: importlib.import_module("dumbbell.spaces").substeps(
        f.space(), 1e308), "dt"),
    "a Figure for an Axes": (lambda f: importlib.import_module("dumbbell.plot").kinetic(
        f.traj, ax=f.ax().figure), "ax"),
    "one Axes for three": (lambda f: importlib.import_module("dumbbell.plot").restitution(
        f.restitution, ax=f.ax()), "ax"),
    "two Axes for three": (lambda f: importlib.import_module("dumbbell.plot").topple(
        f.topple_cf, f.topple_measure, ax=f.ax(3)[:2]), "ax"),
    "an Axes for a figure": (lambda f: importlib.import_module("dumbbell.io.figures")
                             .save_figure(f.ax(), f.tmp / "x.png"), "fig"),
    "a figure file without a format": (lambda f: importlib.import_module("dumbbell.io.figures")
                                       .save_figure(f.ax().figure, f.tmp / "x.part"), "path"),
    "a huge dpi": (lambda f: importlib.import_module("dumbbell.io.figures").save_figure(
        f.ax().figure, f.tmp / "x.png", dpi=1e6), "dpi"),
    "a 1D run for the topple": (lambda f: importlib.import_module("dumbbell.analysis.topple")
                                .measure(f.traj), "traj"),
    "a 1D run for a tilted drop": (lambda f: importlib.import_module(
        "dumbbell.analysis.restitution").bounce(f.traj), "traj"),
    "a 1D run for the rigid closed form": (lambda f: importlib.import_module(
        "dumbbell.analysis.extended").extended_precision_rigid(f.traj, 0.1), "traj"),
    "a 2D run for the 1D closed form": (lambda f: importlib.import_module(
        "dumbbell.analysis.extended").extended_precision_exact(f.traj_2d, 0.1), "traj"),
    "a 1D truth for a 2D run": (lambda f: importlib.import_module("dumbbell.analysis.metrics")
                                .position_error(f.traj_2d, f.traj, 0.1), "truth"),
    "a Body for an example's space": (lambda f: importlib.import_module(
        "dumbbell.examples.pendulum").measure(1e-3, 0.04, space=_pymunk().Body(1, 1)),
        "space"),
    "endless seconds": (lambda f: importlib.import_module("dumbbell.examples.newtons_cradle")
                        .measure(1e-3, 1e300), "seconds"),
    "a scene file that is not there": (lambda f: __import__("dumbbell").simulate(
        f.tmp / "none.toml"), "scene"),
    "frames past the floats": (lambda f: importlib.import_module("dumbbell.animation.render")
                               .frame_count(1e300, 25), "t_end"),
    "a column that is not there": (lambda f: f.traj["K_rot"], "name"),
    "a body that is not there": (lambda f: f.traj.first_impact("C"), "body"),
    "a status that is no verdict": (lambda f: _module("dumbbell.model.trajectory").Verdict(
        "banana"), "status"),
    "an impact of a third body": (lambda f: _module("dumbbell.model.trajectory").Impact(
        0.1, "C", -1.0, 1.0), "body"),
    "an impact at an infinite time": (lambda f: _module("dumbbell.model.trajectory").Impact(
        math.inf, "A", -1.0, 1.0), "t"),
    "a failure at NaN s": (lambda f: _module("dumbbell.model.trajectory").Verdict(
        "failed", math.nan, "why"), "t"),
    "run options with a NaN step": (lambda f: _module("dumbbell.solvers").RunOptions(
        math.nan, 1.0), "dt"),
    "a 2D spring scene for the exact solver": (lambda f: _module("dumbbell.solvers").METHODS[
        "exact"].solve(f.scene_2d, f.options), "scene"),
    "a 2D spring scene for the exact solver's budget": (lambda f: _module(
        "dumbbell.solvers").METHODS["exact"].check_work(f.scene_2d, f.options), "scene"),
    "an elasticity of 2": (lambda f: _module("dumbbell.solvers.exact_rigid")
                           .first_impact_state(30.0, 2.0), "elasticity"),
    "a negative mass": (lambda f: _module("dumbbell.solvers.exact_rigid")
                        .first_impact_state(30.0, 0.5, mA=-0.1), "mA"),
    "a NaN tilt": (lambda f: _module("dumbbell.solvers.exact_rigid")
                   .first_impact_state(math.nan, 0.5), "tilt"),
    "energy columns without E": (lambda f: _module("dumbbell.model.energy")
                                 .relative_energy_error({"K_cm": f.traj["K_cm"]}), "energy"),
    "a 1D scene for L_cm": (lambda f: _module("dumbbell.model.energy").angular_momentum_cm(
        f.scene, dict(f.traj.state)), "scene"),
    "a spring scene for the rigid moment": (lambda f: _module("dumbbell.model.energy")
                                            .rigid_moment(f.scene), "scene"),
    "a state without a column": (lambda f: _module("dumbbell.model.energy").partition(
        f.scene, f.traj.t, {"xA": f.traj["xA"]}), "state"),
    "columns shorter than t": (lambda f: _module("dumbbell.model.energy").partition(
        f.scene, f.traj.t[:-1], dict(f.traj.state)), "state"),
    "a size that is no size": (lambda f: _module("dumbbell.model.scene").parse_size("64x"),
                               "text"),
    "a scene name with a folder": (lambda f: _module("dumbbell.model.scene").packaged_scene(
        "../textbook-1d"), "name"),
    "a numpy float for whole workers": (lambda f: _module("dumbbell.parallel").cap_workers(
        np.float64(2.0), 3), "workers"),
}


@pytest.mark.parametrize("case", sorted(WRONG_KINDS))
def test_wrong_kinds_are_refused_naming_the_argument(case, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    call, argument = WRONG_KINDS[case]
    try:
        with pytest.raises(DumbbellError) as info:
            call(Fixtures(tmp_path))
    finally:
        _close_figures()
    assert argument in str(info.value) and "\n" not in str(info.value)
