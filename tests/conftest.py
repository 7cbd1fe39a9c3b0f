"""Shared fixtures: the shipped scenes and small scene builders."""

from __future__ import annotations

import copy
import functools
import importlib.util
import sys
from pathlib import Path

import pytest

from dumbbell.model.scene import Scene, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parent.parent


def load_tool(name: str):
    """The module ``tools/NAME.py``, loaded once per session: its dataclasses look their
    module up in ``sys.modules`` (a second load would give classes that do not pickle)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]
SCENES = ROOT / "scenes"


@pytest.fixture(autouse=True)
def _no_process_outlives_its_test():
    """Kill what a test started and left running, pass or fail (a subprocess it gave up on,
    that process's own children), so that one failed test does not make the next ones fail
    on ``assert not own_children()``. A test that checks for leftovers checks before this
    runs; processes that were there before the test (a module's fixture, multiprocessing's
    resource tracker) are left alone."""
    import psutil

    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    yield
    left = []
    for p in me.children(recursive=True):
        try:
            if p.pid not in before and \
                    "multiprocessing.resource_tracker" not in " ".join(p.cmdline()):
                p.kill()
                left.append(p)
        except psutil.NoSuchProcess:
            pass
    psutil.wait_procs(left, timeout=60)


#: The textbook's scene as a dict, for tests that vary it.
TEXTBOOK = {
    "title": "textbook",
    "dimensions": 1,
    "bodies": {"A": {"mass": 0.1, "height": 1.2}, "B": {"mass": 0.1, "height": 1.0}},
    "spring": {"stiffness": 200.0, "rest_length": 0.2},
    "floor": {"elasticity": 1.0},
    "gravity": {"g": 9.8},
    "run": {"t_end": 10.0, "dt": 1e-5, "solver": "euler-cromer"},
}


def make_scene(changes: dict | None = None, drop: tuple[str, ...] = (), base: dict | None = None
               ) -> Scene:
    """The textbook scene with dotted keys changed and top-level tables dropped."""
    raw = copy.deepcopy(base or TEXTBOOK)
    for table in drop:
        raw.pop(table)
    scene = scene_from_dict(raw, source="test.toml")
    return scene.with_values(changes) if changes else scene


@pytest.fixture(scope="session")
def textbook() -> Scene:
    """The shipped scenes/textbook-1d.toml."""
    return load_scene(SCENES / "textbook-1d.toml")


#: Tilts (degrees) at which the rotation chapter drops its rigid dumbbell.
DROP_ANGLES = (0.0, 30.0, 45.0, 60.0, 80.0)


@functools.cache
def rigid_pymunk_drops(e: float) -> dict[float, object]:
    """The rigid dumbbell of scenes/tilted-2d.toml dropped on a floor of restitution ``e`` at
    each of :data:`DROP_ANGLES` in pymunk at dt = 1e-5 s, every step kept, as ``dumbbell
    restitution`` drops it: tilt -> Trajectory. Shared by the tests that read the first
    bounce (the runs take seconds)."""
    from dumbbell.analysis.restitution import drop_duration, tilted
    from dumbbell.solvers import simulate

    scene = load_scene(SCENES / "tilted-2d.toml").with_values({"floor.elasticity": e})
    out = {}
    for theta in DROP_ANGLES:
        s = tilted(scene, theta)
        out[theta] = simulate(s, "pymunk", t_end=drop_duration(s), every=1, dt=1e-5)
    return out
