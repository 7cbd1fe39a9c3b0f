"""Shared fixtures: the shipped scenes and small scene builders."""

from __future__ import annotations

import contextlib
import copy
import functools
import importlib.util
import sys
from pathlib import Path

import pytest

from dumbbell.model.scene import Scene, load_scene, load_scene_file, scene_from_dict

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


#: Tilts (degrees) at which the rotation chapter drops its rigid dumbbell: the rotation page's
#: tables (``dumbbell restitution scenes/tilted-2d.toml --theta 0,30,45,60,80``).
DROP_ANGLES = (0.0, 30.0, 45.0, 60.0, 80.0)


@functools.cache
def rotation_table(e: float):
    """What ``dumbbell restitution scenes/tilted-2d.toml --theta 0,30,45,60,80 --elasticity
    E`` computes, for E = ``e`` (the analysis the command runs): the rigid dumbbell dropped
    at each of :data:`DROP_ANGLES` in the truth and in pymunk at dt = 1e-5 s (its ``pymunk``
    column is each drop's first bounce), and the spring dumbbells. Shared by the rotation
    page's tables (test_doc_numbers) and the pymunk column's check against the impulse law
    (test_rotation_chapter), which xdist runs in one process (:data:`SHARED_SCOPE`); its
    pymunk drops at the showcase's tilts are kept for the showcase's restitution piece
    (:func:`drops_made_once`)."""
    from dumbbell.analysis.restitution import restitution

    # Named as the page's command names it (and as the showcase's packaged scene is).
    scene = load_scene_file(SCENES / "tilted-2d.toml", "scenes/tilted-2d.toml")
    with drops_made_once():
        return restitution(scene.with_values({"floor.elasticity": e}), list(DROP_ANGLES))


#: Tests that share :func:`rotation_table`'s runs, put by xdist's loadscope into the scope
#: of tests/test_doc_numbers.py (one process): module file -> test function.
SHARED_SCOPE = {"test_rotation_chapter.py": "test_rigid_pymunk_against_impulse_law",
                "test_showcase.py": "test_each_piece_writes_the_tracked_bytes_again[restitution "}


def _showcase_drops() -> frozenset:
    """The drops (tilted scenes, rigid and with each spring) that :func:`rotation_table` and
    the showcase's restitution piece (``dumbbell restitution tilted-2d --elasticity 0.5``)
    both make: those of the piece's tilts that are in :data:`DROP_ANGLES`."""
    from dumbbell.analysis.restitution import tilted
    from dumbbell.cli.showcase import PIECES, parse

    piece = next(p for p in PIECES if p.argv[0] == "restitution")
    args = parse(piece, Path("unused"), quiet=True)
    base = args.scene.with_values({"floor.elasticity": args.elasticity})
    return frozenset(tilted(base, theta, k) for theta in set(DROP_ANGLES) & set(args.theta)
                     for k in (None, *args.stiffness))


#: pymunk runs of :func:`_showcase_drops` made by :func:`drops_made_once`, until asked again.
_DROPS: dict[tuple, object] = {}


@contextlib.contextmanager
def drops_made_once():
    """While this lasts, ``dumbbell.solvers.simulate`` (what ``restitution()`` calls) makes a
    pymunk run of a drop of :func:`_showcase_drops` once per process: the first call keeps
    the run, the second call with the same arguments gets that run (and it is forgotten).
    A pymunk run is deterministic: the same scene and options give the same numbers, so
    the second caller computes from the run it would have made. Every other call runs."""
    from dumbbell import solvers

    simulate = solvers.simulate
    drops = _showcase_drops()

    def remembered(scene, solver=None, **options):
        if solver != "pymunk" or scene not in drops:
            return simulate(scene, solver, **options)
        key = (scene, tuple(sorted(options.items())))
        if key in _DROPS:
            return _DROPS.pop(key)
        _DROPS[key] = traj = simulate(scene, solver, **options)
        return traj

    solvers.simulate = remembered
    try:
        yield
    finally:
        solvers.simulate = simulate


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """loadscope, with the tests of :data:`SHARED_SCOPE` in tests/test_doc_numbers.py's scope
    (the same worker), so that :func:`rotation_table`'s runs are made once."""
    if config.getvalue("dist") != "loadscope":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class Shared(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path, _, test = nodeid.partition("::")
            folder, _, name = path.rpartition("/")
            if name in SHARED_SCOPE and test.startswith(SHARED_SCOPE[name]):
                return f"{folder}/test_doc_numbers.py"
            return super()._split_scope(nodeid)

    return Shared(config, log)
