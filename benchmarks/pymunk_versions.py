"""What works on each pymunk release: dumbbell's whole pymunk surface run in one virtual
environment per release, compared with a reference release, and one table.

    python benchmarks/pymunk_versions.py /tmp/pm-7.0.0 /tmp/pm-7.3.1 ...   # existing venvs
    python benchmarks/pymunk_versions.py --create /tmp/pmv                 # make them first
    python benchmarks/pymunk_versions.py --create /tmp/pmv --releases 7.0.0,6.11.1

Each venv holds one pymunk release and this project installed from this source tree
(``pip install --no-deps -e .``; ``--create DIR`` makes ``DIR/pm-RELEASE`` for each of
``--releases`` with pip: the project's dependencies from pyproject.toml, then that pymunk;
a venv already there is reused). On each, the script runs:

- ``dumbbell simulate --solver pymunk`` on scenes/textbook-1d.toml and scenes/tilted-2d.toml
  (``--every 100``), the CSV compared with the reference release's: ``same`` when the
  bytes are identical, else the largest difference of a value;
- in that venv's Python (``--probe``), only through the public API of ``dumbbell.spaces``:
  ``energy`` and ``report`` on a space holding every constraint kind and contacts;
  whether ``energy``, ``report`` and ``Ledger`` tell a spring with a custom force function
  (a rotary spring with a custom torque function, a body with a custom ``velocity_func``)
  from one with pymunk's own (a body's set back to pymunk's own after a custom one); a ``Ledger``
  over that space for 240 steps: ``balance().complete``, its relative closure, and whether
  it ran the full ledger or fell back to its public-API ledger (said by a warning naming
  pymunk; every warning is printed below the table);
  ``HeatCounter`` on boxes falling on a floor (its total); a ``Recorder`` to a GIF
  (identical bytes or not).

Then one table: release -> what passed. A release outside the supported range passes when
each of them is refused with one line naming the installed version and the range (the CLI
with exit status 2). ``--reference`` is the release the others are compared with (default:
the newest given). Nothing here times anything.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import math
import os
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RELEASES = ("7.0.0", "7.0.1", "7.1.0", "7.2.0", "7.3.0", "7.3.1", "6.11.1")
SCENES = {"1D": "textbook-1d.toml", "2D": "tilted-2d.toml"}
STEPS, DT = 240, 1.0 / 120.0
#: The table's columns, in order: what each probe checked.
COLUMNS = ("sim 1D", "sim 2D", "energy", "report", "custom fn", "ledger", "heat", "recorder")


# --- in each venv (--probe): the public API of dumbbell.spaces only ----------------------

def every_joint_space():
    """A space with one constraint of each of pymunk's ten kinds, boxes and balls falling
    on a floor (contacts with friction and restitution), SI units."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    space.iterations = 20
    floor = pymunk.Segment(space.static_body, (-5.0, 0.0), (5.0, 0.0), 0.05)
    floor.friction, floor.elasticity = 0.8, 0.5
    space.add(floor)

    def body(x, y, shape="box"):
        b = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.2)))
        b.position = (x, y)
        s = pymunk.Poly.create_box(b, (0.2, 0.2)) if shape == "box" else pymunk.Circle(b, 0.1)
        s.friction, s.elasticity = 0.6, 0.3
        space.add(b, s)
        return b

    static = space.static_body
    hang = [body(-3.0 + 0.5 * i, 2.0 + 0.1 * i, "ball" if i % 2 else "box") for i in range(10)]
    a, b, c, d, e, f, g, h, i, j = hang
    a.velocity = (1.0, 0.5)
    c.angular_velocity = 2.0
    joints = [
        pymunk.PivotJoint(static, a, (-3.0, 2.5)),
        pymunk.PinJoint(a, b),
        pymunk.SlideJoint(b, c, (0, 0), (0, 0), 0.3, 0.6),
        pymunk.GrooveJoint(static, d, (-2.0, 2.6), (-1.0, 2.6), (0.0, 0.0)),
        pymunk.DampedSpring(d, e, (0, 0), (0, 0), 0.4, 50.0, 0.5),
        pymunk.DampedRotarySpring(e, f, 0.0, 5.0, 0.1),
        pymunk.RotaryLimitJoint(f, g, -0.3, 0.3),
        pymunk.RatchetJoint(g, h, 0.0, math.pi / 8),
        pymunk.GearJoint(h, i, 0.0, 2.0),
        pymunk.SimpleMotor(i, j, 1.5),
    ]
    joints[-1].max_force = 5.0
    space.add(*joints)
    for k in range(6):  # loose boxes and balls falling on the floor
        body(1.0 + 0.35 * k, 0.4 + 0.3 * k, "box" if k % 2 else "ball")
    return space


