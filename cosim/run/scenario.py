"""Scenario files: TOML in, a frozen and validated :class:`Scenario` out, lowered to core objects.

A scenario describes one bridge (spans, material, cross-section, supports,
damping), its sensors, scripted vehicles or SUMO traffic, the road surface,
the solver settings and where results go; ``docs/scenario.md`` documents
every key with its unit, default and constraints. The tables themselves are
in :mod:`cosim.run.bridge_tables` and :mod:`cosim.run.tables`.

Typical use::

    from cosim.run.scenario import load_scenario

    scenario = load_scenario("paper-double-tee")      # a bundled scenario, or a path
    bridge = scenario.build_bridge()                  # cosim.core.bridge.BridgeModel

The scenario lowers itself to the core's objects one by one:
:meth:`Scenario.build_bridge`, :meth:`Scenario.build_vehicles` (a
:class:`cosim.core.traffic.ScriptedTraffic`), :meth:`Scenario.build_road` (a
:class:`cosim.core.roughness.RoadProfile`), :meth:`Scenario.solver_settings`
and :meth:`Scenario.sensors_core`. Running it (and starting SUMO) is
:mod:`cosim.run.simulate` (in memory) and :mod:`cosim.run.logged` (with a log).

Every problem with a scenario (missing file, TOML syntax, unknown or missing
key, wrong type, non-physical value) raises :class:`cosim.errors.ConfigError`
whose first line names the file and the dotted key, what was expected and what
was found, e.g.::

    paper.toml: bridge.section.plates[0].thickness: must be > 0 (got -0.25)

Numbers are strict: an integer is accepted where a float belongs, a string or a
boolean never is. All objects are frozen; "changing" one means building a new
one (``model_copy(update=...)``).
"""
from __future__ import annotations

import contextlib
import datetime
import math
import os
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from pydantic import (
    Field,
    PrivateAttr,
    Strict,
    ValidationInfo,
    model_validator,
)

from cosim.core.bridge import DOF_NAMES, SUPPORT_PRESETS, BridgeModel, build_bridge
from cosim.core.modal_bridge import ModalBridge
from cosim.core.records_traffic import RecordsCheck, RecordTraffic, check_records
from cosim.core.roughness import (
    RoadProfile,
    iso8608_profile,
    profile_from_csv,
    smooth_road,
)
from cosim.core.section import Material, SectionProperties
from cosim.core.sensors import Sensor
from cosim.core.simulation import SolverSettings
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
from cosim.errors import ConfigError, ModelError
from cosim.sumo.files import number_text

from .bridge_tables import (
    MODE_KINDS,
    BridgeConfig,
    ConstantsConfig,
    DampingConfig,
    MaterialConfig,
    PlateConfig,
    SectionConfig,
)
from .bundled import bundled_folder, list_bundled_scenarios
from .config_base import (
    ConfigModel,
    Problems,
    Text,
    fail,
    load_config,
    show,
    suggest,
)
from .deck_placement import place_on_network
from .records import axle_models, record_lanes
from .tables import (
    QUANTITIES,
    ROAD_CLASSES,
    SUMO_LEVELS,
    VEHICLE_MODELS,
    OutputConfig,
    RecordsConfig,
    RoadConfig,
    SensorConfig,
    SolverConfig,
    TrafficConfig,
    VehicleConfig,
)

# The tables and names of the scenario file are part of its public face (cosim.run.scenario.X).
__all__ = [
    "BridgeConfig",
    "ConstantsConfig",
    "DampingConfig",
    "DOF_NAMES",
    "MODE_KINDS",
    "MaterialConfig",
    "OutputConfig",
    "PlateConfig",
    "QUANTITIES",
    "ROAD_CLASSES",
    "RecordsConfig",
    "RoadConfig",
    "SUMO_LEVELS",
    "SUPPORT_PRESETS",
    "Scenario",
    "SectionConfig",
    "SensorConfig",
    "SolverConfig",
    "TrafficConfig",
    "VEHICLE_MODELS",
    "VehicleConfig",
    "list_bundled_scenarios",
    "load_scenario",
    "parse_scenario",
]

