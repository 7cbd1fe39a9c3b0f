"""A run's CSVs read back to the very numbers of the run: the samples (17 significant digits)
and the impacts (``repr``), whatever writes them (a file, standard output)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest

from dumbbell.io.trajectory import EVENT_COLUMNS, dump_csv, events_csv, write_csv, write_events
from dumbbell.model.scene import load_scene
from dumbbell.solvers import simulate

SCENES = Path(__file__).parent.parent / "scenes"


@pytest.mark.parametrize("name,solver", [("textbook-1d", "exact"), ("tilted-2d", "pymunk")])
def test_the_csvs_read_back_bit_for_bit(name, solver, tmp_path):
    traj = simulate(load_scene(SCENES / f"{name}.toml"), solver, t_end=1.0, every=50)
    assert traj.events, "the run must hit the floor for the impacts to be checked"
    path = write_csv(traj, tmp_path / "run.csv")
    header = path.read_text().splitlines()[0]
    assert header.split(",") == traj.columns
    np.testing.assert_array_equal(np.loadtxt(path, delimiter=",", skiprows=1), traj.table())
    stream = io.StringIO()
    dump_csv(traj, stream)
    assert stream.getvalue() == path.read_text()

    events = write_events(traj, tmp_path / "impacts.csv").read_text()
    assert events == events_csv(traj)
    rows = list(csv.reader(io.StringIO(events)))
    assert tuple(rows[0]) == EVENT_COLUMNS and len(rows) == len(traj.events) + 1
    for row, impact in zip(rows[1:], traj.events, strict=True):
        assert (float(row[0]), row[1], float(row[2]), float(row[3])) == (
            impact.t, impact.body, impact.v_before, impact.v_after)


def test_a_run_without_impacts_writes_the_header_alone(tmp_path):
    scene = load_scene(SCENES / "textbook-1d.toml")
    traj = simulate(scene, "exact", t_end=0.01)
    assert not traj.events
    assert write_events(traj, tmp_path / "e.csv").read_text() == "t,body,v_before,v_after\n"