def custom_spring_space(custom: bool):
    """Two balls on a DampedSpring and a DampedRotarySpring, with custom force and torque
    functions (the same law as pymunk's) or pymunk's own."""
    import pymunk

    space = pymunk.Space()
    a, b = pymunk.Body(1.0, 0.1), pymunk.Body(1.0, 0.1)
    a.position, b.position = (0.0, 0.0), (1.0, 0.0)
    b.angular_velocity = 1.0
    spring = pymunk.DampedSpring(a, b, (0, 0), (0, 0), 0.5, 10.0, 0.0)
    rotary = pymunk.DampedRotarySpring(a, b, 0.0, 3.0, 0.0)
    if custom:
        spring.force_func = lambda s, dist: -s.stiffness * (dist - s.rest_length)
        rotary.torque_func = lambda s, angle: -s.stiffness * (angle - s.rest_angle)
    space.add(a, b, pymunk.Circle(a, 0.1), pymunk.Circle(b, 0.1), spring, rotary)
    return space


def _failure(exc: BaseException) -> dict:
    from dumbbell import errors

    text = str(exc).strip()
    refused = isinstance(exc, getattr(errors, "PymunkVersionError", ()))
    return {"ok": False, "refused": refused,
            "one_line": "\n" not in text, "error": f"{type(exc).__name__}: {text[:300]}"}


def probe(out: Path) -> dict:
    """Every public-API check of this release; each one's result and the numbers compared."""
    import pymunk

    from dumbbell import spaces

    results: dict[str, dict] = {}

    def run(name, check):
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                results[name] = {"ok": True, **check()}
            results[name]["warnings"] = [str(w.message).splitlines()[0][:300] for w in caught
                                         if not issubclass(w.category, DeprecationWarning)]
        except Exception as exc:  # noqa: BLE001 - the table reports what each release does
            results[name] = _failure(exc)

    def energy():
        e = spaces.energy(every_joint_space())
        return {"value": [e.E, e.K_trans, e.K_rot, e.U_g, e.U_spring],
                "detail": f"E = {e.E:.17g} J"}

    def report():
        text = spaces.report(every_joint_space(), DT)
        return {"value": hashlib.sha256(text.encode()).hexdigest(), "detail": f"{len(text)} chars"}

    def custom():
        import pymunk

        def half(body, gravity, damping, dt):
            pymunk.Body.update_velocity(body, (gravity[0] / 2, gravity[1] / 2), damping, dt)

        named, reports = {}, []
        for flag in (True, False):
            space = custom_spring_space(flag)
            # A body's custom velocity_func too; pymunk's own set back after one (7.0.x's
            # setter keeps the replaced function on the body).
            body = next(iter(space.bodies))
            body.velocity_func = half
            if not flag:
                body.velocity_func = pymunk.Body.update_velocity
            e = spaces.energy(space)
            reports.append(spaces.report(space, 0.01))  # its joint probe copies the bodies
            ledger = spaces.Ledger(space)
            for _ in range(20):
                space.step(0.01)
            bal = ledger.balance()
            named[flag] = (len(e.unknown), len(bal.unaccounted))
        ok = named[True][0] == 3 and named[True][1] >= 3 and named[False] == (0, 0)
        digest = hashlib.sha256("".join(reports).encode()).hexdigest()[:16]
        return {"ok": ok, "value": [*named[True], *named[False], digest],
                "detail": f"custom: energy names {named[True][0]}, ledger {named[True][1]}; "
                          f"pymunk's own: {named[False][0]}, {named[False][1]}"}

    def ledger():
        space = every_joint_space()
        led = spaces.Ledger(space)
        for _ in range(STEPS):
            space.step(DT)
        bal = led.balance()
        kinds = sorted({t.kind for t in bal.terms})
        return {"ok": bool(bal.complete), "value": [bal.E, bal.relative_closure],
                "complete": bool(bal.complete), "closure": bal.relative_closure,
                "kinds": kinds, "unaccounted": [list(u) for u in bal.unaccounted][:3],
                "detail": f"complete={bal.complete} closure={bal.relative_closure:.1e}"}

    def heat():
        space = every_joint_space()
        counter = spaces.HeatCounter(space)
        for _ in range(STEPS):
            space.step(DT)
        return {"ok": counter.total > 0, "value": counter.total,
                "detail": f"{counter.total:.6g} J over {counter.steps} contact-steps"}

    def recorder():
        space = every_joint_space()
        path = out / "recorder.gif"
        with spaces.Recorder(space, path, fps=20, size="320x180") as rec:
            for _ in range(20):
                for _ in range(6):
                    space.step(DT)
                rec.capture()
        data = path.read_bytes()
        return {"ok": data[:6] in (b"GIF87a", b"GIF89a"),
                "value": hashlib.sha256(data).hexdigest(), "detail": f"{len(data)} bytes"}

    for name, check in (("energy", energy), ("report", report), ("custom fn", custom),
                        ("ledger", ledger), ("heat", heat), ("recorder", recorder)):
        run(name, check)
    from importlib.metadata import version

    import dumbbell

    return {"pymunk": version("pymunk"), "pymunk.version": pymunk.version,
            "dumbbell": str(Path(dumbbell.__file__).resolve().parent), "checks": results}


