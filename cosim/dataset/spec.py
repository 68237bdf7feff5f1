"""The dataset file: a base scenario, windows, damage cases, a temperature cycle and instruments.

``docs/analysis.md`` (§4) documents every key. Nothing here runs anything.
"""
from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, Strict, model_validator

from cosim.core.element import DOF_NAMES
from cosim.errors import ConfigError
from cosim.run.config_base import ConfigModel, Name, NonNegative, Number, Positive, choice, fail, load_config
from cosim.run.scenario import Scenario, list_bundled_scenarios, load_scenario

from .sensor_models import SENSOR_TYPES

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["Dataset", "DamageCase", "load_dataset", "parse_dataset"]



class DatasetSection(ConfigModel):
    """``[dataset]``: the base scenario and the windows."""

    name: Name | None = None
    base: Annotated[str, Strict(), Field(min_length=1)]
    window: Positive
    windows: Annotated[int, Strict(), Field(ge=1, le=100000)]
    spacing: Positive = 3600.0
    start: NonNegative = 0.0
    seed: Annotated[int, Strict(), Field(ge=0)] = 1
    output: Annotated[str, Strict(), Field(min_length=1)] | None = None


class TemperatureSection(ConfigModel):
    """``[temperature]``: a daily cycle of the deck's temperature and how E follows it."""

    mean: Number = 10.0
    amplitude: NonNegative = 0.0
    peak_hour: Annotated[float, Strict(), Field(ge=0, lt=24)] = 15.0
    reference: Number = 10.0
    e_per_kelvin: Annotated[float, Strict(), Field(gt=-0.05, lt=0.05)] = -0.003


class DamageConfig(ConfigModel):
    """``[[damage]]``: a damage state; none of the keys: healthy."""

    name: Name
    x: tuple[Number, Number] | None = None
    stiffness: Annotated[float, Strict(), Field(gt=0, le=1)] = 1.0
    support: Annotated[int, Strict(), Field(ge=0)] | None = None
    dof: Annotated[str, choice(DOF_NAMES, "DOF")] = "w"
    spring: Positive | None = None

    @model_validator(mode="after")
    def _consistent(self) -> DamageConfig:
        if self.x is not None and not self.x[0] < self.x[1]:
            raise fail(f"must be [x_start, x_end] with x_start < x_end (got {list(self.x)})", "x")
        if (self.x is None) != (self.stiffness == 1.0):
            raise fail("a stiffness loss needs both x (the damaged length) and stiffness < 1", "stiffness")
        if (self.support is None) != (self.spring is None):
            raise fail("a degraded support needs both support (its index) and spring (its stiffness)", "spring")
        return self


class InstrumentConfig(ConfigModel):
    """``[[sensors]]``: an instrument on the deck."""

    name: Name
    type: Annotated[str, choice(tuple(SENSOR_TYPES), "sensor type")]
    x: Number
    y: Number = 0.0
    z: Number | None = None
    rate_hz: Positive
    noise: NonNegative = 0.0
    resolution: NonNegative = 0.0

    @model_validator(mode="after")
    def _strain_point(self) -> InstrumentConfig:
        if self.type == "strain_gauge" and self.z is None:
            raise fail("required key is missing: a strain gauge sits at the section point (y, z)", "z")
        if self.type != "strain_gauge" and self.z is not None:
            raise fail("only a strain gauge has z", "z")
        return self


class DatasetFile(ConfigModel):
    dataset: DatasetSection
    temperature: TemperatureSection = TemperatureSection()
    damage: tuple[DamageConfig, ...] = Field(default=(DamageConfig(name="healthy"),), min_length=1)
    sensors: tuple[InstrumentConfig, ...] = Field(min_length=1)


DamageCase = DamageConfig


