"""Scripted scenario tests: build and run scenarios in Python, and assert on named results.

A test builds a scenario from a file (or a bundled name, or TOML text, or
plain dicts), changes what it wants, runs it and checks a number::

    from cosim import testing as ct

    def test_truck_daf():
        res = ct.run("examples/scenarios/truck-40t-class-b.toml", road={"class": "B", "seed": 3})
        ct.assert_daf_below(res, "mid", 1.2)

Overrides are the scenario's tables as dicts, merged into the base: a table
is merged key by key (``solver={"dt": 0.002}`` keeps the other solver keys),
``None`` removes a key (``road={"profile": None, "class": "A", "seed": 1}``),
and arrays of tables (``vehicles``, ``sensors``) are replaced as a whole.
Whatever is built is validated exactly like a scenario file.

:func:`run` returns :class:`Results`: the sensor channels by name (``res["mid"]``,
``res.t``), each vehicle's samples (``res.vehicle("truck")["body_acceleration"]``),
peaks over every time step, and the quasi-static run of the same traffic
behind the dynamic amplification factor (``res.daf("mid")``). Scenarios with
``[traffic]`` (SUMO) run through a log (a temporary one unless ``log=`` names
it); scripted ``[[vehicles]]`` run in memory unless ``log=`` is given.

Helpers: :func:`peak`, :func:`daf`, :func:`spectrum`, :func:`dominant_frequency`,
and assertions that say what was expected and what came out:
:func:`assert_peak_below`, :func:`assert_daf_below`,
:func:`assert_deflection_below`, :func:`assert_matches_log`.

As a pytest plugin (entry point ``cosim = "cosim.testing"``) it adds the
fixtures ``run_scenario`` (``run`` with logs in the test's temporary folder),
``cosim_bridge`` (built bridges, cached for the session) and
``cosim_log_snapshot`` (compare a result with a log stored next to the test;
``pytest --cosim-update-logs`` writes them).
"""
from __future__ import annotations

import copy
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import BridgeModel
from cosim.core.fields import VEHICLE_NUMBERS
from cosim.core.quasistatic import QuasiStaticResult, quasi_static
from cosim.errors import ConfigError
from cosim.run.config_base import load_config
from cosim.run.scenario import Scenario, load_scenario, parse_scenario
from cosim.run.simulate import scripted_traffic

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

try:  # the fixtures need pytest; the library part does not
    import pytest
except ImportError:  # pragma: no cover - pytest is a test dependency
    pytest = None  # type: ignore[assignment]

__all__ = [
    "Results",
    "assert_daf_below",
    "assert_deflection_below",
    "assert_matches_log",
    "assert_peak_below",
    "bridge",
    "daf",
    "dominant_frequency",
    "moving_force",
    "peak",
    "quarter_car",
    "run",
    "scenario",
    "sensor",
    "spectrum",
]

#: Default tolerances of :func:`assert_matches_log`: relative to the stored channel's peak, and absolute.
DEFAULT_RTOL = 1e-6
DEFAULT_ATOL = 0.0


# --------------------------------------------------------------------------- building scenarios


