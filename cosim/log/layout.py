"""A Foxglove layout made for one run: its sensors by quantity, its vehicles, the traffic and the 3D scene.

:func:`make_layout` builds the layout (Foxglove's layout JSON: ``configById``,
``layout``, ...) from what a run is made of; :func:`layout_for_log` builds
the same from what a log records (its "cosim" metadata record), so a run's
attached layout (:data:`cosim.log.schemas.LAYOUT_ATTACHMENT`) and ``cosim
layout LOG.mcap`` agree, and logs written before layouts existed get one
too. Nothing is copied from the log but names, which are quoted in the
message paths: a layout never carries a log's text (such as user scripts)
into Foxglove.

Panels: a plot per sensor quantity with every sensor of that quantity (SI
units), the contact force of each vehicle (or of every vehicle on the deck
when they are many or unknown before the run, as with SUMO), the positions
of the traffic near the deck (SUMO frames) or of the vehicles on it, a table
of the vehicles on the deck, the events and the run's status, and the 3D
scene when the log has one.
"""
from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from cosim.core.sensors import SENSOR_UNITS
from cosim.errors import LogError

from .reader import LogOverview
from .schemas import (
    TOPIC_EVENTS,
    TOPIC_SCENE,
    TOPIC_SCENE_STATIC,
    TOPIC_SENSORS,
    TOPIC_STATUS,
    TOPIC_TRAFFIC,
    TOPIC_VEHICLES,
    WORLD_FRAME,
)

__all__ = ["LayoutInputs", "MAX_SERIES", "inputs_from_log", "inputs_from_metadata", "layout_bytes", "layout_for_log",
           "make_layout"]

#: More contact points than this get one series for all of them (a legend of hundreds helps nobody).
MAX_SERIES = 12
_QUANTITY_TITLES = {
    "displacement": "deck displacement",
    "velocity": "deck velocity",
    "acceleration": "deck acceleration",
    "bending_moment": "bending moment",
    "stress": "normal stress",
    "strain": "strain",
    "shear_stress_xy": "shear stress xy",
    "shear_stress_xz": "shear stress xz",
}
_PLAIN_NAME = re.compile(r"^[A-Za-z0-9_-]+$")


@dataclass(frozen=True)
class LayoutInputs:
    """What a run's layout shows.

    Attributes:
        sensors: (name, quantity) of each sensor channel, in log order ("" when the log does not say).
        contacts: the contact points' ids (scripted vehicles, known before the run), or None.
        sumo: the traffic came from SUMO (``/cosim/traffic`` holds its frames).
        scene: the log has the 3D scene; scene_length: the bridge's length, m (for the camera).
        protobuf: the messages are protobuf (a sensor's field is :func:`cosim.log.proto.sensor_fields`' name).
    """

    sensors: tuple[tuple[str, str], ...]
    contacts: tuple[str, ...] | None
    sumo: bool
    scene: bool
    scene_length: float = 0.0
    protobuf: bool = False


def _field(name: str) -> str:
    """A field in a Foxglove message path: plain, or quoted (names with dots)."""
    if _PLAIN_NAME.match(name):
        return name
    return '"' + name.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _plot(title: str, series: Sequence[tuple[str, str]]) -> dict[str, Any]:
    """A Plot panel over time with (message path, legend label) series."""
    return {
        "title": title,
        "paths": [{"value": path, "enabled": True, "timestampMethod": "receiveTime", "label": label}
                  for path, label in series],
        "showXAxisLabels": True,
        "showYAxisLabels": True,
        "showLegend": True,
        "legendDisplay": "floating",
        "showPlotValuesInLegend": False,
        "isSynced": True,
        "xAxisVal": "timestamp",
        "sidebarDimension": 240,
    }


def _raw(topic: str) -> dict[str, Any]:
    return {"topicPath": topic, "diffEnabled": False, "diffMethod": "custom", "diffTopicPath": "",
            "showFullMessageForDiff": False, "expansion": "all"}


