"""Logs for Foxglove: the layout made for each run (``cosim layout``), the 3D scene of real runs (scripted
and real SUMO), and logs written before either existed. Real runs, real MCAP files, the real command line.

What Foxglove itself shows was checked with a script outside this repository (a real Foxglove in a real
browser; docs/foxglove.md): that needs npm and a browser, so it is not run here. Here: the layout names
only fields the log really has, and the scene's messages are what Foxglove's schemas describe.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from _cli import TWO_CARS, cosim_cli

from cosim.log import open_log, read_log, sensor_series
from cosim.log.schemas import (
    LAYOUT_ATTACHMENT,
    TOPIC_SCENE,
    TOPIC_SCENE_STATIC,
    TOPIC_SCENE_TRANSFORM,
    TOPIC_SENSORS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLES,
)
from cosim.sumo import bundled_networks

REGRESSION_LOGS = Path(__file__).resolve().parents[1] / "regression" / "logs"

#: The bundled network's 40 m bridge (explicit constants, 10 elements) under the bundled light demand; the
#: first vehicles reach the deck after about 40 s.
SUMO_SMALL = """\
name = "sumo-small"
[bridge]
spans = [40.0]
elements_per_span = 10
supports = ["pinned", "fork"]
[bridge.material]
E = 35e9
nu = 0.2
rho = 2500.0
[bridge.section.constants]
A = 6.0
I_y = 3.0
I_z = 50.0
J = 5.0
deck_y = [-5.0, 5.0]
[[sensors]]
name = "mid"
x = 20.0
[[sensors]]
name = "mid.left"
x = 20.0
y = 4.0
quantity = "acceleration"
[traffic]
sumo_config = "sumo/light.sumocfg"
step = 0.05
end = 70.0
seed = 3
[solver]
dt = 0.025
[output]
rate_hz = 40.0
"""

_STEP = re.compile(r'\.(?:"((?:[^"\\]|\\.)*)"|([A-Za-z0-9_-]+))(\[:\])?(?:\{id=="([^"]*)"\})?')


def picked(messages: dict[str, list[tuple[int, dict]]], path: str) -> list[Any]:
    """The values a Foxglove message path picks from a log's messages (the part of Foxglove's path syntax that
    cosim's layouts use: ``/topic.field``, ``."quoted name"``, ``[:]`` and ``{id=="..."}``)."""
    topic = max((t for t in messages if path.startswith(t + ".")), key=len, default=None)
    assert topic is not None, f"{path}: no such topic in the log"
    steps = []
    rest = path[len(topic):]
    while rest:
        match = _STEP.match(rest)
        assert match, f"{path}: cannot read {rest!r}"
        name = match.group(1).replace('\\"', '"').replace("\\\\", "\\") if match.group(1) is not None else \
            match.group(2)
        steps.append((name, bool(match.group(3)), match.group(4)))
        rest = rest[match.end():]
    values: list[Any] = [message for _, message in messages[topic]]
    for name, each, wanted in steps:
        values = [v[name] for v in values if isinstance(v, dict) and name in v]
        if each:
            values = [item for v in values for item in v]
        if wanted is not None:
            values = [v for v in values if v.get("id") == wanted]
    return values


def as_foxglove_reads(log: Path) -> dict[str, list[tuple[int, Any]]]:
    """Every message of ``log`` as Foxglove reads it: decoded with the schema stored in the file (protobuf: by
    the protobuf runtime, its fields by their names, zeros included; JSON: as it is), by topic."""
    from google.protobuf import descriptor_pb2, json_format, message_factory
    from mcap.reader import make_reader

    out: dict[str, list[tuple[int, Any]]] = {}
    classes: dict[tuple[str, bytes], Any] = {}
    with open(log, "rb") as fh:
        for schema, channel, message in make_reader(fh).iter_messages():
            if channel.message_encoding == "json":
                value = json.loads(message.data)
            else:
                key = (schema.name, schema.data)
                if key not in classes:
                    files = list(descriptor_pb2.FileDescriptorSet.FromString(schema.data).file)
                    classes[key] = message_factory.GetMessages(files)[schema.name]
                value = json_format.MessageToDict(classes[key].FromString(message.data),
                                                  preserving_proto_field_name=True,
                                                  always_print_fields_with_no_presence=True)
            out.setdefault(channel.topic, []).append((message.log_time, value))
    return out


