"""Make the figures of the docs that no cosim command draws by itself (run on demand).

    python docs/make_figures.py

- docs/img/replay.png (docs/cli.md): one logged run replayed onto another bridge
  (`cosim run` then `cosim replay --scenario`), the two sensor histories overlaid;
- docs/img/drive-by.png (docs/studies.md): the drive-by example of the scenario tests, the
  probe car's body-acceleration spectrum against the bridge's first frequency.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from cosim import testing as ct  # noqa: E402
from cosim.log import sensor_series  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
IMG = HERE / "img"


def replay_figure() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        run = [sys.executable, "-m", "cosim"]
        subprocess.run([*run, "run", "paper-double-tee", "--out", f"{tmp}/a.mcap", "--quiet"], check=True)
        subprocess.run([*run, "replay", f"{tmp}/a.mcap", "--scenario", "paper-double-tee-asymmetric",
                        "--out", f"{tmp}/b.mcap", "--quiet"], check=True, stdout=subprocess.DEVNULL)
        t_a, a = sensor_series(f"{tmp}/a.mcap", ["node2"])
        t_b, b = sensor_series(f"{tmp}/b.mcap", ["node2"])
    fig, ax = plt.subplots(figsize=(8, 3.2), constrained_layout=True)
    ax.plot(t_a, 1e3 * a["node2"], label="logged run: symmetric double-tee")
    ax.plot(t_b, 1e3 * b["node2"], "--", label="replayed onto the asymmetric section (right web 0.25 m)")
    ax.set(xlabel="t [s]", ylabel="node2 (left edge) w [mm]",
           title="cosim replay: the same traffic on another bridge")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(IMG / "replay.png", dpi=110)


def drive_by_figure() -> None:
    res = ct.run(ROOT / "examples" / "scenarios" / "drive-by.toml")
    probe = res.vehicle("probe")
    f, amp = ct.spectrum(probe["t"], probe["body_acceleration"])
    f1 = res.frequencies(1)[0]
    fig, ax = plt.subplots(figsize=(8, 3.2), constrained_layout=True)
    ax.plot(f, 1e3 * amp)
    ax.axvline(f1, color="C3", ls="--", label=f"bridge's first frequency {f1:.2f} Hz")
    ax.axvline(1.0, color="0.5", ls=":", label="the car's own body frequency 1.0 Hz")
    ax.set(xlim=(0, 6), xlabel="frequency [Hz]", ylabel="amplitude [mm/s$^2$]",
           title="drive-by: spectrum of a slow quarter-car's body acceleration")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(IMG / "drive-by.png", dpi=110)


if __name__ == "__main__":
    IMG.mkdir(exist_ok=True)
    replay_figure()
    drive_by_figure()
    print(f"written: {IMG / 'replay.png'}, {IMG / 'drive-by.png'}")
