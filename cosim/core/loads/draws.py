"""What is drawn for one vehicle, and from which random numbers (docs/loads.md).

Every draw depends only on the scenario's ``seed`` and the vehicle's id: its
uniforms are the output of SHAKE-256 (an extendable-output hash, FIPS 202) of
the seed, the purpose and the id, so the same vehicle gets the same load in
any process, in any order, on any number of workers, in a replay and in a
study (Python's ``hash()`` is randomised per process and is never used). Each
purpose has its own stream (the load, the lateral wander), so switching
wander on does not change any load. A hash, not numpy's SeedSequence and
PCG64: those cost 50-120 us to set up per vehicle, SHAKE-256 5-10 us
(benchmarks/bench_loads.py), and its output is fixed by a standard.

Values are made from the uniforms by inverse CDFs (cosim's code), not by a
library's distribution methods, whose algorithms may change between releases.
"""
from __future__ import annotations

import hashlib
import math
import operator
import struct
from dataclasses import dataclass
from statistics import NormalDist
from typing import Literal

import numpy as np

from cosim.errors import ConfigError

from .mixture import Mixture, Mode

_STANDARD = NormalDist()

#: Streams of random numbers of one vehicle: one per purpose.
STREAMS = {"load": 1, "wander": 2}

#: BTLS's gravity (``KG100_TO_KN = 0.981`` in ``Vehicle.cpp``): masses in the files to forces, m/s^2.
G = 9.81


def uniforms(seed: int, vehicle_id: str, stream: str, count: int) -> list[float]:
    """``count`` uniforms in [0, 1) for one vehicle and purpose, the same in every process and release.

    They are the top 53 bits of consecutive little-endian 64-bit words of SHAKE-256 (FIPS 202, an
    extendable-output hash) of ``"cosim-loads", seed, stream, vehicle_id`` (UTF-8, NUL-separated).

    Args:
        seed: the scenario's seed, an integer >= 0.
        vehicle_id: the vehicle's id (SUMO's, or the one given to a record); any string.
        stream: ``"load"`` or ``"wander"``.
        count: how many.

    Raises:
        ConfigError: ``seed`` is not an integer >= 0.
    """
    key = f"cosim-loads\x00{check_seed(seed)}\x00{stream}\x00{vehicle_id}".encode()
    words = struct.unpack(f"<{count}Q", hashlib.shake_256(key).digest(8 * count))
    return [(w >> 11) * _TWO_TO_MINUS_53 for w in words]


_TWO_TO_MINUS_53 = 1.0 / 9007199254740992.0