# --- the driver: one venv per release -------------------------------------------------------

def dependencies() -> list[str]:
    """The project's dependencies from pyproject.toml, pymunk left out."""
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    return [d for d in deps if not d.startswith("pymunk")]


def create(folder: Path, release: str) -> Path:
    """``folder/pm-RELEASE``: a venv with that pymunk and this source tree (reused if there)."""
    venv = folder / f"pm-{release}"
    python = venv / "bin" / "python"
    if not (venv / "bin" / "dumbbell").exists():
        print(f"making {venv} ...", file=sys.stderr, flush=True)
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "-q", *dependencies(),
                        f"pymunk=={release}"], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-deps", "-e",
                        str(ROOT)], check=True)
    return venv


def simulate(venv: Path, scene: str, out: Path) -> dict:
    """``dumbbell simulate --solver pymunk`` on a shipped scene in ``venv``."""
    csv_path = out / f"sim-{Path(scene).stem}.csv"
    done = subprocess.run([str(venv / "bin" / "dumbbell"), "simulate", "--solver", "pymunk",
                           str(ROOT / "scenes" / scene), "--every", "100", "-q",
                           "-o", str(csv_path)], capture_output=True, text=True, check=False)
    lines = done.stderr.strip().splitlines()
    result = {"rc": done.returncode, "stderr": lines[-1][:300] if lines else "",
              "stderr_lines": len(lines), "csv": str(csv_path)}
    result["ok"] = done.returncode == 0 and csv_path.exists()
    result["refused"] = (done.returncode == 2 and len(lines) == 1
                         and "pymunk" in lines[0] and not csv_path.exists())
    return result


def csv_distance(a: Path, b: Path) -> str:
    """'same' when the files are identical, else the largest difference of a value."""
    if a.read_bytes() == b.read_bytes():
        return "same"
    with a.open() as fa, b.open() as fb:
        ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
    if len(ra) != len(rb) or ra[0] != rb[0]:
        return f"{len(ra) - 1} vs {len(rb) - 1} rows"
    worst = max((abs(float(x) - float(y)) for r1, r2 in zip(ra[1:], rb[1:], strict=True)
                 for x, y in zip(r1, r2, strict=True)), default=0.0)
    return f"max |diff| {worst:.1e}"


def measure(venv: Path, out: Path) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    result: dict = {"sim": {label: simulate(venv, scene, out)
                            for label, scene in SCENES.items()}}
    done = subprocess.run([str(venv / "bin" / "python"), str(Path(__file__).resolve()),
                           "--probe", str(out)], capture_output=True, text=True, check=False)
    try:
        result.update(json.loads(done.stdout.strip().splitlines()[-1]))
    except (IndexError, json.JSONDecodeError):
        err = done.stderr.strip().splitlines()
        result["probe_error"] = err[-1] if err else f"exit {done.returncode}"
    if "pymunk" not in result:
        vers = subprocess.run([str(venv / "bin" / "python"), "-c",
                               "from importlib.metadata import version; print(version('pymunk'))"],
                              capture_output=True, text=True, check=False)
        result["pymunk"] = vers.stdout.strip() or "?"
    return result


def _in_range(release: str) -> bool:
    sys.path.insert(0, str(ROOT / "src"))
    from dumbbell._pymunk import supported

    return supported(release)


def cells(result: dict, ref: dict | None, supported: bool) -> dict[str, str]:
    """The table's row for one release."""
    row: dict[str, str] = {}
    for label in SCENES:
        sim = result["sim"][label]
        if not supported:
            row[f"sim {label}"] = "refused" if sim["refused"] else f"NOT refused (rc {sim['rc']})"
        elif not sim["ok"]:
            row[f"sim {label}"] = f"FAIL rc {sim['rc']}"
        elif ref is None or ref is result:
            row[f"sim {label}"] = "ok (ref)"
        else:
            row[f"sim {label}"] = csv_distance(Path(sim["csv"]), Path(ref["sim"][label]["csv"]))
    checks = result.get("checks", {})
    for name in COLUMNS[2:]:
        c = checks.get(name)
        if c is None:
            row[name] = "no probe"
        elif not supported:
            row[name] = "refused" if c.get("refused") and c.get("one_line") else (
                "ok?!" if c["ok"] else c["error"].split(":")[0])
        elif "error" in c:
            row[name] = "FAIL " + c["error"].split(":")[0]
        else:
            row[name] = _passed(name, c, ref, result)
    return row


