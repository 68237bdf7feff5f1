"""Property-based tests (hypothesis): random and mutated inputs give a clean error or a valid result,
never a traceback, for the scenario loader and the log reader; and the reader's compiled schema checks
agree with the ``jsonschema`` package (the reference implementation of JSON Schema)."""
from __future__ import annotations

import json
import math
from pathlib import Path

import jsonschema
import pytest
from _robust import PROFILED, ROAD_CSV
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from cosim.errors import ConfigError, LogError
from cosim.log import iter_messages, open_log, read_log
from cosim.log.checks import compile_schema
from cosim.log.schemas import EVENTS_SCHEMA, STATUS_SCHEMA, TRAFFIC_SCHEMA, VEHICLE_TYPE_SCHEMA, VEHICLES_SCHEMA
from cosim.run.scenario import parse_scenario
from cosim.run.toml_writer import toml_dumps

try:
    import tomllib
except ImportError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

BASE = tomllib.loads(PROFILED)
SETTINGS = settings(deadline=None, max_examples=100, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                            HealthCheck.too_slow])

# --------------------------------------------------------------------------- scenario loader

scalars = st.one_of(st.none(), st.booleans(), st.integers(-10**12, 10**12), st.text(max_size=12),
                    st.floats(allow_nan=True, allow_infinity=True))
toml_values = st.recursive(
    st.one_of(st.booleans(), st.integers(-10**9, 10**9), st.floats(allow_nan=True, allow_infinity=True),
              st.text(max_size=10)),
    lambda children: st.one_of(st.lists(children, max_size=4),
                               st.dictionaries(st.text(min_size=1, max_size=8), children, max_size=4)),
    max_leaves=12)


def _leaves(data: object, path: tuple = ()) -> list[tuple]:
    """Every path to a leaf (and to every table and array) of a TOML document."""
    found = [path] if path else []
    if isinstance(data, dict):
        for key, value in data.items():
            found += _leaves(value, path + (key,))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            found += _leaves(value, path + (i,))
    return found


def _set(data: object, path: tuple, value: object) -> None:
    node = data
    for part in path[:-1]:
        node = node[part]  # type: ignore[index]
    if value is _DELETE:
        del node[path[-1]]  # type: ignore[arg-type,index]
    else:
        node[path[-1]] = value  # type: ignore[index]


_DELETE = object()


def assert_loads_or_fails_with_one_line(text: str, folder: Path) -> None:
    """Parse a scenario: a Scenario or a ConfigError whose message is one self-contained first line."""
    try:
        scenario = parse_scenario(text, "s.toml", base_dir=folder)
    except ConfigError as exc:
        first = str(exc).splitlines()[0]
        assert first.startswith("s.toml: ") and len(first) < 2000, first
        return
    assert scenario.bridge.length > 0 and math.isfinite(scenario.bridge.length)


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("properties")
    (path / "data").mkdir()
    (path / "data" / "road.csv").write_text(ROAD_CSV)
    return path


@SETTINGS
@given(st.data())
def test_a_mutated_scenario_loads_or_fails_with_one_line(folder: Path, data: st.DataObject) -> None:
    doc = tomllib.loads(PROFILED)
    for _ in range(data.draw(st.integers(1, 3))):
        paths = _leaves(doc)
        if not paths:
            break
        path = data.draw(st.sampled_from(paths))
        value = data.draw(st.one_of(scalars, toml_values, st.just(_DELETE)))
        if value is None:
            value = _DELETE
        _set(doc, path, value)
    try:
        text = toml_dumps(doc)
    except (TypeError, ValueError):
        assume(False)
    assert_loads_or_fails_with_one_line(text, folder)


@SETTINGS
@given(st.dictionaries(st.sampled_from(["name", "bridge", "sensors", "vehicles", "road", "solver", "output",
                                        "traffic", "extra"]), toml_values, max_size=6))
def test_a_random_document_fails_with_one_line(folder: Path, doc: dict) -> None:
    try:
        text = toml_dumps(doc)
    except (TypeError, ValueError):
        assume(False)
    assert_loads_or_fails_with_one_line(text, folder)


@SETTINGS
@given(st.binary(max_size=60), st.integers(0, len(PROFILED)))
def test_garbage_spliced_into_a_scenario_text_fails_with_one_line(folder: Path, junk: bytes, at: int) -> None:
    text = PROFILED[:at] + junk.decode("utf-8", "replace") + PROFILED[at:]
    assert_loads_or_fails_with_one_line(text, folder)


@SETTINGS
@given(st.lists(st.lists(st.one_of(st.floats(), st.text(max_size=6)), min_size=0, max_size=3), max_size=30),
       st.binary(max_size=30))
def test_a_random_road_profile_file_loads_or_fails_with_one_line(folder: Path, rows: list, tail: bytes) -> None:
    target = folder / "random" / "data"
    target.mkdir(parents=True, exist_ok=True)
    (target / "road.csv").write_bytes(("\n".join(",".join(map(str, row)) for row in rows)).encode() + tail)
    assert_loads_or_fails_with_one_line(PROFILED, target.parent)