def _merge(base: dict[str, Any], changes: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with ``changes``: tables merged key by key, None removes, anything else replaces."""
    out = dict(base)
    for key, value in changes.items():
        if value is None:
            out.pop(key, None)
        elif isinstance(value, Mapping) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        elif isinstance(value, Mapping):
            out[key] = _merge({}, value)
        elif isinstance(value, (list, tuple)) and value and all(isinstance(v, Mapping) for v in value):
            out[key] = [_merge({}, v) for v in value]
        else:
            out[key] = copy.deepcopy(list(value) if isinstance(value, tuple) else value)
    return out


def _base(base: Scenario | str | os.PathLike[str] | Mapping[str, Any] | None
          ) -> tuple[dict[str, Any], str, Path]:
    """(data, source, folder for relative paths) of whatever names the base scenario."""
    if base is None:
        return {}, "<test scenario>", Path.cwd()
    if isinstance(base, Scenario):
        return tomllib.loads(base.text), base.source, base.base_dir
    if isinstance(base, Mapping):
        return _merge({}, base), "<test scenario>", Path.cwd()
    text = os.fspath(base)
    if "\n" in text or "[" in text:  # TOML text rather than a path or a bundled name
        return load_config(text, "<test scenario>"), "<test scenario>", Path.cwd()
    loaded = load_scenario(text)
    return tomllib.loads(loaded.text), loaded.source, loaded.base_dir


def scenario(base: Scenario | str | os.PathLike[str] | Mapping[str, Any] | None = None,
             **overrides: Any) -> Scenario:
    """A validated :class:`cosim.run.scenario.Scenario` from a base and overrides.

    Args:
        base: a scenario file path, a bundled scenario name, TOML text, a dict of
            tables, a :class:`Scenario`, or None (everything from ``overrides``).
        overrides: top-level keys and tables (``name``, ``bridge``, ``sensors``,
            ``vehicles``, ``traffic``, ``road``, ``solver``, ``output``), merged into the base.

    Raises:
        ConfigError: the result is not a valid scenario (same messages as for a file).
    """
    if isinstance(base, Scenario) and not overrides:
        return base
    data, source, folder = _base(base)
    data = _merge(data, overrides)
    from cosim.run.toml_writer import toml_dumps

    try:
        text = toml_dumps(data)
    except ValueError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return parse_scenario(text, source, base_dir=folder)


def bridge(length: float | Sequence[float] = 40.0, *, elements_per_span: int = 20, E: float = 35e9,
           nu: float = 0.2, rho: float = 2500.0, A: float = 6.0, I_y: float = 3.0, I_z: float = 50.0,
           J: float = 5.0, z_c: float = -0.8, deck_y: tuple[float, float] = (-5.0, 5.0),
           supports: Sequence[str] | None = None, damping: float | None = 0.02) -> dict[str, Any]:
    """The ``[bridge]`` table of a straight girder with explicit section constants (SI units).

    The defaults are a 40 m concrete girder (first vertical frequency about
    2.6 Hz) with a 10 m deck. ``length`` is one span or a list of spans;
    supports default to pinned at x = 0 and fork elsewhere; ``damping`` is the
    Rayleigh ratio at the first vertical and torsional modes (None: undamped).
    """
    spans = [float(length)] if isinstance(length, (int, float)) else [float(s) for s in length]
    table: dict[str, Any] = {
        "spans": spans,
        "elements_per_span": elements_per_span,
        "supports": list(supports) if supports is not None else ["pinned"] + ["fork"] * len(spans),
        "material": {"E": E, "nu": nu, "rho": rho},
        "section": {"constants": {"A": A, "I_y": I_y, "I_z": I_z, "J": J, "z_c": z_c, "deck_y": list(deck_y)}},
    }
    if damping is not None:
        table["damping"] = {"ratios": [damping, damping], "modes": ["vertical-1", "torsion-1"]}
    return table


def sensor(name: str, x: float, y: float = 0.0, quantity: str = "displacement") -> dict[str, Any]:
    """One ``[[sensors]]`` table."""
    return {"name": name, "x": float(x), "y": float(y), "quantity": quantity}


def quarter_car(id: str, mass: float, y: float, speed: float, *, f_body: float = 1.5, zeta: float = 0.1,
                wheel_share: float = 0.1, entry_time: float = 0.0, direction: str = "+x") -> dict[str, Any]:
    """A ``[[vehicles]]`` quarter-car of gross ``mass`` (kg), body bounce ``f_body`` (Hz), damping ratio ``zeta``.

    ``wheel_share`` of the mass is the wheel (unsprung); the body is the rest.
    """
    m_w = wheel_share * mass
    m_v = mass - m_w
    k_v = m_v * (2.0 * math.pi * f_body) ** 2
    return {"id": id, "model": "quarter-car", "m_v": m_v, "m_w": m_w, "k_v": k_v,
            "c_v": 2.0 * zeta * math.sqrt(k_v * m_v), "y": float(y), "speed": float(speed),
            "entry_time": float(entry_time), "direction": direction}


def moving_force(id: str, mass: float, y: float, speed: float, *, entry_time: float = 0.0,
                 direction: str = "+x") -> dict[str, Any]:
    """A ``[[vehicles]]`` moving force ``mass * g`` (no inertia)."""
    return {"id": id, "model": "moving-force", "mass": float(mass), "y": float(y), "speed": float(speed),
            "entry_time": float(entry_time), "direction": direction}


# --------------------------------------------------------------------------- results


@dataclass
class Results:
    """A run's results with named channels.

    Attributes:
        scenario: what ran.
        t: sample times, s (from 0, at the scenario's logging rate).
        channels: sensor name -> samples (SI: m, m/s, m/s^2, N m).
        quantities: sensor name -> quantity.
        extremes: sensor name -> (min, max) over *every* time step.
        vehicle_ids: the vehicles that were on the deck.
        duration: simulated time, s.
        liftoff_events: how often a wheel's contact force turned negative.
        max_on_deck: most vehicles on the deck at once.
        contact_force_range: vehicle id -> (min, max) contact force on the deck, N.
        log_path: the run's MCAP log (None for an in-memory run).
        wall_time: s.
    """

    scenario: Scenario
    t: npt.NDArray[np.float64]
    channels: dict[str, npt.NDArray[np.float64]]
    quantities: dict[str, str]
    extremes: dict[str, tuple[float, float]]
    vehicle_ids: list[str]
    duration: float
    liftoff_events: int = 0
    max_on_deck: int = 0
    contact_force_range: dict[str, tuple[float, float]] = field(default_factory=dict)
    log_path: Path | None = None
    wall_time: float = 0.0
    _vehicles: dict[str, dict[str, npt.NDArray[np.float64]]] | None = field(default=None, repr=False)
    _bridge: BridgeModel | None = field(default=None, repr=False)
    _qs: QuasiStaticResult | None = field(default=None, repr=False)

    # ------------------------------------------------------------- channels
    @property
    def names(self) -> list[str]:
        """The sensor channel names."""
        return list(self.channels)

    def __getitem__(self, name: str) -> npt.NDArray[np.float64]:
        return self.channels[self._check(name)]

    def __contains__(self, name: object) -> bool:
        return name in self.channels

    def _check(self, name: str) -> str:
        if name not in self.channels:
            raise KeyError(f"no sensor {name!r} in this result (sensors: {', '.join(self.channels) or 'none'})")
        return name

    def peak(self, name: str) -> float:
        """Largest absolute value of a sensor over every time step (SI units)."""
        lo, hi = self.extremes[self._check(name)]
        return max(abs(lo), abs(hi))

    def minimum(self, name: str) -> float:
        """Smallest value over every time step (the largest downward deflection is the minimum)."""
        return self.extremes[self._check(name)][0]

    def maximum(self, name: str) -> float:
        """Largest value over every time step."""
        return self.extremes[self._check(name)][1]

    # ------------------------------------------------------------- vehicles
    def vehicle(self, vehicle_id: str) -> dict[str, npt.NDArray[np.float64]]:
        """One vehicle's samples while on the deck, named as in the log (:data:`VEHICLE_COLUMNS`): ``t``,
        ``x``, ``y`` (m), ``speed`` (m/s), ``acceleration`` (m/s^2), ``body_displacement`` (m),
        ``body_acceleration`` (m/s^2), ``contact_force`` (N, compression positive). An in-memory run has
        the fields the simulation keeps (not ``acceleration``)."""
        table = self._vehicle_table()
        if vehicle_id not in table:
            raise KeyError(f"no vehicle {vehicle_id!r} on the deck (vehicles: {', '.join(table) or 'none'})")
        return table[vehicle_id]

    def _vehicle_table(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]:
        if self._vehicles is None:
            self._vehicles = _vehicles_from_log(self.log_path) if self.log_path is not None else {}
        return self._vehicles

    # --------------------------------------------------------- quasi-static
    @property
    def bridge(self) -> BridgeModel:
        """The scenario's bridge model (built once)."""
        if self._bridge is None:
            self._bridge = self.scenario.build_bridge()
        return self._bridge

    def quasi_static(self) -> QuasiStaticResult:
        """The quasi-static run of the same traffic (weights, no inertia), at every step; computed once."""
        if self._qs is None:
            self._qs = quasi_static(self.bridge, self._traffic(), self.duration, self.scenario.solver.dt,
                                    self.scenario.sensors_core(), self.scenario.solver.gravity,
                                    output_every=self.scenario.output_every)
        return self._qs

    def _traffic(self) -> Any:
        if self.log_path is not None:
            from cosim.log.replay_source import read_traffic

            traffic_cfg = self.scenario.traffic
            if traffic_cfg is not None and traffic_cfg.sumo:  # the logged SUMO frames (empty ones are not logged)
                traffic, _ = read_traffic(self.log_path, self.bridge.length, traffic_cfg.step, until=self.duration)
                return traffic
        return scripted_traffic(self.scenario)

    def static(self, name: str) -> npt.NDArray[np.float64]:
        """Quasi-static samples of a sensor at :attr:`t` (NaN for velocity and acceleration sensors)."""
        return self.quasi_static().sensors[self._check(name)]

    def static_peak(self, name: str) -> float:
        """Largest absolute quasi-static value over every step (NaN for velocity and acceleration)."""
        return self.quasi_static().peak[self._check(name)]

    def daf(self, name: str) -> float:
        """Dynamic amplification factor: :meth:`peak` over :meth:`static_peak` (NaN without a static value)."""
        from cosim.core.quasistatic import daf as _daf

        return _daf(self.peak(name), self.static_peak(name))

    def frequencies(self, count: int = 5) -> npt.NDArray[np.float64]:
        """The bridge's lowest natural frequencies, Hz."""
        return self.bridge.modes(count).f_hz


#: A vehicle's samples in :class:`Results`: the time and every numeric field of the log's vehicle items.
VEHICLE_COLUMNS: tuple[str, ...] = ("t", *VEHICLE_NUMBERS)


def _vehicles_from_log(path: Path) -> dict[str, dict[str, npt.NDArray[np.float64]]]:
    from cosim.log.reader import iter_messages
    from cosim.log.schemas import TOPIC_VEHICLES

    columns = VEHICLE_COLUMNS
    rows: dict[str, dict[str, list[float]]] = {}
    for _, msg in iter_messages(path, [TOPIC_VEHICLES]):
        for v in msg["vehicles"]:
            table = rows.setdefault(v["id"], {c: [] for c in columns})
            table["t"].append(msg["t"])
            for c in columns[1:]:
                table[c].append(v[c])
    out = {}
    for vid, table in rows.items():
        order = np.argsort(np.asarray(table["t"]), kind="stable")
        out[vid] = {c: np.asarray(vals, dtype=float)[order] for c, vals in table.items()}
    return out


def _from_simulation(sc: Scenario, result: Any, bridge_model: BridgeModel) -> Results:
    vehicles = {}
    for vid in result.vehicle_ids:
        v = result.vehicle(vid)
        vehicles[vid] = {name: v[name] for name in VEHICLE_COLUMNS}  # the in-memory run uses the log's names
    return Results(
        scenario=sc, t=result.t, channels=dict(result.sensors),
        quantities={s.name: s.quantity for s in sc.sensors},
        extremes={n: (result.sensor_min[n], result.sensor_max[n]) for n in result.sensors},
        vehicle_ids=list(result.vehicle_ids), duration=sc.duration, liftoff_events=result.liftoff_events,
        max_on_deck=result.max_on_deck, contact_force_range=dict(result.contact_force_range),
        wall_time=result.wall_time, _vehicles=vehicles, _bridge=bridge_model,
    )


def _from_log(sc: Scenario, outcome: Any, bridge_model: BridgeModel,
              vehicles: dict[str, dict[str, npt.NDArray[np.float64]]] | None = None) -> Results:
    """The results of a logged run, read from its log (the vehicles' samples too if not given: when first asked)."""
    from cosim.log.reader import sensor_series

    result = outcome.result
    t, series = sensor_series(outcome.log_path, [s.name for s in sc.sensors])
    return Results(
        scenario=sc, t=t, channels=series, quantities={s.name: s.quantity for s in sc.sensors},
        extremes={n: (result.sensor_min[n], result.sensor_max[n]) for n in series},
        vehicle_ids=list(result.vehicle_ids), duration=outcome.duration, liftoff_events=result.liftoff_events,
        max_on_deck=result.max_on_deck, contact_force_range=dict(result.contact_force_range),
        log_path=Path(outcome.log_path), wall_time=outcome.wall_time, _vehicles=vehicles, _bridge=bridge_model,
    )


def _has_traffic(sc: Scenario) -> bool:
    return getattr(sc, "traffic", None) is not None or "traffic" in tomllib.loads(sc.text)


def run(base: Scenario | str | os.PathLike[str] | Mapping[str, Any] | None = None, *,
        log: str | os.PathLike[str] | None = None, bridge_model: BridgeModel | None = None,
        **overrides: Any) -> Results:
    """Build a scenario (see :func:`scenario`), run it and return its :class:`Results`.

    Args:
        base: the base scenario (path, bundled name, TOML text, dict or Scenario).
        log: write the run's MCAP log here (overwritten if it exists); the
            channels are then read back from it. Without it, scripted vehicles
            run in memory and SUMO traffic logs into a temporary file that is
            removed afterwards.
        bridge_model: the scenario's bridge, if already built (e.g. the ``cosim_bridge`` fixture).
        overrides: tables merged into the base (``road={"class": "B", "seed": 1}``).

    Raises:
        ConfigError: the scenario is invalid. ModelError: the model cannot be built or the run diverged.
    """
    sc = scenario(base, **overrides)
    model = bridge_model if bridge_model is not None else sc.build_bridge()
    if log is None and not _has_traffic(sc):
        from cosim.run.simulate import simulate_scenario

        return _from_simulation(sc, simulate_scenario(sc, bridge=model), model)
    from cosim.run.logged import run_logged

    if log is not None:
        outcome = run_logged(sc, Path(log), force=True, bridge=model)
        return _from_log(sc, outcome, model)
    folder = Path(tempfile.mkdtemp(prefix="cosim-test-"))
    try:
        outcome = run_logged(sc, folder / "run.mcap", force=True, bridge=model)
        # What the log holds is read before it goes: the vehicles now, the logged traffic by quasi_static().
        res = _from_log(sc, outcome, model, vehicles=_vehicles_from_log(Path(outcome.log_path)))
        res.quasi_static()
        res.log_path = None
        return res
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# --------------------------------------------------------------------------- helpers


def peak(result: Results, sensor: str) -> float:
    """Largest absolute value of ``sensor`` over every time step."""
    return result.peak(sensor)


def daf(result: Results, sensor: str) -> float:
    """Dynamic amplification factor of ``sensor``: dynamic peak / quasi-static peak of the same traffic."""
    return result.daf(sensor)


def spectrum(t: npt.ArrayLike, values: npt.ArrayLike, pad: int = 8
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """One-sided amplitude spectrum of a uniformly sampled signal (mean removed, Hann window, zero-padded).

    Returns:
        (f in Hz, amplitude in the signal's unit); a sine of amplitude a on a frequency bin reads about a.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(values, dtype=float)
    if len(t) < 4 or len(t) != len(x):
        raise ValueError("spectrum: need at least 4 samples, with as many times as values")
    dt = float(np.median(np.diff(t)))
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-9):
        raise ValueError("spectrum: the samples must be uniformly spaced in time")
    window = np.hanning(len(x))
    n = int(2 ** math.ceil(math.log2(len(x) * max(pad, 1))))
    amplitude = 2.0 * np.abs(np.fft.rfft((x - x.mean()) * window, n)) / window.sum()
    return np.fft.rfftfreq(n, dt).astype(np.float64), amplitude


def dominant_frequency(t: npt.ArrayLike, values: npt.ArrayLike, band: tuple[float, float] | None = None,
                       pad: int = 8) -> float:
    """Frequency (Hz) of the largest spectral peak of a signal, within ``band`` if given."""
    f, amp = spectrum(t, values, pad)
    mask = np.ones(len(f), dtype=bool) if band is None else (f >= band[0]) & (f <= band[1])
    mask &= f > 0
    if not mask.any():
        raise ValueError(f"dominant_frequency: no spectral line in the band {band} Hz")
    idx = np.flatnonzero(mask)
    k = int(idx[np.argmax(amp[idx])])
    if 0 < k < len(f) - 1:  # parabolic interpolation of the peak
        a, b, c = amp[k - 1], amp[k], amp[k + 1]
        denom = a - 2 * b + c
        shift = 0.5 * (a - c) / denom if denom != 0 else 0.0
        return float(f[k] + shift * (f[1] - f[0]))
    return float(f[k])


def _unit(result: Results, name: str) -> tuple[str, float]:
    from cosim.run.units import display_unit

    return display_unit(result.quantities.get(name, ""))


def assert_peak_below(result: Results, sensor: str, bound: float) -> None:
    """Fail unless the peak |value| of ``sensor`` over every step is below ``bound`` (SI units)."""
    value = result.peak(sensor)
    if not value < bound:
        unit, factor = _unit(result, sensor)
        raise AssertionError(f"{result.scenario.title}: peak |{sensor}| = {value * factor:.6g} {unit}, "
                             f"expected below {bound * factor:.6g} {unit}")


def assert_daf_below(result: Results, sensor: str, bound: float) -> None:
    """Fail unless the dynamic amplification factor of ``sensor`` is below ``bound``."""
    value = result.daf(sensor)
    if not value < bound:
        raise AssertionError(
            f"{result.scenario.title}: DAF of {sensor} = {value:.4f} (dynamic peak {result.peak(sensor):.6g}, "
            f"quasi-static peak {result.static_peak(sensor):.6g}), expected below {bound:g}")


def assert_deflection_below(result: Results, sensor: str, ratio: float = 800.0) -> None:
    """Fail unless the peak deflection of displacement ``sensor`` is below span / ``ratio`` (e.g. L/800).

    The span is the one the sensor stands on.
    """
    if result.quantities.get(sensor) != "displacement":
        raise ValueError(f"{sensor}: a deflection limit needs a displacement sensor "
                         f"(got {result.quantities.get(sensor)!r})")
    x = next(s.x for s in result.scenario.sensors if s.name == sensor)
    ends = np.cumsum(result.scenario.bridge.spans)
    span = float(result.scenario.bridge.spans[min(int(np.searchsorted(ends, x - 1e-9)), len(ends) - 1)])
    limit = span / ratio
    value = result.peak(sensor)
    if not value < limit:
        raise AssertionError(f"{result.scenario.title}: peak deflection at {sensor} = {value * 1e3:.4g} mm, "
                             f"expected below L/{ratio:g} = {span:g} m / {ratio:g} = {limit * 1e3:.4g} mm")


def assert_matches_log(result: Results, log_path: str | os.PathLike[str], rtol: float = DEFAULT_RTOL,
                       atol: float = DEFAULT_ATOL, sensors: Iterable[str] | None = None) -> None:
    """Fail unless the sensor channels match those of a stored log within a tolerance.

    Per channel: ``max |result - stored| <= atol + rtol * max |stored|`` over the
    stored samples (the stored log is interpolated at the result's times when
    its times differ). Every channel compared must be in both.
    """
    from cosim.log.reader import open_log, sensor_series

    stored_names = open_log(log_path).sensor_names
    names = list(sensors) if sensors is not None else list(result.channels)
    missing = [n for n in names if n not in stored_names or n not in result.channels]
    if missing:
        raise AssertionError(f"{log_path}: channel(s) {', '.join(missing)} missing (result: "
                             f"{', '.join(result.channels)}; log: {', '.join(stored_names)})")
    t_log, stored = sensor_series(log_path, names)
    same_times = len(t_log) == len(result.t) and np.allclose(t_log, result.t, rtol=0, atol=1e-9)
    if not same_times and (result.t[-1] > t_log[-1] + 1e-9 or result.t[0] < t_log[0] - 1e-9):
        raise AssertionError(f"{log_path}: the log covers t = {t_log[0]:g} ... {t_log[-1]:g} s, the result "
                             f"{result.t[0]:g} ... {result.t[-1]:g} s")
    problems = []
    for name in names:
        ref = stored[name] if same_times else np.interp(result.t, t_log, stored[name])
        diff = np.abs(result.channels[name] - ref)
        allowed = atol + rtol * float(np.max(np.abs(stored[name]))) if len(ref) else atol
        worst = int(np.argmax(diff)) if len(diff) else 0
        if len(diff) and not diff[worst] <= allowed:
            problems.append(f"{name}: max |difference| = {diff[worst]:.6g} at t = {result.t[worst]:g} s "
                            f"(result {result.channels[name][worst]:.6g}, log {ref[worst]:.6g}), "
                            f"allowed {allowed:.6g} (atol {atol:g} + rtol {rtol:g} x peak)")
    if problems:
        raise AssertionError(f"{result.scenario.title} vs {log_path}:\n  " + "\n  ".join(problems))


# --------------------------------------------------------------------------- pytest plugin

UPDATE_OPTION = "--cosim-update-logs"
#: Environment variable that does what --cosim-update-logs does (e.g. ``COSIM_UPDATE_LOGS=1 pytest``).
UPDATE_ENV = "COSIM_UPDATE_LOGS"
SNAPSHOT_FOLDER = "logs"

if pytest is not None:

    def pytest_addoption(parser: Any) -> None:
        """``--cosim-update-logs``: (re)write the stored logs that ``cosim_log_snapshot`` compares with."""
        group = parser.getgroup("cosim", "cosim scenario tests")
        group.addoption(UPDATE_OPTION, action="store_true", default=False,
                        help="write the logs that cosim_log_snapshot compares results with, instead of comparing")

    def pytest_configure(config: Any) -> None:
        config.addinivalue_line("markers", "cosim: a cosim scenario test")

    @pytest.fixture(scope="session")
    def cosim_bridge() -> Any:
        """Factory: ``cosim_bridge(scenario_or_path) -> BridgeModel``, each distinct bridge built once per session."""
        cache: dict[str, BridgeModel] = {}

        def build(base: Any = None, **overrides: Any) -> BridgeModel:
            sc = scenario(base, **overrides)
            key = repr(sc.bridge.model_dump())
            if key not in cache:
                cache[key] = sc.build_bridge()
            return cache[key]

        return build

    @pytest.fixture
    def run_scenario(tmp_path: Path, cosim_bridge: Any) -> Any:
        """Factory: ``run_scenario(scenario_or_path, log=False, **overrides) -> Results``.

        Bridges are cached for the session; with ``log=True`` (or for SUMO
        traffic) the run's log is written into the test's temporary folder and
        stays there (``result.log_path``).
        """
        counter = iter(range(1, 1_000_000))

        def runner(base: Any = None, *, log: bool = False, **overrides: Any) -> Results:
            sc = scenario(base, **overrides)
            model = cosim_bridge(sc)
            path = None
            if log or _has_traffic(sc):
                path = tmp_path / f"{sc.title}-{next(counter)}.mcap"
            return run(sc, log=path, bridge_model=model)

        return runner

    @pytest.fixture
    def cosim_log_snapshot(request: Any) -> Any:
        """Factory: ``cosim_log_snapshot(result, name, rtol=1e-6, atol=0.0)`` compares with ``logs/<name>.mcap``
        next to the test file; ``pytest --cosim-update-logs`` (or ``COSIM_UPDATE_LOGS=1``) writes that log
        from the result instead."""
        folder = Path(str(request.node.fspath)).parent / SNAPSHOT_FOLDER
        try:
            update = bool(request.config.getoption(UPDATE_OPTION))
        except ValueError:  # the plugin's option was not registered (fixtures imported by hand)
            update = False
        update = update or os.environ.get(UPDATE_ENV, "") not in ("", "0")

        def check(result: Results, name: str, rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL) -> Path:
            path = folder / f"{name}.mcap"
            if update:
                folder.mkdir(parents=True, exist_ok=True)
                if result.log_path is not None and Path(result.log_path).is_file():
                    shutil.copyfile(result.log_path, path)
                else:
                    from cosim.run.logged import run_logged

                    run_logged(result.scenario, path, force=True, bridge=result.bridge)
                return path
            if not path.is_file():
                pytest.fail(f"no stored log {path}; run pytest {UPDATE_OPTION} to write it", pytrace=False)
            assert_matches_log(result, path, rtol=rtol, atol=atol)
            return path

        return check
