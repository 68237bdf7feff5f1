"""SUMO stepped in a child process (cosim.run.sumo_process): real SUMO, real forks, real signals."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from _cli import broken_sumo_configs, bundled_scenario

from cosim.core.simulation import simulate
from cosim.errors import ConfigError, SumoError
from cosim.log.process import fork_possible
from cosim.run.simulate import build_traffic
from cosim.run.sumo_process import SumoProcess
from cosim.sumo.adapter import MESSAGES_FILE, VEHICLE_TYPES_ATTACHMENT, BridgeAxis, SumoTraffic, bundled_networks

pytestmark = pytest.mark.skipif(not fork_possible(), reason="SUMO's process needs Linux and fork")
AXIS = BridgeAxis((0.0, 0.0), (40.0, 0.0))


class _Sink:
    """A frame sink that keeps what it is given: each frame's time and ids, and the documents' names."""

    def __init__(self) -> None:
        self.seen: list[tuple[float, tuple[str, ...]]] = []
        self.documents: list[str] = []

    def __call__(self, frame, models) -> None:  # noqa: ANN001
        self.seen.append((frame.t, frame.ids))

    def attach(self, name: str, data: bytes | str, media_type: str) -> None:
        self.documents.append(name)


def test_sumo_in_its_own_process_gives_the_same_run_to_the_bit() -> None:
    scenario = bundled_scenario("paper-bridge-traffic", end=30.0)
    bridge = scenario.build_bridge()
    runs, sinks = [], []
    for process in (True, False):
        sink = _Sink()
        with build_traffic(scenario, frame_sink=sink, process=process) as traffic:
            assert isinstance(traffic, SumoProcess) == process
            runs.append(simulate(bridge, traffic, 30.0, scenario.solver_settings(), scenario.sensors_core(),
                                 road=scenario.build_road(), output_every=scenario.output_every))
        sinks.append(sink.seen)
        # One attach implementation for both: the vehicle types at the start, SUMO's messages at the end.
        assert sink.documents == [VEHICLE_TYPES_ATTACHMENT, MESSAGES_FILE]
    child, here = runs
    assert len(here.vehicle_ids) >= 5 and child.vehicle_ids == here.vehicle_ids
    for name in here.sensors:
        np.testing.assert_array_equal(child.sensors[name], here.sensors[name])
    for key, column in here.vehicle_table.items():
        np.testing.assert_array_equal(child.vehicle_table[key], column)
    assert sinks[0] == sinks[1]  # the same frames reached the frame sink, in the same order


def test_errors_of_sumo_in_its_process_are_those_of_sumo_here(tmp_path: Path) -> None:
    broken, unknown = broken_sumo_configs(tmp_path)
    for config, kind in ((broken, ConfigError), (unknown, SumoError)):
        with pytest.raises(kind) as here:
            SumoTraffic(config, AXIS).start()
        with pytest.raises(kind) as child:
            SumoProcess(SumoTraffic(config, AXIS)).start()
        assert str(child.value) == str(here.value)
    light = bundled_networks() / "light.sumocfg"
    with SumoProcess(SumoTraffic(light, AXIS, end=2.0, half_width=6.0)) as traffic:
        traffic.block(np.arange(1, 41) * 0.05)  # SUMO's whole run
        with pytest.raises(SumoError, match="SUMO's run ends at 2.0 s"):
            traffic.block(np.array([2.05]))


_KILLED_RUN = r"""
import sys, time
import numpy as np
from cosim.run.sumo_process import SumoProcess
from cosim.sumo.adapter import MESSAGES_FILE, VEHICLE_TYPES_ATTACHMENT, BridgeAxis, SumoTraffic, bundled_networks
traffic = SumoProcess(SumoTraffic(bundled_networks() / "medium.sumocfg", BridgeAxis((0.0, 0.0), (40.0, 0.0)),
                                  end=3600.0, half_width=6.0)).start()
traffic.block(np.arange(1, 201) * 0.05)
print(traffic._process.pid, flush=True)
time.sleep(60)
"""


def test_sumo_s_process_ends_and_cleans_up_when_the_run_is_killed(tmp_path: Path) -> None:
    env = {**os.environ, "TMPDIR": str(tmp_path)}  # SUMO's scratch folder is made here
    run = subprocess.Popen([sys.executable, "-c", _KILLED_RUN], stdout=subprocess.PIPE, text=True, env=env)
    try:
        child = int(run.stdout.readline())
        assert list(tmp_path.glob("cosim-sumo-*"))  # SUMO is running, ahead of the run
        run.send_signal(signal.SIGKILL)
        run.wait(10)
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline and Path(f"/proc/{child}").exists() and \
                Path(f"/proc/{child}/stat").read_text().split()[2] != "Z":
            time.sleep(0.1)
        assert not Path(f"/proc/{child}").exists() or Path(f"/proc/{child}/stat").read_text().split()[2] == "Z"
        assert not list(tmp_path.glob("cosim-sumo-*"))  # it closed SUMO and removed its scratch folder
    finally:
        run.kill()
        run.wait()