def check_layout(layout: dict[str, Any], log: Path) -> list[str]:
    """Every panel of ``layout`` shows something of ``log`` as Foxglove reads it: each plot series picks numbers,
    each table and raw-message panel has messages, the 3D panel's topics exist; returns the panels' ids."""
    messages = as_foxglove_reads(log)
    config = layout["configById"]
    for panel, settings in config.items():
        if panel.startswith("Plot!"):
            for series in settings["paths"]:
                numbers = picked(messages, series["value"])
                assert numbers and all(isinstance(v, (int, float)) for v in numbers), (panel, series["value"])
        elif panel.startswith(("Table!", "RawMessages!")):
            path = settings["topicPath"]
            assert picked(messages, path) if "." in path.split("/")[-1] else messages[path], (panel, path)
        elif panel.startswith("3D!"):
            assert settings["followTf"] == "world"
            for topic in settings["topics"]:
                assert messages[topic], (panel, topic)
    shown = set(re.findall(r"[A-Za-z0-9]+![A-Za-z0-9_]+", json.dumps(layout["layout"])))
    assert shown == set(config)  # every configured panel is placed, and only those
    return sorted(config)


@pytest.fixture(scope="module")
def cars(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("cars")
    (folder / "cars.toml").write_text(TWO_CARS)
    result = cosim_cli("run", "cars.toml", "--out", "cars.mcap", "--quiet", cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder / "cars.mcap"


def test_a_scripted_run_attaches_its_layout_and_cosim_layout_writes_the_same(cars: Path, tmp_path: Path) -> None:
    result = cosim_cli("layout", str(cars), "-o", str(tmp_path / "layout.json"))
    assert result.returncode == 0 and result.stderr == ""
    assert "the 3D scene" in result.stdout and "Layouts -> Import from file" in result.stdout
    written = (tmp_path / "layout.json").read_bytes()
    assert written == read_log(cars, topics=[]).attachments[LAYOUT_ATTACHMENT]
    layout = json.loads(written)
    assert check_layout(layout, cars) == ["3D!scene", "Plot!acceleration", "Plot!contact_force", "Plot!displacement",
                                          "Plot!traffic", "RawMessages!events", "RawMessages!status",
                                          "Table!vehicles"]
    config = layout["configById"]
    assert [p["label"] for p in config["Plot!contact_force"]["paths"]] == ["truck", "car"]  # its own vehicles
    assert [p["value"] for p in config["Plot!displacement"]["paths"]] == [f"{TOPIC_SENSORS}.mid"]
    info = open_log(cars).info
    assert float(info["scene_hz"]) == 10.0 and json.loads(info["contacts"]) == ["truck", "car"]


def test_cosim_layout_never_replaces_a_file_silently_nor_the_log(cars: Path, tmp_path: Path) -> None:
    target = tmp_path / "layout.json"
    target.write_text("mine\n")
    refused = cosim_cli("layout", str(cars), "-o", str(target))
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr == f"cosim: error: {target}: already exists; refusing to overwrite the layout (use --force)\n"
    assert target.read_text() == "mine\n"
    assert cosim_cli("layout", str(cars), "-o", str(target), "--force").returncode == 0
    assert json.loads(target.read_text())["configById"]
    before = cars.read_bytes()
    itself = cosim_cli("layout", str(cars), "-o", str(cars), "--force")
    assert itself.returncode == 2 and "is the log of this command; refusing" in itself.stderr
    assert len(itself.stderr.splitlines()) == 1 and cars.read_bytes() == before
    other = cosim_cli("layout", str(cars), "-o", str(tmp_path / "layout.txt"))
    assert other.returncode == 2 and "expected a name ending in .json" in other.stderr
    missing = cosim_cli("layout", str(tmp_path / "none.mcap"), "-o", str(tmp_path / "new.json"))
    assert missing.returncode == 2 and not (tmp_path / "new.json").exists()


@pytest.mark.parametrize("name", ["paper-double-tee", "paper-bridge-traffic-fixed-weights"])
def test_logs_written_before_layouts_get_one(name: str, tmp_path: Path) -> None:
    log = REGRESSION_LOGS / f"{name}.mcap"
    assert LAYOUT_ATTACHMENT not in open_log(log).attachments
    result = cosim_cli("layout", str(log), "-o", str(tmp_path / "old.json"))
    assert result.returncode == 0, result.stderr
    layout = json.loads((tmp_path / "old.json").read_text())
    panels = check_layout(layout, log)
    assert "3D!scene" not in panels  # no scene in those logs
    forces = [p["value"] for p in layout["configById"]["Plot!contact_force"]["paths"]]
    if name == "paper-double-tee":
        assert forces == [f'{TOPIC_VEHICLES}.vehicles[:]{{id=="QC-{k}"}}.contact_force' for k in (1, 2)]
    else:
        assert forces == [f"{TOPIC_VEHICLES}.vehicles[:].contact_force"]
        assert layout["configById"]["Plot!traffic"]["paths"][0]["value"] == f"{TOPIC_TRAFFIC}.x[:]"


def test_a_sumo_run_draws_its_traffic_in_the_scene(tmp_path: Path) -> None:
    """Real SUMO (the bundled light demand): the vehicles appear in the scene, the lanes are learnt from the
    traffic, and a sensor whose name has a dot is plotted by its field (a protobuf identifier: ``mid_left``,
    whose json_name is the sensor's name; older JSON logs quote it, below)."""
    sumo = tmp_path / "sumo"
    sumo.mkdir()
    for name in ("light.sumocfg", "bridge.net.xml", "vtypes.add.xml", "light.rou.xml"):
        (sumo / name).write_bytes((bundled_networks() / name).read_bytes())
    (tmp_path / "sumo.toml").write_text(SUMO_SMALL)
    result = cosim_cli("run", "sumo.toml", "--out", "run.mcap", "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    log = tmp_path / "run.mcap"
    assert cosim_cli("layout", str(log), "-o", str(tmp_path / "layout.json")).returncode == 0
    layout = json.loads((tmp_path / "layout.json").read_text())
    check_layout(layout, log)
    paths = [p["value"] for p in layout["configById"]["Plot!acceleration"]["paths"]]
    assert paths == [f"{TOPIC_SENSORS}.mid_left"]
    assert [p["label"] for p in layout["configById"]["Plot!acceleration"]["paths"]] == ["mid.left"]
    assert sensor_series(log, ["mid.left"])[1]["mid.left"].size == 2801  # cosim reads it by the sensor's name
    contents = read_log(log, topics=[TOPIC_SCENE, TOPIC_SCENE_STATIC, TOPIC_SCENE_TRANSFORM, TOPIC_VEHICLES])
    scenes = contents.topic(TOPIC_SCENE)
    assert len(scenes) == 701  # 10 Hz over 70 s, and t = 0
    drawn = {e["id"] for m in scenes for e in m["entities"] if e["id"].startswith("vehicle ")}
    on_deck = {v["id"].split("#")[0] for m in contents.topic(TOPIC_VEHICLES) for v in m["vehicles"]}
    assert on_deck and {f"vehicle {v}" for v in on_deck} <= drawn
    lanes = sorted(line["points"][0]["y"] for e in scenes[-1]["entities"] if e["id"] == "wheel paths"
                   for line in e["lines"])
    assert lanes == pytest.approx([-1.875, 1.875], abs=0.01)  # the bundled network's lane centres (docs/sumo.md)


def test_every_sensor_quantity_gets_a_plot_and_a_place_in_the_scene(tmp_path: Path) -> None:
    """Stresses, strains and shear stresses (section points) are plotted and drawn like deck sensors."""
    from cosim.core.sensors import SECTION_POINT_QUANTITIES

    paper = (Path(__file__).resolve().parents[2] / "cosim" / "scenarios" / "paper-double-tee.toml").read_text()
    extra = "".join(f'[[sensors]]\nname = "{q}"\nx = 20.0\ny = 1.0\nz = -0.1\nquantity = "{q}"\n'
                    for q in SECTION_POINT_QUANTITIES)
    assert "duration = 20.0" in paper
    (tmp_path / "all.toml").write_text(paper.replace("[[vehicles]]", extra + "[[vehicles]]", 1)
                                       .replace("duration = 20.0", "duration = 0.5"))
    result = cosim_cli("run", "all.toml", "--out", "all.mcap", "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    layout = json.loads(open_log(tmp_path / "all.mcap").attachments[LAYOUT_ATTACHMENT])
    messages = read_log(tmp_path / "all.mcap").messages
    for q in SECTION_POINT_QUANTITIES:
        series = layout["configById"][f"Plot!{q}"]["paths"]
        assert [p["value"] for p in series] == [f"{TOPIC_SENSORS}.{q}"]
        assert all(isinstance(v, float) for v in picked(messages, series[0]["value"]))
    labels = {label["text"] for e in messages[TOPIC_SCENE_STATIC][0][1]["entities"] for label in e.get("texts", [])}
    assert set(SECTION_POINT_QUANTITIES) <= labels
    spheres = [e["spheres"] for e in messages[TOPIC_SCENE][-1][1]["entities"] if e["id"] == "sensors"][0]
    assert len(spheres) == 4 + len(SECTION_POINT_QUANTITIES)  # the scenario's four sensors and these


def test_the_scene_key_of_output(tmp_path: Path) -> None:
    off = TWO_CARS + "[output]\nscene = false\n"
    (tmp_path / "off.toml").write_text(off)
    assert cosim_cli("run", "off.toml", "--out", "off.mcap", "--quiet", cwd=tmp_path).returncode == 0
    overview = open_log(tmp_path / "off.mcap")
    assert TOPIC_SCENE not in overview.counts and "scene_hz" not in overview.info
    assert "3D!scene" not in json.loads(overview.attachments[LAYOUT_ATTACHMENT])["configById"]
    (tmp_path / "bad.toml").write_text(TWO_CARS + '[output]\nscene = "yes"\n')
    bad = cosim_cli("run", "bad.toml", "--out", "bad.mcap", "--quiet", cwd=tmp_path)
    assert bad.returncode == 2 and not (tmp_path / "bad.mcap").exists()
    assert bad.stderr.splitlines()[0].startswith("cosim: error: bad.toml: output.scene: expected true, false or ")
    (tmp_path / "huge.toml").write_text(TWO_CARS + "[output]\nscene = 1e300\n")
    huge = cosim_cli("run", "huge.toml", "--out", "huge.mcap", "--quiet", cwd=tmp_path)
    assert huge.returncode == 2 and "output.scene" in huge.stderr and "<= 1e+06" in huge.stderr
    (tmp_path / "big.toml").write_text(TWO_CARS + "[output]\nscene = 250\n")
    assert cosim_cli("run", "big.toml", "--out", "big.mcap", "--quiet", cwd=tmp_path).returncode == 0
    assert open_log(tmp_path / "big.mcap").info["scene_exaggeration"] == "250.0"


def test_a_layout_takes_only_names_from_a_log_and_checks_the_rest() -> None:
    """Logs are untrusted: names are quoted into message paths, malformed metadata is one clear error."""
    from cosim.errors import LogError
    from cosim.log.layout import inputs_from_metadata, make_layout

    inputs = inputs_from_metadata({"traffic": "scripted", "contacts": json.dumps(['a"b', "c"])},
                                  ["x y", 'q"t'], ["displacement", "velocity"], "crafted.mcap")
    layout = make_layout(inputs)
    config = layout["configById"]
    assert [p["value"] for p in config["Plot!displacement"]["paths"]] == [f'{TOPIC_SENSORS}."x y"']
    assert [p["value"] for p in config["Plot!velocity"]["paths"]] == [f'{TOPIC_SENSORS}."q\\"t"']
    # an id that cannot be written in a filter: every vehicle in one series instead
    forces = [p["value"] for p in config["Plot!contact_force"]["paths"]]
    assert forces == [f"{TOPIC_VEHICLES}.vehicles[:].contact_force"]
    assert layout["userNodes"] == {} and layout["globalVariables"] == {}
    for info, key in (({"scene_hz": "10.0", "scene_length": "nan"}, "scene_length"),
                      ({"contacts": "{}"}, "contacts")):
        with pytest.raises(LogError, match=f"^crafted.mcap: malformed cosim metadata: {key}"):
            inputs_from_metadata(info, [], [], "crafted.mcap")
