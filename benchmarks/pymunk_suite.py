"""pymunk's own test suite with a spaces.Ledger and a spaces.HeatCounter attached to every
Space it creates, against the bare suite; and what attaching a ledger costs every later
``gc.collect()`` and the process's memory.

    python benchmarks/pymunk_suite.py                 # both runs, the comparison, the costs
    python benchmarks/pymunk_suite.py --run bare      # one run, its results as JSON
    python benchmarks/pymunk_suite.py --run ledgers

Each run is a subprocess of its own (an abort would end that run only, and show as its
exit status), running every test of ``pymunk.tests`` (from the installed pymunk: its unit
tests and doctests, as ``python -m pymunk.tests`` runs them). The ``ledgers`` run wraps
``pymunk.Space.__init__`` so that every space, the moment it is made, gets
``space.dumbbell_ledger = spaces.Ledger(space)`` and ``space.dumbbell_heat =
spaces.HeatCounter(space)``: kept on the space (a reference cycle, copied and pickled with
it), so that pymunk's own copies, pickles, removals, callbacks and collections meet them.
Printed: tests run, failed and errored in each run and which fail only with the ledgers;
wall time of each run (its tests only, interpreter start apart); the spaces made and the
ledgers still counting or stopped.

Then the costs, each measured in a fresh subprocess that builds 50 spaces of 20 bouncing
balls and steps each 50 times (bare; with the ledger's modules imported but none attached;
with a ledger kept on each space): the median of 20 ``gc.collect()`` calls afterwards, and
the process's resident memory (VmRSS) and its peak (VmHWM).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: What the ``ledgers`` run attaches, and counts.
_WRAP = """
import pymunk
from dumbbell import spaces

MADE = []
_init = pymunk.Space.__init__


def _with_ledger(self, *args, **kwargs):
    _init(self, *args, **kwargs)
    self.dumbbell_ledger = spaces.Ledger(self)
    self.dumbbell_heat = spaces.HeatCounter(self)
    import weakref
    MADE.append(weakref.ref(self.dumbbell_ledger))


