"""Property-based tests: whatever text or values reach the scene loader, the answer is a valid
Scene or one SceneError, never another exception."""

from __future__ import annotations

import copy
import json
import math
import os

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dumbbell.errors import SceneError
from dumbbell.model.scene import Scene, load_scene, scene_from_dict
from tests.conftest import TEXTBOOK

# The suite's run is derandomized, so CI is reproducible; FUZZ_EXAMPLES=5000 explores afresh.
FUZZ = settings(max_examples=int(os.environ.get("FUZZ_EXAMPLES", "150")), deadline=None,
                derandomize="FUZZ_EXAMPLES" not in os.environ, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])

#: A valid 2D scene, so that mutations reach the 2D branches too.
TILTED = {
    "dimensions": 2, "tilt": 30.0,
    "bodies": {"A": {"mass": 0.1, "velocity": [1.0, 0.0], "radius": 0.02},
               "B": {"mass": 0.1, "height": 1.0, "x": 0.5, "spin": 1.0}},
    "spring": {"stiffness": 200.0, "rest_length": 0.2},
    "floor": {"elasticity": 0.9, "friction": 0.3},
    "gravity": {"g": 9.8},
    "pymunk": {"collision_slop": 0.001, "collision_bias": 1.0, "iterations": 10, "spin": True},
    "run": {"t_end": 1.0, "dt": 1e-4, "solver": "pymunk", "every": 10,
            "unstable_energy": 5.0},
    "outputs": {"figures": ["positions"], "csv": True,
                "gif": {"fps": 25, "size": "320x240", "strip": True, "t_end": 1.0}},
}

#: Every key the schema knows, plus a few it does not.
KEYS = [
    "title", "dimensions", "tilt", "bodies.A.mass", "bodies.A.height", "bodies.A.x",
    "bodies.A.velocity", "bodies.A.radius", "bodies.A.spin", "bodies.B.mass", "bodies.B.height",
    "bodies.B.x", "bodies.B.velocity", "bodies.B.radius", "bodies.B.spin", "spring.stiffness",
    "spring.rest_length", "rigid.length", "floor.elasticity", "floor.friction", "gravity.g",
    "run.t_end", "run.dt", "run.solver", "run.every", "run.unstable_energy", "outputs.figures",
    "outputs.csv", "outputs.gif.fps", "outputs.gif.size", "outputs.gif.strip", "outputs.gif.t_end",
    "pymunk.collision_slop", "pymunk.collision_bias", "pymunk.iterations", "pymunk.spin",
    "bodies", "bodies.A", "spring", "floor", "run", "outputs", "outputs.gif", "pymunk",
    "bodies.C.mass", "nonsense", "run.nonsense", "spring.k",
]

scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e3, max_value=1e3),
    st.integers(),
    st.integers(min_value=-10**400, max_value=10**400),
    st.booleans(),
    st.text(max_size=12),
    st.sampled_from(["euler-cromer", "pymunk", "exact", "640x360", "²x³", "9" * 5000 + "x64",
                     "positions", "", "A", "B"]),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.text(max_size=6), inner, max_size=4)),
    max_leaves=8,
)


def _set(raw: dict, dotted: str, value) -> None:
    parts = dotted.split(".")
    table = raw
    for part in parts[:-1]:
        nxt = table.get(part)
        if not isinstance(nxt, dict):
            nxt = table[part] = {}
        table = nxt
    table[parts[-1]] = value


def _delete(raw: dict, dotted: str) -> None:
    parts = dotted.split(".")
    table = raw
    for part in parts[:-1]:
        table = table.get(part)
        if not isinstance(table, dict):
            return
    table.pop(parts[-1], None)


def _check(make) -> None:
    """``make()`` must return a usable Scene or raise SceneError."""
    try:
        scene = make()
    except SceneError as exc:
        text = str(exc)
        assert text and "\n" not in text
        return
    assert isinstance(scene, Scene)
    # A valid scene's derived quantities exist and are numbers.
    system = scene.system
    for value in (system.M, system.mu, system.omega, scene.run.dt, scene.run.t_end):
        assert isinstance(value, float) and not math.isnan(value)
    assert scene.system.M > 0 and scene.system.mu > 0 and 0 < scene.run.dt <= scene.run.t_end
    assert isinstance(scene.name, str) and isinstance(scene.system.dissipative, bool)
    # The document rebuilt from the fields reads back as the same scene.
    assert scene_from_dict(scene.to_dict(), scene.source) == scene


@FUZZ
@given(base=st.sampled_from([TEXTBOOK, TILTED]),
       changes=st.lists(st.tuples(st.sampled_from(KEYS), values), max_size=4),
       drops=st.lists(st.sampled_from(KEYS), max_size=2))
def test_values_near_the_schema_give_a_scene_or_a_scene_error(base, changes, drops):
    raw = copy.deepcopy(base)
    for key in drops:
        _delete(raw, key)
    for key, value in changes:
        _set(raw, key, value)
    _check(lambda: scene_from_dict(raw, source="fuzz.toml"))


@FUZZ
@given(changes=st.dictionaries(st.sampled_from(KEYS + ["a..b", "", ".x", "bodies.A.mass.x"]),
                               values, max_size=3))
def test_with_values_gives_a_scene_or_a_scene_error(changes):
    scene = scene_from_dict(copy.deepcopy(TEXTBOOK), source="fuzz.toml")
    _check(lambda: scene.with_values(changes))


@FUZZ
@given(data=st.one_of(values, st.dictionaries(st.text(max_size=8), values, max_size=5)))
def test_any_document_shape_gives_a_scene_or_a_scene_error(data):
    _check(lambda: scene_from_dict(data, source="fuzz.toml"))  # type: ignore[arg-type]


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return {math.inf: "inf", -math.inf: "-inf"}.get(value, repr(value))
    if isinstance(value, str):
        return json.dumps(value)  # JSON strings are TOML basic strings
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(v)}" for k, v in value.items()) + "}"


def _toml(doc: dict) -> str:
    """A TOML document for ``doc`` (inline tables below the top level)."""
    return "\n".join(f"{json.dumps(k)} = {_toml_value(v)}" for k, v in doc.items()) + "\n"


@FUZZ
@given(base=st.sampled_from([TEXTBOOK, TILTED]),
       changes=st.lists(st.tuples(st.sampled_from(KEYS), values), max_size=3))
def test_random_toml_documents_give_a_scene_or_a_scene_error(tmp_path, base, changes):
    raw = copy.deepcopy(base)
    for key, value in changes:
        _set(raw, key, value)
    path = tmp_path / "fuzz.toml"
    path.write_text(_toml(raw), encoding="utf-8")
    _check(lambda: load_scene(path))


@FUZZ
@given(text=st.one_of(
    st.text(max_size=300),
    st.text(alphabet="[]=.\"'#\n abcdeAB0123456789-+eE_xinf{},", max_size=300),
    st.binary(max_size=300),
))
def test_random_text_gives_a_scene_or_a_scene_error(tmp_path, text):
    path = tmp_path / "fuzz.toml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _check(lambda: load_scene(path))
