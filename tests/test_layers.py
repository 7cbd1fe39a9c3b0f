"""The layers of docs/architecture.md, checked: every module imports only its own layer and
the ones below it, so data flows one way, and no two files import each other."""

from __future__ import annotations

import ast
from pathlib import Path

import dumbbell

ROOT = Path(dumbbell.__file__).parent

#: The one kind of upward import allowed: a convenience method that delegates to the layer
#: above, imported inside the method (never at module level), as the brief allows for
#: ``traj.to_csv(path)``. (importer, imported) pairs.
DELEGATES = {("dumbbell.model.trajectory", "dumbbell.io.trajectory")}
#: Layer of each package: ``spaces`` (any pymunk space: energy, heat, step guard) sits with
#: the model; its recorder (and ``_draw``, what it collects of a space as the recording's
#: primitives) is the user's API above the animation that paints the recording
#: (``animation/recording.py``), as the commands are. The modules directly in the package
#: (errors, progress, parallel, frames, _lazy, _display, ...) serve every layer: layer 0.
LAYERS = {"model": 1, "spaces": 1, "spaces.recorder": 5, "spaces._draw": 5, "solvers": 2,
          "analysis": 3, "io": 4, "plot": 4, "animation": 4, "cli": 5, "examples": 5,
          "__main__": 5}


def layer(module: str) -> int:
    """The layer of ``dumbbell.X.Y``: the most specific entry of LAYERS; 0 for a module
    directly in the package; 5 for the package's own __init__ (it re-exports the API)."""
    parts = module.split(".")[1:]
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        if name in LAYERS:
            return LAYERS[name]
    return 0 if len(parts) == 1 else 5


def _module(path: Path, root: Path) -> tuple[str, list[str]]:
    """The dotted name of the module at ``path`` and the package a relative import in it
    starts from."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts), parts[:-1]


def _exists(module: str, root: Path) -> bool:
    where = root.parent / module.replace(".", "/")
    return where.with_suffix(".py").is_file() or (where / "__init__.py").is_file()


def imports(path: Path, local: bool = True, root: Path = ROOT) -> tuple[str, list[str]]:
    """The module's dotted name and the dumbbell modules it imports: relative (``from ..x
    import y``) and absolute (``from dumbbell.x import y``, ``import dumbbell.x``); ``from p
    import m`` names the module ``p.m`` when there is one. With ``local`` False, only those at
    module level (not inside a function)."""
    module, package = _module(path, root)
    tree = ast.parse(path.read_text())
    inside = {id(n) for f in ast.walk(tree)
              if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) for n in ast.walk(f)}
    found = []
    for node in ast.walk(tree):
        if not local and id(node) in inside:
            continue
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] == "dumbbell"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "dumbbell":
                continue
            subs = [f"{target}.{a.name}" for a in node.names]
            found += [s for s in subs if _exists(s, root)] or [target]
    return module, found


def upward_imports(root: Path = ROOT) -> list[str]:
    """Every import that reaches up a layer, but a listed delegate's import inside a function."""
    upward = []
    for path in sorted(root.rglob("*.py")):
        module, targets = imports(path, root=root)
        _, top = imports(path, local=False, root=root)
        upward += [f"{module} -> {t}" for t in targets if layer(t) > layer(module)
                   and ((module, t) not in DELEGATES or t in top)]
    return upward


def _graph(root: Path = ROOT) -> dict[str, set[str]]:
    """Who imports whom, but a listed delegate's import (it goes one way by design)."""
    graph = {}
    for path in sorted(root.rglob("*.py")):
        module, targets = imports(path, root=root)
        graph[module] = {t for t in targets if t != module and (module, t) not in DELEGATES}
    return graph


def circles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The groups of modules that import each other, directly or round a loop (the strongly
    connected components of more than one module)."""
    reach = {m: set() for m in graph}
    for start, targets in graph.items():
        todo = list(targets)
        while todo:
            m = todo.pop()
            if m in graph and m not in reach[start]:
                reach[start].add(m)
                todo += graph[m]
    groups: list[set[str]] = []
    for m in graph:
        group = {m} | {n for n in reach[m] if m in reach.get(n, ())}
        if len(group) > 1 and group not in groups:
            groups.append(group)
    return groups


def test_every_module_imports_only_its_layer_and_the_ones_below():
    assert upward_imports() == []


def test_no_files_import_each_other():
    assert circles(_graph()) == []


def test_a_delegate_may_import_up_only_inside_a_function(tmp_path):
    model = tmp_path / "dumbbell" / "model"
    model.mkdir(parents=True)
    (model / "trajectory.py").write_text(
        "def to_csv(self, path):\n    from ..io.trajectory import write_csv\n")
    assert upward_imports(tmp_path / "dumbbell") == []
    (model / "trajectory.py").write_text("from ..io.trajectory import write_csv\n")
    assert upward_imports(tmp_path / "dumbbell") == [
        "dumbbell.model.trajectory -> dumbbell.io.trajectory"]
    (model / "scene.py").write_text("def f():\n    from ..io.trajectory import write_csv\n")
    assert "dumbbell.model.scene -> dumbbell.io.trajectory" in upward_imports(
        tmp_path / "dumbbell")


def test_the_layer_rule_sees_an_upward_import():
    # The check itself can fail: a model module reaching up to plot is caught.
    assert layer("dumbbell.plot.style") > layer("dumbbell.model.scene")
    assert layer("dumbbell.spaces.recorder") > layer("dumbbell.solvers.engine")
    # The recorder may use the painter in animation/, never the other way round.
    assert layer("dumbbell.animation.recording") < layer("dumbbell.spaces.recorder")
    assert layer("dumbbell.errors") == 0 < layer("dumbbell.model.trajectory") < layer(
        "dumbbell.io.files")
    assert layer("dumbbell.frames") == 0 and layer("dumbbell") == 5
    # Writing files is io's: a model module that wrote its own would be caught.
    assert layer("dumbbell.io.trajectory") > layer("dumbbell.model.trajectory")


def test_absolute_imports_and_circles_are_seen(tmp_path):
    root = tmp_path / "dumbbell"
    (root / "model").mkdir(parents=True)
    path = root / "model" / "x.py"
    path.write_text("import dumbbell.plot.style\nfrom dumbbell.io import files\n"
                    "def f():\n    from dumbbell.cli import app\n")
    for name in ("plot/style.py", "io/files.py", "cli/app.py"):
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text("")
    assert imports(path, root=root) == ("dumbbell.model.x", [
        "dumbbell.plot.style", "dumbbell.io.files", "dumbbell.cli.app"])
    assert imports(path, local=False, root=root)[1] == ["dumbbell.plot.style",
                                                         "dumbbell.io.files"]
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [{"a", "b", "c"}]