#: Random road profiles cover the deck plus this margin at both ends, m.
ROAD_MARGIN = 10.0
#: With SUMO traffic, random road profiles are laid on wheel paths this far apart across the deck, m.
SUMO_PATH_SPACING = 0.5
#: Without ``solver.duration``, the run lasts until the last vehicle leaves the deck plus this, s.
RING_DOWN = 2.0
DEFAULT_OUTPUT_DIR = "runs"


def _leave_time(vehicle: ScriptedVehicle, length: float) -> float:
    """When ``vehicle`` leaves a deck of ``length`` m, s from the start (inf if it stops on the deck)."""
    end = ScriptedTraffic((vehicle,), length).end_time()
    if math.isfinite(end) or not vehicle.profile:
        return end
    # The profile ends at 0 m/s: the vehicle stops; on the deck, or after leaving it?
    t_last = vehicle.profile[-1][0]
    if float(vehicle.distance(t_last)[0]) <= length:
        return math.inf
    lo, hi = 0.0, t_last  # distance is non-decreasing (speeds >= 0): bisect for distance = length
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if float(vehicle.distance(mid)[0]) > length:
            hi = mid
        else:
            lo = mid
        if hi - lo <= 1e-9 * max(t_last, 1.0):
            break
    return vehicle.entry_time + hi