def _scene_panel(length: float) -> dict[str, Any]:
    """The 3D panel: the scene seen from above one end and the right side, the whole bridge in view."""
    extent = max(length, 10.0) + 24.0  # the approaches drawn around the deck
    grid = 10.0 * math.ceil(1.6 * extent / 10.0)
    return {
        "cameraState": {"distance": round(0.68 * extent, 1), "perspective": True, "phi": 66.0, "thetaOffset": 15.0,
                        "target": [0, 0, 0], "targetOffset": [0, 0, 0], "targetOrientation": [0, 0, 0, 1],
                        "fovy": 45, "near": 0.5, "far": 5000},
        "followMode": "follow-pose",
        "followTf": WORLD_FRAME,
        # The bridge frame's axes at the first support (x along the bridge, y left, z up); no frame links.
        "scene": {"enableStats": False, "transforms": {"showLabel": False, "axisScale": 2.0, "lineWidth": 0}},
        "transforms": {f"frame:{WORLD_FRAME}": {"visible": False}},
        "topics": {TOPIC_SCENE: {"visible": True}, TOPIC_SCENE_STATIC: {"visible": True}},
        "layers": {"grid": {"visible": True, "frameLocked": True, "label": "Grid", "instanceId": "grid",
                            "layerId": "foxglove.Grid", "frameId": WORLD_FRAME, "size": grid,
                            "divisions": int(grid / 5.0), "lineWidth": 1, "color": "#248eff40",
                            "position": [0, 0, -1.2], "rotation": [0, 0, 0]}},
        "publish": {"type": "point", "poseTopic": "/move_base_simple/goal", "pointTopic": "/clicked_point",
                    "poseEstimateTopic": "/initialpose", "poseEstimateXDeviation": 0.5,
                    "poseEstimateYDeviation": 0.5, "poseEstimateThetaDeviation": 0.26179939},
        "imageMode": {},
    }


def _split(direction: str, panels: Sequence[Any], weights: Sequence[float] | None = None) -> Any:
    """A mosaic tree over ``panels`` in one direction, each taking its share (by ``weights``)."""
    weights = list(weights) if weights is not None else [1.0] * len(panels)
    if len(panels) == 1:
        return panels[0]
    first = weights[0] / sum(weights)
    return {"direction": direction, "first": panels[0], "second": _split(direction, panels[1:], weights[1:]),
            "splitPercentage": round(100.0 * first, 1)}


def make_layout(inputs: LayoutInputs) -> dict[str, Any]:
    """The Foxglove layout of a run (see the module's description)."""
    config: dict[str, Any] = {}
    groups: dict[str, list[str]] = {}
    for name, quantity in inputs.sensors:
        groups.setdefault(quantity if quantity in SENSOR_UNITS else "", []).append(name)
    plots = []
    if inputs.protobuf:  # the sensor's field in the message (its name, where that is a protobuf identifier)
        from .proto import sensor_fields

        field = dict(zip((n for n, _ in inputs.sensors), sensor_fields(n for n, _ in inputs.sensors)))
    else:
        field = {n: _field(n) for n, _ in inputs.sensors}
    for quantity, names in groups.items():
        key = f"Plot!{quantity or 'sensors'}"
        title = (f"{_QUANTITY_TITLES[quantity]}, {SENSOR_UNITS[quantity]}" if quantity else "sensors, SI units")
        config[key] = _plot(title, [(f"{TOPIC_SENSORS}.{field[n]}", n) for n in names])
        plots.append(key)
    contacts = inputs.contacts
    if contacts is not None and 0 < len(contacts) <= MAX_SERIES and all('"' not in c for c in contacts):
        forces = [(f'{TOPIC_VEHICLES}.vehicles[:]{{id=="{c}"}}.contact_force', c) for c in contacts]
        positions = [(f'{TOPIC_VEHICLES}.vehicles[:]{{id=="{c}"}}.x', c) for c in contacts]
    else:
        forces = [(f"{TOPIC_VEHICLES}.vehicles[:].contact_force", "each vehicle on the deck")]
        positions = [(f"{TOPIC_VEHICLES}.vehicles[:].x", "each vehicle on the deck")]
    config["Plot!contact_force"] = _plot("contact force of the vehicles on the deck, N (compression positive)",
                                         forces)
    if inputs.sumo:
        config["Plot!traffic"] = _plot("SUMO traffic near the deck: position along the bridge, m",
                                       [(f"{TOPIC_TRAFFIC}.x[:]", "each vehicle near the deck")])
    else:
        config["Plot!traffic"] = _plot("vehicles on the deck: position along the bridge, m", positions)
    config["Table!vehicles"] = {"topicPath": f"{TOPIC_VEHICLES}.vehicles"}
    config["RawMessages!events"] = _raw(TOPIC_EVENTS)
    config["RawMessages!status"] = _raw(TOPIC_STATUS)
    side = _split("column", ["Plot!contact_force", "Plot!traffic", "Table!vehicles",
                             _split("row", ["RawMessages!events", "RawMessages!status"])], [1.0, 1.0, 0.9, 0.8])
    sensor_plots = _split("row" if inputs.scene else "column", plots) if plots else None
    if inputs.scene:
        config["3D!scene"] = _scene_panel(inputs.scene_length)
        main: Any = _split("column", ["3D!scene", sensor_plots], [1.5, 1.0]) if sensor_plots else "3D!scene"
    else:
        main = sensor_plots if sensor_plots is not None else "Plot!contact_force"
    layout = _split("row", [main, side], [62.0, 38.0]) if main != "Plot!contact_force" else side
    return {"configById": config, "globalVariables": {}, "userNodes": {}, "playbackConfig": {"speed": 1.0},
            "layout": layout}


