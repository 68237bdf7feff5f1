"""The default run's scenario for a benchmark configuration, its kernels compiled (bench_day, profile_day).

Imported by the worker processes those scripts start (one per configuration: libsumo is a per-process
singleton), with benchmarks/ put on their path.
"""
from __future__ import annotations

from typing import Any

import tomllib


def default_run(mode: str, hours: float) -> tuple[Any, Any]:
    """The scenario and bridge of `cosim run` with no arguments for ``hours`` simulated hours, as ``mode`` says:
    ``direct`` or ``modal`` (30 modes) first, ``@1ms`` for dt = 1 ms, ``/no-scene`` without the 3D scene.

    Every compiled function of a SUMO run is compiled (or loaded from numba's cache) before it returns: the
    bridge alone for 0.05 s, then 20 s of the same traffic with SUMO where the timed run has it (in a child
    without a log, or with a log but no scene).
    """
    from cosim.core.sensors import Sensor
    from cosim.core.simulation import simulate
    from cosim.core.traffic import ScriptedTraffic
    from cosim.run.scenario import load_scenario, parse_scenario
    from cosim.run.simulate import build_traffic
    from cosim.run.toml_writer import toml_dumps

    base = load_scenario("paper-bridge-traffic")
    data = tomllib.loads(base.text)
    data["traffic"]["end"] = 3600.0 * hours
    basis = mode.split("+")[0]
    if basis in ("direct", "modal"):
        data["solver"]["basis"] = basis
        if basis == "modal":
            data["solver"]["modes"] = 30
    if mode.endswith("@1ms"):
        data["solver"]["dt"] = 0.001
    if mode.endswith("/no-scene"):  # as a run longer than SCENE_MAX_DURATION (or one that says so) has it
        data.setdefault("output", {})["scene"] = False
    scenario = parse_scenario(toml_dumps(data), f"bench-{mode}", base_dir=base.base_dir)
    bridge = scenario.build_bridge()
    simulate(bridge, ScriptedTraffic((), bridge.length), 0.05, scenario.solver_settings(), [Sensor("s", 1.0)])
    data["traffic"]["end"] = 20.0
    warm = parse_scenario(toml_dumps(data), "warm-up", base_dir=base.base_dir)
    with build_traffic(warm, process=mode in ("direct", "modal") or mode.endswith("/no-scene")) as traffic:
        simulate(bridge, traffic, 20.0, warm.solver_settings(), warm.sensors_core(), road=warm.build_road(),
                 output_every=warm.output_every, collect=False)
    return scenario, bridge


def plain_libsumo(config: str, step: float, end: float, seed: int | None) -> None:
    """Issue 27's yardstick: libsumo started on a SUMO config as cosim starts it (step, ballistic update, seed)
    and stepped to ``end`` (s), nothing read. Imports libsumo only, so that as a whole process it is Python's
    start, SUMO's and its steps."""
    import libsumo

    libsumo.start(["sumo", "-c", config, "--step-length", repr(step), "--begin", "0", "--end", repr(end),
                   "--step-method.ballistic", "true", "--no-step-log", "true", "--no-warnings", "true",
                   *(["--seed", str(seed)] if seed is not None else [])])
    for _ in range(int(round(end / step))):
        libsumo.simulationStep()
    libsumo.close()
