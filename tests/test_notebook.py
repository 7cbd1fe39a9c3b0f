"""The tutorial notebooks in examples/ run from top to bottom without an error, and every
figure they draw passes the figure checker (tests/figcheck.py): no text on text, legends or
lines, units on every axis."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import dumbbell

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = sorted((ROOT / "examples").glob("*.ipynb"))
#: Longest one cell may take (s) before nbclient calls it a hang: a guard, not a speed test
#: (how long a notebook takes is the machine's load; speed lives in the benchmarks).
CELL_HANG_S = 600
#: Run first in the kernel: checks every open figure after each cell, before the inline
#: backend shows and closes it (its hook is registered later, when pyplot is imported).
CHECK_FIGURES = f"""
import sys as _sys
_sys.path.insert(0, {str(ROOT)!r})
from tests.figcheck import problems as _problems
_figure_report = {{"figures": 0, "findings": []}}

def _check_figures():
    import matplotlib.pyplot as _plt
    for _num in _plt.get_fignums():
        _fig = _plt.figure(_num)
        _figure_report["figures"] += 1
        _cell = get_ipython().execution_count
        _figure_report["findings"] += [f"cell {{_cell}}: {{_x}}" for _x in _problems(_fig)]

get_ipython().events.register("post_execute", _check_figures)
"""
REPORT_FIGURES = 'import json as _json; print("FIGCHECK " + _json.dumps(_figure_report))'


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
    nb.cells.insert(0, nbformat.v4.new_code_cell(CHECK_FIGURES))
    nb.cells.append(nbformat.v4.new_code_cell(REPORT_FIGURES))
    client = NotebookClient(nb, timeout=CELL_HANG_S, kernel_name="python3",
                            resources={"metadata": {"path": str(path.parent)}})
    client.execute()          # raises CellExecutionError at the first cell that fails
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert [o for o in outputs if o.output_type == "error"] == []
    # Every notebook shows at least one figure inline, and every figure is fit for a lecture.
    assert any("image/png" in o.get("data", {}) for o in outputs)
    import json

    report = next(json.loads(line.removeprefix("FIGCHECK "))
                  for o in nb.cells[-1].outputs if o.output_type == "stream"
                  for line in o.text.splitlines() if line.startswith("FIGCHECK "))
    shown = sum("image/png" in o.get("data", {}) for o in outputs)
    assert report["figures"] >= shown - sum(c.source.count("render_gif") for c in nb.cells)
    assert report["findings"] == []