def check_seed(seed: object) -> int:
    """The seed as an int, or a :class:`ConfigError` saying what a seed is."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or int(seed) < 0:
        raise ConfigError(f"seed: expected an integer >= 0 (got {seed!r}); give the scenario's seed, e.g. seed = 1")
    return operator.index(seed)


@dataclass(frozen=True)
class VehicleLoad:
    """The loads drawn for one vehicle: what a vehicle model is later built from.

    Attributes:
        vehicle_id: the vehicle it was drawn for.
        truck_class: Grave's class, the truck's axle count (2-5); 0 for a car.
        direction: the direction whose parameters were used (1 or 2); 0 for a car (one distribution).
        gross_weight: gross vehicle weight, N.
        axle_loads: static load of each axle, N, front axle first; they add up to ``gross_weight`` (1e-9).
        axle_spacings: distance from each axle to the next, m (one fewer than the axles).
        track_widths: each axle's track width (wheel centre to wheel centre), m.
    """

    vehicle_id: str
    truck_class: int
    direction: int
    gross_weight: float
    axle_loads: tuple[float, ...]
    axle_spacings: tuple[float, ...]
    track_widths: tuple[float, ...]

    @property
    def axle_count(self) -> int:
        """Number of axles."""
        return len(self.axle_loads)

    @property
    def wheelbase(self) -> float:
        """First to last axle, m."""
        return math.fsum(self.axle_spacings)


def split(gross_weight: float, shares: list[float]) -> tuple[float, ...]:
    """Axle loads (N) from relative shares, scaled to add up to ``gross_weight``; the last axle takes the
    rounding, so the sum equals the gross weight to the last bit or two."""
    total = math.fsum(shares)
    loads = [gross_weight * s / total for s in shares[:-1]]
    loads.append(gross_weight - math.fsum(loads))
    return tuple(loads)


# --------------------------------------------------------------------------- cars

@dataclass(frozen=True)
class CarModel:
    """The light distribution every car draws from (Grave's model covers trucks only).

    Attributes:
        gross_weight: gross weight, N (a truncated normal).
        wheelbase: front to rear axle, m.
        front_share: the front axle's share of the gross weight.
        track_width: track width of both axles, m.
        source: where the numbers come from.
    """

    gross_weight: Mixture
    wheelbase: Mixture
    front_share: Mixture
    track_width: float
    source: str


def _normal(mean: float, sd: float, lower: float, upper: float, unit: str) -> Mixture:
    return Mixture((Mode(1.0, mean, sd),), lower, upper, unit)


#: The default car: mean mass, wheelbase and front share those of cosim's library car
#: (cosim/sumo/library.py: 1500 kg, 2.7 m, 55 %), spreads cosim's choice (docs/loads.md#cars).
CAR = CarModel(
    gross_weight=_normal(1500.0 * G, 250.0 * G, 800.0 * G, 3500.0 * G, "N"),
    wheelbase=_normal(2.7, 0.15, 2.2, 3.2, "m"),
    front_share=_normal(0.55, 0.03, 0.45, 0.65, "1"),
    track_width=1.55,
    source="cosim's choice: mean of cosim's library car (1500 kg, 2.7 m, 55 % front), sd 250 kg, 0.15 m, 3 %; "
           "at most 3500 kg, the limit of a category B (car) licence, Directive 2006/126/EC Art. 4(4)",
)


def draw_car(seed: int, vehicle_id: str, model: CarModel = CAR) -> VehicleLoad:
    """A car's two axle loads and its wheelbase, from its own light distribution (``model``).

    Each value is a truncated normal drawn by inverse CDF (no rejection: out-of-bounds values are
    impossible, not redrawn). Deterministic per (seed, vehicle id), from the same stream as a truck's load.
    """
    u = uniforms(seed, vehicle_id, "load", 6)
    gross = model.gross_weight.sampler().draw(u[0], u[1])
    wheelbase = model.wheelbase.sampler().draw(u[2], u[3])
    front = model.front_share.sampler().draw(u[4], u[5])
    return VehicleLoad(str(vehicle_id), 0, 0, gross, split(gross, [front, 1.0 - front]), (wheelbase,),
                       (model.track_width, model.track_width))


# --------------------------------------------------------------------------- lateral wander

#: EN 1991-2:2003 4.6.1(5), Figure 4.6: frequency distribution of the transverse location of the centre
#: line of vehicles (offsets from the lane's centre line, m, and their frequencies).
EN1991_2_OFFSETS = (-0.2, -0.1, 0.0, 0.1, 0.2)
EN1991_2_FREQUENCIES = (0.07, 0.18, 0.50, 0.18, 0.07)


def wander(seed: int, vehicle_id: str, kind: Literal["en1991-2", "normal"] = "en1991-2",
           sd: float | None = None, limit: float | None = None) -> float:
    """A vehicle's lateral offset from its lane's centre line, m (positive to the lane's left).

    Args:
        seed, vehicle_id: what the draw depends on (its own stream, independent of the load's).
        kind: ``"en1991-2"``: one of the five offsets of EN 1991-2 Figure 4.6 (0, +-0.1, +-0.2 m with
            50, 18 and 7 %); ``"normal"``: a normal offset with standard deviation ``sd``.
        sd: the normal's standard deviation, m (> 0; only for ``"normal"``).
        limit: for ``"normal"``, truncate to ``[-limit, limit]`` m (inverse CDF, no redraws); None: none.

    Raises:
        ConfigError: an unknown kind, or ``sd``/``limit`` missing or not positive.
    """
    u = uniforms(seed, vehicle_id, "wander", 1)[0]
    if kind == "en1991-2":
        cumulative = 0.0
        for offset, frequency in zip(EN1991_2_OFFSETS, EN1991_2_FREQUENCIES):
            cumulative += frequency
            if u < cumulative:
                return offset
        return EN1991_2_OFFSETS[-1]
    if kind != "normal":
        raise ConfigError(f"wander: unknown kind {kind!r}; expected 'en1991-2' or 'normal'")
    if sd is None or not (isinstance(sd, (int, float)) and math.isfinite(sd) and sd > 0.0):
        raise ConfigError(f"wander: sd must be a number > 0 m for a normal wander (got {sd!r})")
    if limit is None:
        return float(sd) * _STANDARD.inv_cdf(max(u, 1e-300))
    if not (isinstance(limit, (int, float)) and math.isfinite(limit) and limit > 0.0):
        raise ConfigError(f"wander: limit must be a number > 0 m (got {limit!r})")
    return _normal(0.0, float(sd), -float(limit), float(limit), "m").sampler().draw(0.0, u)


#: What a wander setting may be (``[traffic.loads]`` and ``[traffic.records]`` ``wander``): EN 1991-2's
#: distribution, none, or the standard deviation of a normal one (m, truncated at 3 standard deviations).
WANDER_WORDS = ("en1991-2", "none")


def lane_wander(seed: int, vehicle_id: str, setting: str | float) -> float:
    """A vehicle's lateral offset within its lane (m) for a scenario's ``wander`` setting: ``"none"`` (0),
    ``"en1991-2"`` (:func:`wander`'s EN 1991-2 Figure 4.6), or a number, the standard deviation of a normal
    offset (m) truncated to 3 standard deviations."""
    if setting == "none":
        return 0.0
    if setting == "en1991-2":
        return wander(seed, vehicle_id, "en1991-2")
    if isinstance(setting, str):
        raise ConfigError(f"wander: expected {', '.join(WANDER_WORDS)} or a standard deviation in m (got {setting!r})")
    return wander(seed, vehicle_id, "normal", sd=float(setting), limit=3.0 * float(setting))