@dataclass(frozen=True)
class Dataset:
    """A validated dataset file. Build one with :func:`load_dataset` or :func:`parse_dataset`."""

    name: str
    source: str
    text: str
    base: Scenario
    base_data: dict[str, Any]
    output: Path
    window: float
    windows: int
    spacing: float
    start: float
    seed: int
    temperature: TemperatureSection
    damage: tuple[DamageConfig, ...]
    sensors: tuple[InstrumentConfig, ...]

    def temperature_at(self, seconds_of_day: float) -> float:
        """The deck's temperature, deg C, at a time of day (s): mean + amplitude cos(2 pi (h - peak)/24)."""
        t = self.temperature
        hours = (seconds_of_day / 3600.0) % 24.0
        return t.mean + t.amplitude * math.cos(2 * math.pi * (hours - t.peak_hour) / 24.0)

    def e_factor(self, temperature: float) -> float:
        """E(T) / E(reference) = 1 + e_per_kelvin (T - reference)."""
        return 1.0 + self.temperature.e_per_kelvin * (temperature - self.temperature.reference)


def parse_dataset(text: str, source: str = "<dataset>", base_dir: str | os.PathLike[str] = ".",
                  output: str | os.PathLike[str] | None = None) -> Dataset:
    """Validate dataset TOML text and load its base scenario.

    Raises:
        ConfigError: the file is malformed or does not fit its base scenario (the message names the file and key).
    """
    parsed = load_config(text, source, DatasetFile)
    sec = parsed.dataset
    base_path = Path(base_dir) / sec.base
    try:
        base = load_scenario(base_path if base_path.is_file() or sec.base not in list_bundled_scenarios()
                             else sec.base)
    except ConfigError as exc:
        raise ConfigError(f"{source}: dataset.base: {exc}") from None
    if not base.vehicles and base.traffic is None:
        raise ConfigError(f"{source}: dataset.base: the base scenario {base.source} has no [[vehicles]] and no "
                          "[traffic]: nothing loads the bridge")
    length = base.bridge.length
    n_supports = len(base.bridge.spans) + 1
    names = [s.name for s in parsed.sensors]
    for i, sensor in enumerate(parsed.sensors):
        if names.index(sensor.name) != i:
            raise ConfigError(f"{source}: sensors[{i}].name: duplicate sensor name {sensor.name!r}")
        if not 0 <= sensor.x <= length:
            raise ConfigError(f"{source}: sensors[{i}].x: must lie on the bridge, 0 <= x <= {length:g} m "
                              f"(got {sensor.x:g})")
        if sensor.rate_hz > base.output_rate_hz * (1 + 1e-12):
            raise ConfigError(f"{source}: sensors[{i}].rate_hz: at most the base scenario's logging rate, "
                              f"{base.output_rate_hz:g} Hz (got {sensor.rate_hz:g}); raise [output].rate_hz there")
    for i, case in enumerate(parsed.damage):
        if case.x is not None and not (0 <= case.x[0] and case.x[1] <= length):
            raise ConfigError(f"{source}: damage[{i}].x: must lie on the bridge, 0 ... {length:g} m")
        if case.support is not None and case.support >= n_supports:
            raise ConfigError(f"{source}: damage[{i}].support: the bridge has supports 0 ... {n_supports - 1}")
    name = sec.name or (Path(source).stem if source != "<dataset>" else base.title)
    out = Path(output) if output is not None else Path(sec.output or f"datasets/{name}")
    return Dataset(name=name, source=source, text=text, base=base, base_data=tomllib.loads(base.text),
                   output=out.resolve(), window=sec.window, windows=sec.windows, spacing=sec.spacing,
                   start=sec.start, seed=sec.seed, temperature=parsed.temperature, damage=parsed.damage,
                   sensors=parsed.sensors)


def load_dataset(path: str | os.PathLike[str], output: str | os.PathLike[str] | None = None) -> Dataset:
    """Load and validate a dataset file (see :func:`parse_dataset`)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the dataset file ({exc})") from None
    return parse_dataset(text, str(path), base_dir=path.parent, output=output)
