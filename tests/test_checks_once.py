"""Arguments are checked once, at the border: the top-level functions check what they are
given, and inside, the typed frozen values (Scene, RunOptions, the analyses' options records,
solver classes) pass unchecked. Counted here as calls into ``dumbbell.model.args`` from
outside it, the way a profiler sees them (so a check imported by name counts too)."""

from __future__ import annotations

import collections
import sys
from collections.abc import Callable
from typing import Any

import pytest

import dumbbell
from dumbbell.model import args
from tests.conftest import SCENES

TEXTBOOK = SCENES / "textbook-1d.toml"


def checks(call: Callable[[], Any]) -> collections.Counter:
    """The calls into model/args.py from outside it while ``call()`` runs, by (check, caller)."""
    counts: collections.Counter = collections.Counter()
    here = args.__file__

    def profile(frame: Any, event: str, _arg: Any) -> None:
        if event == "call" and frame.f_code.co_filename == here:
            caller = frame.f_back
            if caller is not None and caller.f_code.co_filename != here:
                counts[(frame.f_code.co_name, caller.f_code.co_name)] += 1

    before = sys.getprofile()
    sys.setprofile(profile)
    try:
        call()
    finally:
        sys.setprofile(before)
    return counts


def test_the_counter_counts_a_check():
    # The counter itself can fail: a public function that checks is seen doing it.
    assert sum(checks(lambda: dumbbell.model.energy.disc_inertia(0.1, 0.02)).values()) == 2
    assert sum(checks(lambda: None).values()) == 0


@pytest.mark.parametrize("call,most", [
    (lambda s: dumbbell.simulate(s, t_end=0.2), 5),
    (lambda s: dumbbell.simulate(TEXTBOOK, "verlet", t_end=0.2, every=10), 5),
    (lambda s: dumbbell.simulate(s, "exact", dt=1e-3, t_end=0.5, every=1, quiet=True), 5),
])
def test_a_simulation_checks_its_arguments_once(textbook, call, most):
    found = checks(lambda: call(textbook))
    assert sum(found.values()) <= most, found
    # Each is the border's own: simulate's, and the run options' it was given.
    assert {caller for _, caller in found} <= {"simulate", "make_options", "scene_options"}, found


def test_a_comparison_checks_its_arguments_once(textbook):
    found = checks(lambda: dumbbell.compare(textbook, t_end=0.5, window=0.5))
    # Its own border (the scene, the options), then the pymunk run's use of the public
    # dumbbell.spaces toolkit on the space it builds (inventory, evaluate, heat counter).
    ours = {key: n for key, n in found.items() if key[1] in ("compare",)}
    assert sum(ours.values()) <= 2, found
    assert sum(found.values()) <= 15, found


def test_checks_do_not_grow_with_the_runs(textbook):
    def compare(dts: list[float]) -> int:
        return sum(checks(lambda: dumbbell.compare(
            textbook, solvers=["euler-cromer", "verlet"], dts=dts, t_end=0.3,
            window=0.3)).values())

    # The scene, the options record, and the list of steps: not once per run.
    one, three = compare([1e-3]), compare([1e-3, 5e-4, 2.5e-4])
    assert one == three <= 3
    bench = checks(lambda: dumbbell.bench(textbook, solvers=["euler-cromer"],
                                          dts=[1e-3, 5e-4], t_end=0.1, window=0.1, repeat=1))
    assert sum(bench.values()) <= 3, bench


def test_dumbbell_run_checks_the_fps_and_the_scene_once_on_the_way_to_its_gif(tmp_path):
    # Each value is checked where it enters: the scene (and its GIF's fps) when the file is
    # read; from there to the GIF's bytes nothing checks them again (issue 32: the fps was
    # checked 9 times on this path, the scene 4 times more).
    import re

    from dumbbell.animation import timing
    from dumbbell.cli import main
    from dumbbell.model import checker
    from dumbbell.model import scene as scene_module

    text = re.sub(r"\[outputs\][\s\S]*", "", TEXTBOOK.read_text())
    path = tmp_path / "gif-only.toml"
    path.write_text(text + '\n[outputs]\nfigures = []\ncsv = false\n[outputs.gif]\nfps = 10\n'
                    'size = "160x90"\nt_end = 0.2\n')
    counts: collections.Counter = collections.Counter()

    def profile(frame: Any, event: str, _arg: Any) -> None:
        if event != "call":
            return
        code = frame.f_code
        if code.co_filename == timing.__file__ and code.co_name == "check_fps":
            counts["fps"] += 1
        elif (code.co_filename == checker.__file__ and code.co_name == "integer"
              and frame.f_locals.get("name") == "fps"):
            counts["fps"] += 1  # the scene reader's check of outputs.gif.fps
        elif code.co_filename == args.__file__ and code.co_name in ("scene", "trajectory"):
            counts["scene"] += 1
        elif code.co_filename == scene_module.__file__ and code.co_name == "load_scene":
            counts["scene"] += 1  # the scene read and checked from its file

    sys.setprofile(profile)
    try:
        status = main(["run", str(path), "--out", str(tmp_path / "out"), "-q"])
    finally:
        sys.setprofile(None)
    assert status == 0 and (tmp_path / "out" / "gif-only.gif").stat().st_size > 0
    assert counts == {"fps": 1, "scene": 1}, counts