# --------------------------------------------------------------------------- log reader


def assert_read_or_refused_with_one_line(path: Path) -> None:
    """Every reader on a file: LogError, or results that are what they claim."""
    try:
        overview = open_log(path)
    except LogError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(str(path)), exc
        return
    assert overview.end_time >= 0 and all(count > 0 for count in overview.counts.values())
    for read in (lambda: read_log(path), lambda: list(iter_messages(path, ["/cosim/sensors", "/cosim/traffic"]))):
        try:
            read()
        except LogError as exc:
            assert "\n" not in str(exc), exc


@pytest.fixture(scope="module")
def log_bytes(profiled_log: Path) -> bytes:
    return profiled_log.read_bytes()


@SETTINGS
@given(st.data())
def test_a_mutated_log_is_read_or_refused_with_one_line(log_bytes: bytes, tmp_path_factory: pytest.TempPathFactory,
                                                        data: st.DataObject) -> None:
    raw = bytearray(log_bytes)
    for _ in range(data.draw(st.integers(1, 4))):
        kind = data.draw(st.sampled_from(["flip", "set", "cut", "insert", "delete"]))
        at = data.draw(st.integers(0, len(raw) - 1))
        if kind == "flip":
            raw[at] ^= 1 << data.draw(st.integers(0, 7))
        elif kind == "set":
            raw[at:at + 8] = data.draw(st.binary(min_size=1, max_size=8))
        elif kind == "cut":
            del raw[at:]
        elif kind == "insert":
            raw[at:at] = data.draw(st.binary(min_size=1, max_size=16))
        else:
            del raw[at:at + data.draw(st.integers(1, 64))]
        if len(raw) < 2:
            break
    path = tmp_path_factory.mktemp("mutated") / "log.mcap"
    path.write_bytes(bytes(raw))
    assert_read_or_refused_with_one_line(path)


@SETTINGS
@given(st.binary(max_size=400))
def test_random_bytes_after_the_magic_are_refused_with_one_line(tmp_path_factory: pytest.TempPathFactory,
                                                                body: bytes) -> None:
    path = tmp_path_factory.mktemp("random") / "log.mcap"
    path.write_bytes(b"\x89MCAP0\r\n" + body)
    assert_read_or_refused_with_one_line(path)


# --------------------------------------------------------------------------- the compiled schema checks

json_values = st.recursive(  # JSON with the keys and words of cosim's topics
    st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=False, allow_infinity=False),
              st.text(max_size=6), st.sampled_from(["entered", "left", "finished", "running", "quarter-car"])),
    lambda children: st.one_of(st.lists(children, max_size=3), st.dictionaries(
        st.sampled_from(["t", "x", "y", "id", "ids", "vehicles", "event", "state", "model", "type", "speed",
                         "message", "vehicle", "types", "acceleration", "contact_force", "k_v"]), children,
        max_size=6)),
    max_leaves=15)


#: A genuine message of each topic (as cosim writes them), to mutate.
GENUINE = [
    (VEHICLES_SCHEMA, {"t": 1.5, "vehicles": [{"id": "car", "model": "quarter-car", "x": 3.0, "y": 1.875,
                                               "speed": 14.0, "acceleration": 0.0, "body_displacement": -0.01,
                                               "body_acceleration": 0.2, "contact_force": 14000.0}]}),
    (EVENTS_SCHEMA, {"t": 1.0, "vehicle": "car", "event": "entered", "x": 0.0}),
    (STATUS_SCHEMA, {"t": 10.0, "state": "running", "progress": 0.5}),
    (TRAFFIC_SCHEMA, {"t": 2.0, "ids": ["a", "b"], "x": [1.0, 2.0], "y": [1.8, -1.8], "speed": [10.0, 12],
                      "acceleration": [0.0, 0.1], "types": ["car", "bus"]}),
    (VEHICLE_TYPE_SCHEMA, {"t": 0.0, "type": "car", "model": {"model": "quarter-car", "m_v": 1350.0, "k_v": 7e4}}),
]


@settings(deadline=None, max_examples=200)
@given(st.sampled_from(GENUINE), st.lists(st.tuples(st.integers(0, 10**6), st.one_of(json_values, st.just(_DELETE))),
                                          max_size=2))
def test_the_compiled_checks_agree_with_jsonschema(example: tuple, mutations: list) -> None:
    """A genuine message of a topic, with up to two fields replaced or deleted. (Finite numbers only: the
    compiled checks also refuse NaN and infinities, which JSON Schema allows.)"""
    schema, message = example
    value = json.loads(json.dumps(message))
    for pick, replacement in mutations:
        paths = _leaves(value)
        if paths:
            _set(value, paths[pick % len(paths)], replacement)
    reference = jsonschema.Draft202012Validator(schema).is_valid(value)
    assert (compile_schema(schema)(value) is None) == reference, (schema["title"], value)