def _file_name(text: str) -> str:
    """``text`` with anything but letters, digits, '_', '.' and '-' replaced by '_'."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", text) or "scenario"


class Scenario(ConfigModel):
    """A validated scenario: the bridge, its sensors, scripted vehicles, road, solver and output settings.

    Build one with :func:`load_scenario` (file or bundled name) or
    :func:`parse_scenario` (TOML text). ``source`` is where it came from and
    ``text`` the raw TOML, kept for logs.
    """

    name: Annotated[str, Strict(), Field(min_length=1)] | None = None
    description: Text = ""
    bridge: BridgeConfig
    sensors: tuple[SensorConfig, ...] = ()
    vehicles: tuple[VehicleConfig, ...] = ()
    traffic: TrafficConfig | None = None
    road: RoadConfig = RoadConfig()
    solver: SolverConfig = SolverConfig()
    output: OutputConfig = OutputConfig()

    _records_check: RecordsCheck | None = PrivateAttr(default=None)
    _source: str = PrivateAttr(default="<scenario>")
    _text: str = PrivateAttr(default="")
    _base_dir: str = PrivateAttr(default=".")

    def model_post_init(self, context: Any) -> None:  # noqa: D102
        if isinstance(context, dict):
            self._source = str(context.get("source", self._source))
            self._text = str(context.get("text", self._text))
            self._base_dir = str(context.get("base_dir", self._base_dir))

    @model_validator(mode="before")
    @classmethod
    def _modal_solver(cls, data: Any, info: ValidationInfo) -> Any:
        """A deck given by its modes is solved on its modes: ``[solver] basis`` is "modal" whether given or
        not, and it keeps every mode of the file unless ``modes`` or ``cutoff_hz`` says otherwise."""
        if not (isinstance(data, dict) and isinstance(data.get("bridge"), dict) and "modes" in data["bridge"]):
            return data
        solver = data.get("solver", {})
        if not isinstance(solver, dict):
            return data
        if solver.get("basis", "modal") != "modal":
            raise fail(f"a deck given by its modes is solved on its modes: remove basis or write basis = \"modal\" "
                       f"(got {show(solver['basis'])})", "solver", "basis")
        if isinstance(info.context, dict):
            info.context["all_modes"] = True  # SolverConfig: no default count of modes
        return {**data, "solver": {**solver, "basis": "modal"}}

    @model_validator(mode="before")
    @classmethod
    def _default_vehicle_ids(cls, data: Any) -> Any:
        """Vehicles without an ``id`` are "V1", "V2", ... by their position."""
        if isinstance(data, dict) and isinstance(data.get("vehicles"), list):
            data = dict(data)
            data["vehicles"] = [
                {"id": f"V{i + 1}", **item} if isinstance(item, dict) and "id" not in item else item
                for i, item in enumerate(data["vehicles"])
            ]
        return data

    @model_validator(mode="after")
    def _modes_file(self, info: ValidationInfo) -> Scenario:
        """``[bridge] modes``: the file read (bounded, no pickles) and checked before any other check needs the
        deck's extent; its damping and the solver's choice of modes fit it."""
        bridge = self.bridge
        if bridge.modes is None:
            return self
        if bridge.frame == "network" and (self.traffic is None or not self.traffic.sumo):
            raise fail('frame = "network" places the deck by a SUMO network\'s coordinates: give [traffic] '
                       'sumo_config, or give the points in the bridge frame (frame = "bridge")', "bridge", "frame")
        base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
        path = Path(base) / bridge.modes
        if not path.exists():
            raise fail(f"file not found: {path} (a .npz file or a folder of CSV files, docs/modal-decks.md; a "
                       "relative path is relative to the scenario file's folder)", "bridge", "modes")
        from cosim.bridges.files import read_modes

        try:
            deck = read_modes(path, frame=bridge.frame)
        except ConfigError as exc:
            raise fail(str(exc), "bridge", "modes") from None
        if self.solver.method == "quasi-static":
            raise fail('a deck given by its modes runs with method = "dynamic" (the quasi-static method uses the '
                       "beam model's influence lines)", "solver", "method")
        if bridge.frame == "network":
            assert self.traffic is not None
            deck, axis = place_on_network(deck, self.traffic, self.sumo_config_path_in(Path(base)))
            bridge.keep_axis(axis)
        bridge.keep_deck(deck)
        try:  # the deck is in the bridge frame now, wherever its points were given
            built = self.build_modal_bridge()
        except ConfigError as exc:
            raise fail(str(exc).split(": bridge: ", 1)[-1], "bridge", "modes") from None
        for i, sensor in enumerate(self.sensors):
            try:
                built.sensor_row(sensor.to_sensor())
            except ConfigError as exc:
                raise fail(str(exc), "sensors", i) from None
        return self

    def sumo_config_path_in(self, base: Path) -> Path:
        """``[traffic] sumo_config`` resolved (a bundled level, or a file relative to ``base``)."""
        assert self.traffic is not None and self.traffic.sumo_config is not None
        if self.traffic.bundled:
            from cosim.sumo.install import bundled_networks

            return bundled_networks() / f"{self.traffic.sumo_config}.sumocfg"
        return base / self.traffic.sumo_config

    @model_validator(mode="after")
    def _sensors_on_deck(self) -> Scenario:
        problems: list[tuple[tuple[str | int, ...], str]] = []
        length = self.bridge.length
        y_min, y_max = self.bridge.deck_y
        tol_x = 1e-9 * length
        tol_y = 1e-9 * max(y_max - y_min, 1.0)
        seen: dict[str, int] = {}
        for i, sensor in enumerate(self.sensors):
            if sensor.name in seen:
                problems.append(
                    (("sensors", i, "name"),
                     f"duplicate sensor name {show(sensor.name)} (also sensors[{seen[sensor.name]}])")
                )
            seen.setdefault(sensor.name, i)
            if not -tol_x <= sensor.x <= length + tol_x:
                problems.append(
                    (("sensors", i, "x"), f"must lie on the bridge, 0 <= x <= {length:g} m (got {show(sensor.x)})")
                )
            if sensor.z is None and not y_min - tol_y <= sensor.y <= y_max + tol_y:  # (y, z): checked in the section
                problems.append(
                    (("sensors", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {show(sensor.y)})")
                )
        if problems:
            raise Problems(problems)
        return self

    @model_validator(mode="after")
    def _vehicles_fit(self) -> Scenario:
        problems: list[tuple[tuple[str | int, ...], str]] = []
        y_min, y_max = self.bridge.deck_y
        tol_y = 1e-9 * max(y_max - y_min, 1.0)
        seen: dict[str, int] = {}
        for i, vehicle in enumerate(self.vehicles):
            if vehicle.id in seen:
                problems.append(
                    (("vehicles", i, "id"),
                     f"duplicate vehicle id {show(vehicle.id)} (also vehicles[{seen[vehicle.id]}]; "
                     "vehicles without an id are named V1, V2, ... by position)")
                )
            seen.setdefault(vehicle.id, i)
            if not y_min - tol_y <= vehicle.y <= y_max + tol_y:
                problems.append(
                    (("vehicles", i, "y"),
                     f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {show(vehicle.y)})")
                )
        if self.vehicles and self.solver.duration is None and not problems:
            length = self.bridge.length
            for i, vehicle in enumerate(self.vehicles):
                scripted = vehicle.to_scripted()
                if math.isinf(_leave_time(scripted, length)):
                    s_stop = float(scripted.distance(scripted.profile[-1][0])[0])
                    x_stop = s_stop if scripted.direction > 0 else length - s_stop
                    problems.append(
                        (("solver", "duration"),
                         f"required key is missing: vehicles[{i}] ({vehicle.id}) stops on the deck at "
                         f"x = {x_stop:g} m (its speed profile ends at 0 m/s), so the run has no natural end; "
                         "give the simulated time in s")
                    )
                    break
        if problems:
            raise Problems(problems)
        return self

    @model_validator(mode="after")
    def _traffic_fits(self, info: ValidationInfo) -> Scenario:
        traffic = self.traffic
        if traffic is None:
            return self
        if self.vehicles:
            raise fail("give either [traffic] (SUMO) or [[vehicles]] (scripted), not both", "traffic")
        base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
        if traffic.records is not None:
            self._records_fit(traffic.records, Path(base))
        if not traffic.sumo:
            return self
        ratio = traffic.step / self.solver.dt
        if abs(ratio - round(ratio)) > 1e-6 * ratio or round(ratio) < 1:
            raise fail(f"SUMO's step must be a whole number of solver steps: step / solver.dt = "
                        f"{number_text(traffic.step)} / {number_text(self.solver.dt)} = {ratio:.6g}", "traffic", "step")
        length = self.bridge.length
        network_deck = self.bridge.is_modal and self.bridge.frame == "network"  # the axis gives a direction only
        if traffic.axis is not None and not network_deck and abs(math.dist(*traffic.axis) - length) > 1e-3:
            raise fail(f"the axis is {math.dist(*traffic.axis):.6g} m long; it must be the bridge's length, "
                        f"{length:g} m", "traffic", "axis")
        if not traffic.bundled:
            assert traffic.sumo_config is not None
            path = Path(base) / traffic.sumo_config
            if not path.is_file():
                raise fail(f"file not found: {path} (a bundled level: {', '.join(SUMO_LEVELS)}; a relative path "
                            "is relative to the scenario file's folder)", "traffic", "sumo_config")
        return self

    def _records_fit(self, records: RecordsConfig, base: Path) -> None:
        """``[traffic.records]``: its file is there, its lanes lie on the deck."""
        path = base / records.file
        if not path.is_file():
            raise fail(f"file not found: {path} (a relative path is relative to the scenario file's folder)",
                       "traffic", "records", "file")
        y_min, y_max = self.bridge.deck_y
        tol_y = 1e-9 * max(y_max - y_min, 1.0)
        problems: list[tuple[tuple[str | int, ...], str]] = []
        for i, lane in enumerate(records.lanes):
            if not y_min - tol_y <= lane.y <= y_max + tol_y:
                problems.append((("traffic", "records", "lanes", i, "y"),
                                 f"must lie on the deck, {y_min:g} <= y <= {y_max:g} m (got {show(lane.y)})"))
        if problems:
            raise Problems(problems)

    @model_validator(mode="after")
    def _rate_within_steps(self) -> Scenario:
        rate, dt = self.output.rate_hz, self.solver.dt
        if rate is not None and rate * dt > 1.0 + 1e-9:
            raise fail(
                f"must be <= 1 / solver.dt = {number_text(1.0 / dt)} Hz (got {show(rate)}): "
                "the log samples the solver's steps, it cannot be faster than them", "output", "rate_hz"
            )
        return self

    @model_validator(mode="after")
    def _road_file(self, info: ValidationInfo) -> Scenario:
        if self.road.profile is None:
            return self
        base = (info.context or {}).get("base_dir", ".") if isinstance(info.context, dict) else "."
        path = Path(base) / self.road.profile
        if not path.is_file():
            raise fail(
                f"file not found: {path} (a relative path is relative to the scenario file's folder)",
                "road", "profile",
            )
        try:
            road = profile_from_csv(path)
        except ConfigError as exc:
            raise fail(str(exc), "road", "profile") from None
        x_end = road.x0 + road.dx * (road.r.shape[1] - 1)
        length = self.bridge.length
        tol = 1e-6 * max(length, 1.0)
        if road.x0 > tol or x_end < length - tol:
            raise fail(
                f"{path}: the profile covers {road.x0:g} <= x <= {x_end:g} m; it must cover the deck, "
                f"0 <= x <= {length:g} m", "road", "profile",
            )
        return self

    @property
    def source(self) -> str:
        """Where the scenario came from: the file path as given, or the bundled scenario's name."""
        return self._source

    @property
    def text(self) -> str:
        """The raw TOML text the scenario was read from."""
        return self._text

    @property
    def sumo(self) -> bool:
        """Whether the run's traffic is a SUMO simulation (``[traffic] sumo_config``)."""
        return self.traffic is not None and self.traffic.sumo

    @property
    def records(self) -> RecordsConfig | None:
        """The ``[traffic.records]`` table, or None."""
        return self.traffic.records if self.traffic is not None else None

    @property
    def scripted_records(self) -> RecordsConfig | None:
        """The records driven as recorded, without SUMO (``[traffic.records] via = "scripted"``), or None."""
        return self.traffic.scripted_records if self.traffic is not None else None

    @property
    def records_path(self) -> Path | None:
        """The record file of ``[traffic.records]`` (relative to the scenario's folder), or None."""
        records = self.records
        return None if records is None else Path(self._base_dir) / records.file

    @property
    def records_window(self) -> tuple[float, float]:
        """The records that run, ``begin <= time < end`` (s from midnight of the file's first day): ``[traffic.records]
        begin`` and ``end``; with ``via = "sumo"`` also within SUMO's ``[traffic] begin`` and ``end`` (SUMO's clock
        is the records').

        Raises:
            ConfigError: the scenario has no ``[traffic.records]``.
        """
        records, traffic = self.records, self.traffic
        if records is None or traffic is None:
            raise ConfigError(f"{self._source}: the scenario has no [traffic.records]")
        if records.via == "sumo":
            return max(records.begin, traffic.begin), min(records.window_end, traffic.end)
        return records.begin, records.window_end

    def records_check(self) -> RecordsCheck:
        """``[traffic.records]``'s file read and checked once (every line; the lanes mapped by its lanes table,
        times never going backwards; what its window, :attr:`records_window`, holds), before anything is written
        (:func:`cosim.core.records_traffic.check_records`); the same answer afterwards.

        Raises:
            ConfigError: the first bad line of the file (naming it and the line); a window without records.
        """
        if self._records_check is not None:
            return self._records_check
        records, path = self.records, self.records_path
        if records is None or path is None:
            raise ConfigError(f"{self._source}: the scenario has no [traffic.records]")
        begin, end = self.records_window
        check = check_records(path, records.format, record_lanes(records), self.bridge.length, begin, end,
                              key="traffic.records.lanes")
        if check.count == 0:
            summary = check.summary
            window = f"begin = {number_text(records.begin)} s" + (
                f" to end = {number_text(records.window_end)} s" if records.end is not None else " on")
            if records.via == "sumo" and self.traffic is not None:
                window += (f", within SUMO's [traffic] begin = {number_text(self.traffic.begin)} s to "
                           f"end = {number_text(self.traffic.end)} s")
            raise ConfigError(f"{self._source}: traffic.records: no record of {path} lies in the window, {window} "
                              f"(its {summary.count} records run from {number_text(summary.first)} to "
                              f"{number_text(summary.last)} s after midnight of its first day, "
                              f"{summary.origin.isoformat()}); change begin and end")
        self._records_check = check
        return check

    def build_records(self) -> RecordTraffic:
        """``[traffic.records]`` driven as recorded (``via = "scripted"``): a
        :class:`cosim.core.records_traffic.RecordTraffic` on this bridge's length, not started (the file checked
        first: :meth:`records_check`)."""
        records = self.scripted_records
        if records is None:
            raise ConfigError(f'{self._source}: the scenario has no [traffic.records] with via = "scripted"')
        check = self.records_check()
        with self.named("traffic.records"):
            return RecordTraffic(check.path, records.format, record_lanes(records), self.bridge.length,
                                 begin=records.begin, end=records.window_end,
                                 lanes_per_direction=check.lanes_per_direction,
                                 models=axle_models(records.axle_model), wander=records.wander,
                                 seed=records.seed if records.seed is not None else 0)

    @property
    def base_dir(self) -> Path:
        """The folder relative paths of the scenario (``road.profile``, ``traffic.sumo_config``) start from."""
        return Path(self._base_dir)

    @property
    def title(self) -> str:
        """The scenario's name, or the file's stem when it has none."""
        if self.name:
            return self.name
        return Path(self._source).stem or self._source

    def material(self) -> Material:
        """The bridge's :class:`cosim.core.section.Material`."""
        return self.bridge.beam_material.to_material()

    def build_section(self) -> SectionProperties:
        """The bridge's section constants (runs the FE section solver for plates).

        Raises:
            ConfigError, ModelError: the section cannot be built (e.g. plates that do
                not touch); the message names the scenario and ``bridge.section``.
        """
        with self.named("bridge.section"):
            return self.bridge.beam_section.build(nu=self.bridge.beam_material.poisson)

    def build_bridge(self) -> BridgeModel | ModalBridge:
        """The bridge: the finite-element beam model (:func:`cosim.core.bridge.build_bridge`), or the deck given
        by its modes (:class:`cosim.core.modal_bridge.ModalBridge`, with ``[solver] modes``/``cutoff_hz``
        keeping the first of them).

        Raises:
            ConfigError, ModelError: the section or the model cannot be built (e.g. a
                damping mode that the model does not have); the message names the
                scenario and the table.
        """
        bridge = self.bridge
        if bridge.is_modal:
            return self.build_modal_bridge()
        return self.build_beam()

    def build_modal_bridge(self) -> ModalBridge:
        """The deck given by its modes (``[bridge] modes``), placed in the bridge frame, with the modes the run
        keeps (``[solver] modes``/``cutoff_hz``) and ``[bridge.damping]`` (else the file's ``zeta``)."""
        bridge = self.bridge
        with self.named("bridge"):
            deck = bridge.deck.select(self.solver.modes, self.solver.cutoff_hz)
            damping = bridge.damping.to_damping() if bridge.damping is not None else None
            axis = bridge.network_axis
            placement = ("the bridge frame (the modes file's points)" if axis is None else
                         f"network coordinates, placed on the axis ({axis[0][0]:.3f}, {axis[0][1]:.3f}) -> "
                         f"({axis[1][0]:.3f}, {axis[1][1]:.3f})")
            return ModalBridge(deck, damping, placement=placement)

    def build_beam(self) -> BridgeModel:
        """The finite-element beam model (:func:`cosim.core.bridge.build_bridge`)."""
        bridge = self.bridge
        if bridge.is_modal:
            raise ConfigError(f"{self._source}: bridge: a deck given by its modes ({bridge.modes}) has no beam model: "
                              "cosim modes and cosim static describe beams (the file's frequencies are in the header "
                              "of cosim run and in its log's modes.json)")
        section = self.build_section()
        with self.named("bridge"):
            return build_bridge(
                spans=bridge.spans,
                elements_per_span=bridge.elements_per_span,
                material=self.material(),
                section=section,
                supports=bridge.supports,
                damping=bridge.damping.beam_damping() if bridge.damping is not None else None,
                theory=bridge.theory(),
            )

    @property
    def modes_path(self) -> Path | None:
        """The modes file of ``[bridge] modes`` (resolved against the scenario's folder), or None."""
        if self.bridge.modes is None:
            return None
        return Path(self._base_dir) / self.bridge.modes

    @property
    def road_profile_path(self) -> Path | None:
        """The road profile file (``road.profile`` resolved against the scenario's folder), or None."""
        if self.road.profile is None:
            return None
        return Path(self._base_dir) / self.road.profile

    @property
    def csv_path(self) -> Path | None:
        """The extra sensor CSV, ``output.csv`` (relative to the current folder), or None."""
        return Path(self.output.csv) if self.output.csv is not None else None

    @property
    def log_path(self) -> Path | None:
        """The MCAP log of a run, ``output.log`` (relative to the current folder), or None for the default."""
        return Path(self.output.log) if self.output.log is not None else None

    def default_log_path(self, started: datetime.datetime | None = None, suffix: str = "") -> Path:
        """``runs/<title><suffix>-<YYYYmmdd-HHMMSS>.mcap`` (relative to the current folder)."""
        stamp = (started or datetime.datetime.now()).strftime("%Y%m%d-%H%M%S")
        return Path(DEFAULT_OUTPUT_DIR) / f"{_file_name(self.title)}{suffix}-{stamp}.mcap"

    @property
    def output_every(self) -> int:
        """Solver steps per logged sample (``[output]`` rate_hz or every, with ``solver.dt``)."""
        return self.output.decimation(self.solver.dt)

    @property
    def output_rate_hz(self) -> float:
        """The logging rate actually used, Hz: ``1 / (output_every * dt)``."""
        return 1.0 / (self.output_every * self.solver.dt)

    @property
    def leave_time(self) -> float | None:
        """When the last scripted vehicle leaves the deck, s (inf if one stops on it; None without vehicles)."""
        if not self.vehicles:
            return None
        length = self.bridge.length
        return max(_leave_time(v.to_scripted(), length) for v in self.vehicles)

    @property
    def duration(self) -> float:
        """Simulated time, s: ``solver.duration``, default :attr:`leave_time` + 2 s.

        Raises:
            ConfigError: no ``solver.duration`` and no vehicles to take it from.
        """
        if self.solver.duration is not None:
            return self.solver.duration
        if self.scripted_records is not None:
            return self.records_check().leave + RING_DOWN
        if self.traffic is not None:
            return self.traffic.end - self.traffic.begin
        leave = self.leave_time
        if leave is None:
            raise ConfigError(
                f"{self._source}: solver.duration: required key is missing "
                "(without [[vehicles]] there is no default simulated time)"
            )
        return leave + RING_DOWN

    def build_vehicles(self) -> ScriptedTraffic:
        """The scripted vehicles as a :class:`cosim.core.traffic.ScriptedTraffic` on this bridge's length."""
        with self.named("vehicles"):
            return ScriptedTraffic(tuple(v.to_scripted(self.solver.gravity) for v in self.vehicles), self.bridge.length)

    def wheel_paths(self) -> tuple[float, ...]:
        """Lateral offsets with a road profile of their own, sorted, m.

        Scripted vehicles: their distinct offsets; records driven as recorded
        without wander: their lanes'. SUMO traffic (and records with wander):
        paths every 0.5 m across the deck (a wheel uses the nearest), since
        lanes and lateral positions come from SUMO. Otherwise ``(0.0,)``.
        """
        records = self.scripted_records
        if records is not None and records.wander == "none":
            return tuple(sorted({lane.y for lane in records.lanes}))
        if self.traffic is not None:
            y_min, y_max = self.bridge.deck_y
            n = int(math.floor((y_max - y_min) / SUMO_PATH_SPACING)) + 1
            return tuple(float(v) for v in y_min + SUMO_PATH_SPACING * np.arange(n))
        return tuple(sorted({v.y for v in self.vehicles})) or (0.0,)

    @property
    def sumo_config_path(self) -> Path | None:
        """The SUMO config of ``[traffic]`` (a bundled level or a file relative to the scenario), or None."""
        if self.traffic is None or self.traffic.sumo_config is None:
            return None
        return self.sumo_config_path_in(Path(self._base_dir))

    def build_road(self) -> RoadProfile:
        """The road profile, one wheel path per distinct vehicle offset (:meth:`wheel_paths`).

        A random class covers -10 m <= x <= L + 10 m (L the bridge length) with
        independent profiles per path, all drawn from ``road.seed``; a profile
        file is used on every path; no ``[road]`` or ``class = "smooth"`` is a
        smooth road.
        """
        road = self.road
        paths = self.wheel_paths()
        with self.named("road"):
            if road.random:
                assert road.road_class is not None and road.seed is not None
                return iso8608_profile(
                    road.road_class, road.seed, -ROAD_MARGIN, self.bridge.length + ROAD_MARGIN, path_y=paths
                )
            path = self.road_profile_path
            if path is None:
                return smooth_road()
            one = profile_from_csv(path)
            n = len(paths)
            return RoadProfile(
                path_y=paths, x0=one.x0, dx=one.dx,
                r=np.repeat(one.r, n, axis=0), r_x=np.repeat(one.r_x, n, axis=0),
                description=f"{one.description} on {n} path(s)",
            )

    def solver_settings(self) -> SolverSettings:
        """The :class:`cosim.core.simulation.SolverSettings` of ``[solver]``."""
        return self.solver.to_settings()

    def sensors_core(self) -> list[Sensor]:
        """The ``[[sensors]]`` as :class:`cosim.core.simulation.Sensor` objects."""
        return [s.to_sensor() for s in self.sensors]

    @contextlib.contextmanager
    def named(self, key: str) -> Iterator[None]:
        """Within the block, errors of the numerical core are prefixed with this scenario's source and ``key``
        (``with scenario.named("traffic"): ...`` -> "paper.toml: traffic: <message>")."""
        try:
            yield
        except (ConfigError, ModelError) as exc:
            raise type(exc)(f"{self._source}: {key}: {exc}") from exc


