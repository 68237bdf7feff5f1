"""Logs written by earlier versions stay readable (issue 27, item 2): the reference logs of tests/regression are
JSON-encoded (written before the logs became protobuf); every one reads, verifies, exports and plots as before,
and a replay re-drives the bridge from one to the numbers the previous version's replay gives.

"As before" is pinned by the SHA-256 of the CSV files the previous version (main at 1dbccfe, JSON logs) exported
from these logs: this version's exports are the same bytes. A replay of paper-double-tee's old log by main and by
this version gave the same sensors, vehicles, events and loads, bit for bit (checked by hand when this test was
written; the scene differs only in encoding defaults, the status in wall time); here the replay is checked against
the old log itself, to the regression tests' 1e-9 of the peak (its arithmetic changed since that log, as the
regression tests say).
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from _cli import cosim_cli
from mcap.reader import make_reader

from cosim.log import TOPIC_VEHICLES, open_log, read_log, sensor_series

OLD_LOGS = Path(__file__).resolve().parents[1] / "regression" / "logs"

#: SHA-256 (first 16 hex digits) of ``cosim export LOG --csv`` and ``--topic /cosim/vehicles`` by main at 1dbccfe.
EXPORTS = {
    "congested-deck": ("558a22f225a0b137", "1737ece268a73a4c"),
    "drive-by": ("144d009b1d49606e", "de3a311008296508"),
    "paper-bridge-traffic-fixed-weights": ("602f9fc70691d639", "f3fb5c558b64e711"),
    "paper-bridge-traffic": ("f634cdee603e21d4", "69ed607503f47980"),
    "paper-double-tee-asymmetric": ("6f54918a460c00d4", "1e80219976f50f22"),
    "paper-double-tee": ("f353c7658faa2c6f", "e4a382e714cca6a0"),
    "traffic-40m": ("636bcb28e593aed2", "9d660aa236e602b8"),
    "truck-40t-class-b": ("b03b9aaca946af22", "86b81fcc45ae48d1"),
}


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def test_every_reference_log_is_json_and_listed_here() -> None:
    assert sorted(p.stem for p in OLD_LOGS.glob("*.mcap")) == sorted(EXPORTS)
    for name in EXPORTS:
        with open(OLD_LOGS / f"{name}.mcap", "rb") as fh:
            summary = make_reader(fh).get_summary()
        assert summary is not None
        assert {c.message_encoding for c in summary.channels.values()} == {"json"}, name


@pytest.mark.parametrize("name", sorted(EXPORTS))
def test_an_old_log_verifies_reads_and_exports_as_before(name: str, tmp_path: Path) -> None:
    log = OLD_LOGS / f"{name}.mcap"
    info = cosim_cli("info", "--verify", str(log), cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    assert "finished file" in info.stdout and "checksums verified" in info.stdout
    whole = read_log(log)
    assert not whole.truncated and whole.final_status["state"] == "finished"
    assert {topic: len(m) for topic, m in whole.messages.items()} == open_log(log).counts
    sensors, vehicles = EXPORTS[name]
    assert cosim_cli("export", str(log), "--csv", "s.csv", cwd=tmp_path).returncode == 0
    assert cosim_cli("export", str(log), "--topic", TOPIC_VEHICLES, "--csv", "v.csv", cwd=tmp_path).returncode == 0
    assert (_sha(tmp_path / "s.csv"), _sha(tmp_path / "v.csv")) == (sensors, vehicles)


def test_an_old_log_plots_and_replays(tmp_path: Path) -> None:
    log = OLD_LOGS / "paper-double-tee.mcap"
    plot = cosim_cli("plot", str(log), "-o", "p.png", cwd=tmp_path)
    assert plot.returncode == 0, plot.stderr
    assert (tmp_path / "p.png").read_bytes().startswith(b"\x89PNG")
    replay = cosim_cli("replay", str(log), "--out", "r.mcap", "--quiet", cwd=tmp_path)
    # The old log's own numbers to round-off (1e-13 of them), as the previous version's replay finds: exit 1, "DIFFER".
    assert replay.returncode == 1 and "the sensor channels DIFFER" in replay.stdout, replay.stderr
    new = tmp_path / "r.mcap"
    with open(new, "rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None and {c.message_encoding for c in summary.channels.values()} == {"protobuf"}
    t_old, old = sensor_series(log)
    t_new, replayed = sensor_series(new)
    np.testing.assert_array_equal(t_new, t_old)
    for name, values in old.items():
        assert np.max(np.abs(replayed[name] - values)) <= 1e-9 * np.max(np.abs(values)), name
