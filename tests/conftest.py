"""Shared fixtures: the shipped scenes and small scene builders."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from dumbbell.model.scene import Scene, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "scenes"

#: The textbook's scene as a dict, for tests that vary it.
TEXTBOOK = {
    "title": "textbook",
    "dimensions": 1,
    "bodies": {"A": {"mass": 0.1, "height": 1.2}, "B": {"mass": 0.1, "height": 1.0}},
    "spring": {"stiffness": 200.0, "rest_length": 0.2},
    "floor": {"elasticity": 1.0},
    "gravity": {"g": 9.8},
    "run": {"t_end": 10.0, "dt": 1e-5, "solver": "euler-cromer"},
}


def make_scene(changes: dict | None = None, drop: tuple[str, ...] = (), base: dict | None = None
               ) -> Scene:
    """The textbook scene with dotted keys changed and top-level tables dropped."""
    raw = copy.deepcopy(base or TEXTBOOK)
    for table in drop:
        raw.pop(table)
    scene = scene_from_dict(raw, source="test.toml")
    return scene.with_values(changes) if changes else scene


@pytest.fixture(scope="session")
def textbook() -> Scene:
    """The shipped scenes/textbook-1d.toml."""
    return load_scene(SCENES / "textbook-1d.toml")