# --------------------------------------------------------------------------- loading

def parse_scenario(
    text: str, source: str = "<scenario>", base_dir: str | os.PathLike[str] = "."
) -> Scenario:
    """Validate scenario TOML text.

    Args:
        text: the TOML document.
        source: how to name it in error messages (usually the file path).
        base_dir: the folder relative paths in the scenario (``road.profile``)
            are resolved against: the scenario file's folder.

    Raises:
        ConfigError: syntax error, unknown/missing key, wrong type or non-physical value.
    """
    context = {"source": source, "text": text, "base_dir": os.fspath(base_dir)}
    return load_config(text, source, Scenario, context=context)


def load_scenario(path_or_name: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario.

    Args:
        path_or_name: a path to a ``.toml`` file, or the name of a bundled scenario
            (see :func:`list_bundled_scenarios`), e.g. ``"paper-double-tee"``.

    Returns:
        The frozen, validated :class:`Scenario`.

    Raises:
        ConfigError: the file is missing or unreadable, or its content is invalid.
    """
    source = os.fspath(path_or_name)
    path = Path(source)
    if path.is_file():
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"{source}: cannot read scenario file ({exc})") from None
        return parse_scenario(text, source, base_dir=path.parent)
    bundled = list_bundled_scenarios()
    if source in bundled:
        folder = bundled_folder()
        resource = folder.joinpath(f"{source}.toml")
        return parse_scenario(resource.read_text(encoding="utf-8"), source, base_dir=str(folder))
    if path.is_dir():
        raise ConfigError(f"{source}: is a directory, expected a scenario .toml file")
    listed = ", ".join(bundled) or "none"
    hint = suggest(source, bundled)
    hint_text = f'; did you mean "{hint}"?' if hint else ""
    raise ConfigError(f"{source}: no such scenario file{hint_text} (bundled scenarios: {listed})")
