"""The layers of docs/architecture.md, checked: every module imports only its own layer and
the ones below it, so data flows one way, and no two files import each other."""

from __future__ import annotations

import ast
import functools
import re
from collections import deque
from collections.abc import Iterator
from pathlib import Path

import pytest

import dumbbell

ROOT = Path(dumbbell.__file__).parent

#: Layer of each package: ``spaces`` (any pymunk space: energy, heat, step guard) sits with
#: the model; its recorder (and ``_draw``, what it collects of a space as the recording's
#: primitives, and ``_recorder_checks``, its arguments' checks) is the user's API above the
#: animation that paints the recording (``animation/recording.py``), as the commands are.
#: The modules directly in the package (errors, progress, parallel, frames, _lazy, _display,
#: ...) serve every layer: layer 0; ``files`` (the one way a file is written,
#: ``atomic_output``) with the model, below every writer (it checks paths with
#: ``model.args``).
LAYERS = {"model": 1, "files": 1, "spaces": 1, "spaces.recorder": 5, "spaces._draw": 5,
          "spaces._recorder_checks": 5, "solvers": 2,
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
    tree = _parsed(path.read_text())
    found = []
    for node, inside in _walk(tree):
        if not local and inside:
            continue
        if isinstance(node, ast.Call):
            target = _dynamic(node, module)
            if target == "?":  # a name computed at run time: every module the file names
                found += [t for t in _named(tree) if _exists(t, root)]
            elif target and _exists(target, root):
                found.append(target)
        elif isinstance(node, ast.Import):
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


@functools.cache
def _parsed(source: str) -> ast.Module:
    """``ast.parse(source)``, once per source text: the two tests of the package's own files
    read the same trees (the parse is most of their time). Nothing changes a tree."""
    return ast.parse(source)


@pytest.fixture(scope="module", autouse=True)
def _forget_the_trees():
    yield
    _parsed.cache_clear()  # some 60 MB of trees


def _walk(tree: ast.AST) -> Iterator[tuple[ast.AST, bool]]:
    """Every node of ``tree`` in :func:`ast.walk`'s order, with whether it is inside a
    function (a ``def`` or ``async def``, the function's own node included): one pass."""
    todo = deque([(tree, False)])
    while todo:
        node, inside = todo.popleft()
        inside = inside or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
        todo.extend((child, inside) for child in ast.iter_child_nodes(node))
        yield node, inside


def _dynamic(call: ast.Call, module: str) -> str | None:
    """The dumbbell module a call ``importlib.import_module(NAME)``, ``import_module(NAME)``
    or ``__import__(NAME)`` loads, when NAME is a string or an f-string that starts with
    one (``f"dumbbell.cli.{name}"`` loads a module of ``dumbbell.cli``; ``f"{__name__}.x"``
    one of this package); '?' when NAME is computed at run time; None for any other call."""
    func = call.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
    if name not in ("import_module", "__import__") or not call.args:
        return None
    arg = call.args[0]
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        target = arg.value
    elif isinstance(arg, ast.JoinedStr) and arg.values:
        head = arg.values[0]
        if isinstance(head, ast.Constant) and isinstance(head.value, str):
            target = head.value.rstrip(".")
        elif (isinstance(head, ast.FormattedValue) and isinstance(head.value, ast.Name)
              and head.value.id == "__name__"):
            target = module
        else:
            return "?"
    else:
        return "?"
    return target if target.split(".")[0] == "dumbbell" else None


def _named(tree: ast.AST) -> list[str]:
    """The dumbbell modules a file names in its strings (``"dumbbell.x.y"`` or
    ``"dumbbell.x.y:Class"``, docstrings left out): what a name computed at run time may
    load."""
    docs = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)}
    return [n.value.partition(":")[0] for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs
            and re.fullmatch(r"dumbbell(\.\w+)+(:\w+)?", n.value)]


def upward_imports(root: Path = ROOT) -> list[str]:
    """Every import that reaches up a layer: at module level, inside a function, or by name
    through importlib."""
    upward = []
    for path in sorted(root.rglob("*.py")):
        module, targets = imports(path, root=root)
        upward += [f"{module} -> {t}" for t in targets if layer(t) > layer(module)]
    return upward


def _graph(root: Path = ROOT) -> dict[str, set[str]]:
    """Who imports whom (at module level, inside a function or by name)."""
    graph = {}
    for path in sorted(root.rglob("*.py")):
        module, targets = imports(path, root=root)
        # (A module that loads a module of its own package by name, ``f"{__name__}.x"`` or
        # ``f"dumbbell.cli.{name}"`` in the package, names the package: no circle.)
        graph[module] = {t for t in targets if t != module and not module.startswith(t + ".")}
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


def test_an_import_inside_a_function_reaches_up_as_one_at_the_top_does(tmp_path):
    model = tmp_path / "dumbbell" / "model"
    model.mkdir(parents=True)
    (tmp_path / "dumbbell" / "io").mkdir()
    (tmp_path / "dumbbell" / "io" / "trajectory.py").write_text("")
    (model / "trajectory.py").write_text(
        "def to_csv(self, path):\n    from ..io.trajectory import write_csv\n")
    assert upward_imports(tmp_path / "dumbbell") == [
        "dumbbell.model.trajectory -> dumbbell.io.trajectory"]
    (model / "trajectory.py").write_text("from ..io.trajectory import write_csv\n")
    assert upward_imports(tmp_path / "dumbbell") == [
        "dumbbell.model.trajectory -> dumbbell.io.trajectory"]


def test_the_layer_rule_sees_an_upward_import():
    # The check itself can fail: a model module reaching up to plot is caught.
    assert layer("dumbbell.plot.style") > layer("dumbbell.model.scene")
    assert layer("dumbbell.spaces.recorder") > layer("dumbbell.solvers.engine")
    # The recorder may use the painter in animation/, never the other way round.
    assert layer("dumbbell.animation.recording") < layer("dumbbell.spaces.recorder")
    assert layer("dumbbell.errors") == 0 < layer("dumbbell.model.trajectory") == layer(
        "dumbbell.files") < layer("dumbbell.io.trajectory")
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


def test_importlib_calls_are_seen(tmp_path):
    # A module loaded by name reaches up as an import does: the rule reads those calls too.
    root = tmp_path / "dumbbell"
    for name in ("model/x.py", "solvers/settings.py", "cli/run.py", "cli/__init__.py"):
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text("")
    (root / "model" / "x.py").write_text(
        "import importlib\n"
        "def f(name):\n"
        "    importlib.import_module('dumbbell.solvers.settings')\n"
        "    return importlib.import_module(f'dumbbell.cli.{name}')\n")
    assert imports(root / "model" / "x.py", root=root)[1] == [
        "dumbbell.solvers.settings", "dumbbell.cli"]
    assert upward_imports(root) == ["dumbbell.model.x -> dumbbell.solvers.settings",
                                    "dumbbell.model.x -> dumbbell.cli"]
    # A name computed at run time: the modules the file names in its strings count.
    (root / "model" / "x.py").write_text(
        "import importlib\n"
        "OWNED = {'t': 'dumbbell.solvers.settings:Settings'}\n"
        "def owner(t):\n"
        "    module, _, name = OWNED[t].partition(':')\n"
        "    return getattr(importlib.import_module(module), name)\n")
    assert upward_imports(root) == ["dumbbell.model.x -> dumbbell.solvers.settings"]
