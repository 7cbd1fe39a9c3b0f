"""The tutorial notebooks in examples/ run from top to bottom without an error."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

import dumbbell

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = sorted((ROOT / "examples").glob("*.ipynb"))
#: Each notebook must run in under a minute on a 2-core machine.
LIMIT_S = 60.0


def test_the_notebooks_are_stored_without_outputs():
    import nbformat

    assert NOTEBOOKS
    for path in NOTEBOOKS:
        nb = nbformat.read(path, as_version=4)
        for cell in nb.cells:
            if cell.cell_type == "code":
                assert cell.outputs == [] and cell.execution_count is None, path.name


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_the_notebook_runs_cleanly(path, monkeypatch):
    import nbformat
    from nbclient import NotebookClient

    # The kernel imports the same dumbbell as these tests (a checkout or an install).
    package_root = str(Path(dumbbell.__file__).resolve().parents[1])
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [package_root, *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(nb, timeout=int(LIMIT_S), kernel_name="python3",
                            resources={"metadata": {"path": str(path.parent)}})
    t0 = time.perf_counter()
    client.execute()          # raises CellExecutionError at the first cell that fails
    seconds = time.perf_counter() - t0
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert [o for o in outputs if o.output_type == "error"] == []
    # Every notebook shows at least one figure inline.
    assert any("image/png" in o.get("data", {}) for o in outputs)
    assert seconds < LIMIT_S, f"{path.name} took {seconds:.1f} s"
