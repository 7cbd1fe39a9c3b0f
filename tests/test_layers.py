"""The layers of docs/architecture.md, checked: every module imports only its own layer and
the ones below it, so data flows one way and there are no import circles."""

from __future__ import annotations

import ast
from pathlib import Path

import dumbbell

ROOT = Path(dumbbell.__file__).parent

#: Modules every layer may use (``_lazy``: the lazy loading of submodules by ``__getattr__``;
#: ``_display``: how results show themselves, repr and notebook table).
SHARED = {"errors", "progress", "parallel", "io.frames", "_lazy", "_display"}
#: The one kind of upward import allowed: a convenience method that delegates to the layer
#: above, imported inside the method (never at module level), as the brief allows for
#: ``traj.to_csv(path)``. (importer, imported) pairs.
DELEGATES = {("dumbbell.model.trajectory", "dumbbell.io.trajectory")}
#: Layer of each package: ``spaces`` (any pymunk space: energy, heat, step guard) sits with
#: the model; its recorder is the user's API above the animation that paints the recording
#: (``animation/recording.py``), as the commands are.
LAYERS = {"model": 1, "spaces": 1, "spaces.recorder": 5, "solvers": 2,
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


def imports(path: Path, local: bool = True, root: Path = ROOT) -> tuple[str, list[str]]:
    """The module's dotted name and the dumbbell modules it imports (relative imports);
    with ``local`` False, only those at module level (not inside a function)."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    package = parts[:-1]  # the package a relative import starts from
    module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
    tree = ast.parse(path.read_text())
    inside = {id(n) for f in ast.walk(tree)
              if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) for n in ast.walk(f)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level and (local or id(node) not in inside):
            base = package[: len(package) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
            found += [target] if node.module else [f"{target}.{a.name}" for a in node.names]
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


def test_every_module_imports_only_its_layer_and_the_ones_below():
    assert upward_imports() == []


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
    # Writing files is io's: a model module that wrote its own would be caught.
    assert layer("dumbbell.io.trajectory") > layer("dumbbell.model.trajectory")
