"""The layers of docs/architecture.md, checked: every module imports only its own layer and
the ones below it, so data flows one way and there are no import circles."""

from __future__ import annotations

import ast
from pathlib import Path

import dumbbell

ROOT = Path(dumbbell.__file__).parent

#: Modules every layer may use.
SHARED = {"errors", "progress", "parallel", "io.frames", "_install"}
#: Layer of each package: ``spaces`` (any pymunk space: energy, heat, step guard) sits with
#: the model, except its recorder, which paints like the animation.
LAYERS = {"model": 1, "spaces": 1, "spaces.recorder": 4, "solvers": 2,
          "analysis": 3, "io": 4, "plot": 4, "animation": 4, "cli": 5, "examples": 5}


def layer(module: str) -> int:
    """The layer of ``dumbbell.X.Y``: the most specific entry of LAYERS, 0 when shared."""
    parts = module.split(".")[1:]
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        if name in SHARED:
            return 0
        if name in LAYERS:
            return LAYERS[name]
    return 5  # the package's own __init__ re-exports the public API


def imports(path: Path) -> tuple[str, list[str]]:
    """The module's dotted name and the dumbbell modules it imports (relative imports)."""
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    package = parts[:-1]  # the package a relative import starts from
    module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package[: len(package) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
            found += [target] if node.module else [f"{target}.{a.name}" for a in node.names]
    return module, found


def test_every_module_imports_only_its_layer_and_the_ones_below():
    upward = []
    for path in sorted(ROOT.rglob("*.py")):
        module, targets = imports(path)
        upward += [f"{module} -> {t}" for t in targets if layer(t) > layer(module)]
    assert upward == []


def test_the_layer_rule_sees_an_upward_import():
    # The check itself can fail: a model module reaching up to plot is caught.
    assert layer("dumbbell.plot.style") > layer("dumbbell.model.scene")
    assert layer("dumbbell.spaces.recorder") > layer("dumbbell.solvers.engine")
    assert layer("dumbbell.errors") == 0 < layer("dumbbell.model.trajectory") < layer(
        "dumbbell.io.files")
    # Writing files is io's: a model module that wrote its own would be caught.
    assert layer("dumbbell.io.trajectory") > layer("dumbbell.model.trajectory")