pymunk.Space.__init__ = _with_ledger
"""


def run(mode: str, freeze: bool = False) -> dict[str, object]:
    """Run pymunk's suite in this process (``mode`` 'bare' or 'ledgers'); its results. With
    ``freeze``, what the process holds before the first test (the modules imported: numpy
    and dumbbell's in the ledgers run) is frozen out of the garbage collector's way
    (``gc.freeze()``): pymunk's testGC calls ``gc.collect()`` 720 times, each of which would
    otherwise walk all of it again (most of the run's time); every object the suite makes
    (spaces, ledgers, counters) is collected as ever."""
    import gc
    import io
    import unittest

    made: list = []
    if mode == "ledgers":
        scope: dict[str, object] = {}
        exec(_WRAP, scope)  # noqa: S102 - the harness's own code, above
        made = scope["MADE"]  # type: ignore[assignment]
    import pymunk.tests as suite_module
    from pymunk.tests import doctests

    path = Path(suite_module.__file__).parent
    suite = unittest.TestLoader().discover(str(path))
    doctests.load_tests(suite, [])
    out = io.StringIO()
    if freeze:
        gc.collect()
        gc.freeze()
    t0 = time.perf_counter()
    result = unittest.TextTestRunner(stream=out, verbosity=0).run(suite)
    seconds = time.perf_counter() - t0
    ledgers = [ref() for ref in made]
    alive = [x for x in ledgers if x is not None]
    return {"mode": mode, "run": result.testsRun, "seconds": seconds,
            "failed": sorted(t.id() for t, _ in result.failures),
            "errors": sorted(t.id() for t, _ in result.errors),
            "spaces": len(made), "ledgers_alive": len(alive),
            "stopped": sorted({str(x._error)[:80] for x in alive if x._error})}


def _subprocess(*args: str, timeout: float = 900.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(Path(__file__).resolve()), *args],
                          capture_output=True, text=True, timeout=timeout, check=False,
                          cwd=ROOT)


def suite_run(mode: str, freeze: bool = False) -> dict[str, object]:
    """One run in a subprocess (``freeze`` as :func:`run` takes it): its results, or its exit
    status and what it said."""
    done = _subprocess("--run", mode, *(["--freeze"] if freeze else []))
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode != 0 or not lines:
        return {"mode": mode, "exit": done.returncode, "stderr": done.stderr[-2000:]}
    return json.loads(lines[-1])


_COST = """
import gc, json, statistics, time
import pymunk
from dumbbell import spaces

if MODE == "imported":
    import dumbbell.spaces.ledger  # what a ledger loads (numpy), none attached
keep = []
for k in range(50):
    space = pymunk.Space()
    space.gravity = (0, -900)
    floor = pymunk.Segment(space.static_body, (-500, 0), (500, 0), 5)
    floor.elasticity = 0.9
    space.add(floor)
    for i in range(20):
        b = pymunk.Body(1, 100)
        b.position = (40 * i - 400, 50 + 10 * (i % 3))
        c = pymunk.Circle(b, 10)
        c.elasticity = 0.9
        space.add(b, c)
    if MODE == "ledger":
        space.ledger = spaces.Ledger(space)
    for _ in range(50):
        space.step(1 / 60)
    keep.append(space)
gc.collect()
times = []
for _ in range(20):
    t0 = time.perf_counter()
    gc.collect()
    times.append(time.perf_counter() - t0)
status = dict(line.split(":", 1) for line in open("/proc/self/status") if ":" in line)
print(json.dumps({"gc_ms": statistics.median(times) * 1e3, "objects": len(gc.get_objects()),
                  "rss_mb": int(status["VmRSS"].split()[0]) / 1024,
                  "peak_mb": int(status["VmHWM"].split()[0]) / 1024}))
"""


def costs() -> dict[str, dict[str, float]]:
    """gc.collect() and memory: bare, with the ledger's modules imported, and with a ledger
    on each of 50 spaces."""
    out = {}
    for label in ("bare", "imported", "ledger"):
        done = subprocess.run([sys.executable, "-c", _COST.replace("MODE", repr(label))],
                              capture_output=True, text=True, timeout=600, check=False)
        if done.returncode != 0:
            raise SystemExit(f"cost run {label} failed: {done.stderr[-2000:]}")
        out[label] = json.loads(done.stdout.strip().splitlines()[-1])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", choices=["bare", "ledgers"], help="one run, as JSON")
    parser.add_argument("--freeze", action="store_true",
                        help="with --run: the imported modules frozen out of gc's way")
    a = parser.parse_args()
    if a.run:
        sys.path.insert(0, str(ROOT / "src"))
        print(json.dumps(run(a.run, a.freeze)))
        return
    runs = {mode: suite_run(mode) for mode in ("bare", "ledgers")}
    for mode, r in runs.items():
        if "exit" in r:
            print(f"{mode}: exit status {r['exit']}\n{r['stderr']}")
            raise SystemExit(1)
        print(f"{mode:8s} {r['run']} tests, {len(r['failed'])} failed, "
              f"{len(r['errors'])} errors, {r['seconds']:.2f} s")
    bare, led = runs["bare"], runs["ledgers"]
    newly = sorted(set(led["failed"] + led["errors"]) - set(bare["failed"] + bare["errors"]))
    print(f"failing only with ledgers: {newly or 'none'}")
    print(f"spaces made with a ledger and a heat counter: {led['spaces']}; ledgers still "
          f"alive at the end: {led['ledgers_alive']}, of them stopped: "
          f"{led['stopped'] or 'none'}")
    print(f"time: {led['seconds']:.2f} s against {bare['seconds']:.2f} s bare "
          f"({led['seconds'] / bare['seconds']:.1f}x)")
    c = costs()
    print("50 spaces of 20 balls, 50 steps each: gc.collect() (median of 20) and memory")
    for label, what in (("bare", "bare"), ("imported", "the ledger's modules imported"),
                        ("ledger", "a ledger kept on each space")):
        print(f"  {what:30s} gc.collect() {c[label]['gc_ms']:7.2f} ms "
              f"({c[label]['objects']:,} objects tracked)   memory "
              f"{c[label]['rss_mb']:5.0f} MB (peak {c[label]['peak_mb']:.0f} MB)")
    print(f"(load: {Path('/proc/loadavg').read_text().split()[:3]})")


if __name__ == "__main__":
    main()