def layout_bytes(layout: dict[str, Any]) -> bytes:
    """The layout as the JSON file Foxglove imports (*Layouts -> Import from file*)."""
    return (json.dumps(layout, indent=1, ensure_ascii=False) + "\n").encode()


def _json_strings(info: dict[str, str], key: str, where: str) -> tuple[str, ...] | None:
    text = info.get(key)
    if text is None:
        return None
    try:
        value = json.loads(text)
    except (ValueError, RecursionError):
        value = None
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise LogError(f"{where}: malformed cosim metadata: {key}: expected a JSON array of strings")
    return tuple(value)


def inputs_from_metadata(info: dict[str, str], sensor_names: Sequence[str], quantities: Sequence[str],
                         where: str = "the log") -> LayoutInputs:
    """What a run's layout shows, from its "cosim" metadata record and sensor channels (``where`` names the log).

    The same for a run that is starting (its attached layout) and for its log read back (``cosim layout``).

    Raises:
        LogError: the metadata's contact ids or scene length are malformed.
    """
    contacts = _json_strings(info, "contacts", where)
    if contacts is None and info.get("traffic") == "scripted":
        contacts = _json_strings(info, "vehicles", where)  # logs before "contacts": a vehicle's only contact
    length = 0.0
    scene = "scene_hz" in info
    if scene:
        try:
            length = float(info.get("scene_length", "nan"))
        except ValueError:
            length = math.nan
        if not (math.isfinite(length) and length > 0):
            raise LogError(f"{where}: malformed cosim metadata: scene_length = {info.get('scene_length', '')[:40]!r}")
    # SUMO's frames are logged by a run with SUMO, not by a replay of one (it re-drives them).
    sumo = info.get("traffic") == "sumo" and info.get("kind") != "replay"
    return LayoutInputs(sensors=tuple(zip(sensor_names, quantities)), contacts=contacts, sumo=sumo, scene=scene,
                        scene_length=length, protobuf=info.get("encoding") == "protobuf")


def inputs_from_log(overview: LogOverview) -> LayoutInputs:
    """What a log's layout shows (:func:`inputs_from_metadata` of its record)."""
    return inputs_from_metadata(overview.info, overview.sensor_names, overview.quantities, str(overview.path))


def layout_for_log(overview: LogOverview) -> dict[str, Any]:
    """The layout of the run a log records (:func:`make_layout` of :func:`inputs_from_log`)."""
    return make_layout(inputs_from_log(overview))