def _passed(name: str, c: dict, ref: dict | None, result: dict) -> str:
    """A check that ran: ok, same as the reference or how far from it, with the ledger's
    mode and the warnings it gave."""
    if name == "ledger":
        # The ledger falls back to its public-API ledger with a warning naming pymunk.
        mode = "fallback" if any("pymunk" in w.lower() for w in c["warnings"]) else "full"
        text = f"{mode}, {'complete' if c['complete'] else 'INCOMPLETE'} {c['closure']:.0e}"
        other = None if ref is None or ref is result else ref.get("checks", {}).get(name)
        if other is not None and "value" in other:
            text += ", same" if other["value"] == c["value"] else ", E differs"
        return text if c["ok"] else text + " FAIL"
    if not c["ok"]:
        return "FAIL " + c.get("detail", "")
    other = None if ref is None or ref is result else ref.get("checks", {}).get(name)
    if other is None or "value" not in other:
        return "ok" + (" (ref)" if ref is result else "")
    a, b = c["value"], other["value"]
    if a == b:
        return "same"
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return f"ok, diff {abs(a - b):.1e}"
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b) and all(
            isinstance(x, (int, float)) for x in a + b):
        return f"ok, diff {max(abs(x - y) for x, y in zip(a, b, strict=True)):.1e}"
    return "ok, differs"


def table(results: dict[str, dict], reference: str) -> str:
    """One line per release: what passed."""
    rows = []
    for release, result in results.items():
        supported = _in_range(result["pymunk"])
        row = cells(result, results.get(reference), supported)
        rows.append([release, "yes" if supported else "no", *(row[c] for c in COLUMNS)])
    head = ["pymunk", "in range", *COLUMNS]
    widths = [max(len(str(r[i])) for r in [head, *rows]) for i in range(len(head))]
    line = " | ".join
    out = [line(h.ljust(w) for h, w in zip(head, widths, strict=True)),
           line("-" * w for w in widths)]
    out += [line(str(v).ljust(w) for v, w in zip(r, widths, strict=True)) for r in rows]
    return "\n".join(out)


def _release_key(release: str) -> tuple[int, ...]:
    return tuple(int(p) for p in release.split(".") if p.isdigit())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("venvs", nargs="*", type=Path, help="venvs, one pymunk release each")
    parser.add_argument("--create", type=Path, metavar="DIR",
                        help="make (or reuse) DIR/pm-RELEASE for each of --releases")
    parser.add_argument("--releases", default=",".join(RELEASES),
                        help=f"with --create (default {','.join(RELEASES)})")
    parser.add_argument("--reference", help="release to compare with (default: the newest)")
    parser.add_argument("--out", type=Path, default=Path("/tmp/pymunk-versions"),
                        help="scratch folder for the outputs (default /tmp/pymunk-versions)")
    parser.add_argument("--json", action="store_true", help="also print every result as JSON")
    parser.add_argument("--probe", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.probe is not None:
        print(json.dumps(probe(args.probe)))
        return 0
    venvs = list(args.venvs)
    if args.create is not None:
        args.create.mkdir(parents=True, exist_ok=True)
        venvs += [create(args.create, r) for r in args.releases.split(",") if r]
    if not venvs:
        parser.error("give venvs, or --create DIR")
    results = {}
    for venv in venvs:
        print(f"running {venv} ...", file=sys.stderr, flush=True)
        result = measure(venv, args.out / venv.name)
        results[result["pymunk"]] = result
    results = dict(sorted(results.items(), key=lambda kv: _release_key(kv[0])))
    supported = [r for r in results if _in_range(r)]
    reference = args.reference or (supported[-1] if supported else next(iter(results)))
    if args.json:
        print(json.dumps(results, indent=1))
    print(table(results, reference))
    print(f"\nCompared with pymunk {reference}: 'same' = identical bytes (CSV, report text, "
          "GIF) or values; 'refused' = one line naming the version and the range (CLI: exit 2)."
          f"\nEach venv: this source tree ({ROOT}) installed --no-deps -e; Python "
          f"{sys.version.split()[0]}; ledger over {STEPS} steps of {DT:.4g} s.")
    for release, result in results.items():
        for name, c in result.get("checks", {}).items():
            for w in c.get("warnings", []):
                print(f"  {release} {name}: warning: {w}")
        here = str(ROOT / "src" / "dumbbell")
        if result.get("dumbbell", here) != here:
            print(f"  {release}: dumbbell imported from {result['dumbbell']}")
        if not _in_range(release):
            print(f"  {release}: the CLI said: {result['sim']['1D']['stderr']}")
        if "probe_error" in result:
            print(f"  {release}: probe failed: {result['probe_error']}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("PYTHONHASHSEED", "0")
    sys.exit(main())
