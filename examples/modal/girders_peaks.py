"""The load distribution between the five girders of examples/modal/girders.toml under SUMO traffic in two
directions, against the one-beam model of the same bridge (girders-beam.toml): runs both, writes the plot
docs/img/girders-peaks.png and prints the table of docs/modal-decks.md ("Worked example: a slab on five
girders").

    python examples/modal/girders_peaks.py [--end SECONDS] [--logs DIR] [--plot FILE]

Each girder's peak is its largest downward deflection at mid-span over the whole run (every time step), at the
slab's mid-plane over the girder; its share is that peak over the sum of the five peaks (the peaks need not
happen at the same time). Beside them: the static distribution of a point load at mid-span on each lane's
centre through the same modes (cosim's contact rows and the static flexibility sum_j phi_j phi_j / omega_j^2 of
the file's 50 modes, which tests/integration/test_modal_girders.py checks against OpenSees' own static analysis
of the model), the lever rule for that point load, and AASHTO LRFD's moment distribution factor of an interior
girder with one lane loaded (Table 4.6.2.2.2b-1, concrete deck on concrete beams, without the multiple presence
factor 1.2) as a rough yardstick.
"""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from cosim import testing
from cosim.bridges import from_beam, read_modes
from cosim.core.modal_deck import ModalDeck
from cosim.run.api import run_scenario

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
GIRDERS_Y = (-5.0, -2.5, 0.0, 2.5, 5.0)  # m (examples/modal/girders.py)
LANES_Y = (-1.875, 1.875)  # m: eastbound (+x), westbound (-x)
EDGE = 6.5  # m
SPAN = 40.0  # m
NAMES = ("g1", "g2", "g3", "g4", "g5")


def peaks(path: Path, end: float | None, log: Path) -> np.ndarray:
    """Each girder's largest downward mid-span deflection over the run of the scenario at ``path``, m."""
    scenario = testing.scenario(path, traffic={"end": end}) if end is not None else testing.scenario(path)
    run = run_scenario(scenario, out=log, force=True)
    low = run.outcome.result.sensor_min  # type: ignore[union-attr]
    return np.array([-low[name] for name in NAMES])


def static_shares(deck: ModalDeck) -> dict[float, np.ndarray]:
    """The girders' shares of the mid-span deflection under a point load at mid-span on each lane's centre,
    through the deck's static flexibility (its modes' sum)."""
    at = np.stack([deck.rows(np.array([SPAN / 2]), np.array([y]))[0, 0] for y in GIRDERS_Y])  # (5, m)
    out = {}
    for lane in LANES_Y:
        load = deck.rows(np.array([SPAN / 2]), np.array([lane]))[0, 0]
        w = at @ (load / deck.omega**2)
        out[lane] = w / w.sum()
    return out


def lever_rule(y: float) -> np.ndarray:
    """A point load at ``y`` shared by its two neighbouring girders as a simply supported slab strip would."""
    shares = np.zeros(len(GIRDERS_Y))
    k = int(np.clip(np.searchsorted(GIRDERS_Y, y) - 1, 0, len(GIRDERS_Y) - 2))
    a, b = GIRDERS_Y[k], GIRDERS_Y[k + 1]
    shares[k], shares[k + 1] = (b - y) / (b - a), (y - a) / (b - a)
    return shares


def aashto_interior_one_lane(spacing: float = 2.5, span: float = SPAN, slab: float = 0.25, girder_i: float = 0.2378,
                             girder_a: float = 0.5365, eg: float = 1.008) -> float:
    """AASHTO LRFD Table 4.6.2.2.2b-1 (type k): 0.06 + (S/14)^0.4 (S/L)^0.3 (Kg / (12 L ts^3))^0.1 in US units
    (ft, in), Kg = n (I + A eg^2) with n = 1 (one concrete); divided by the multiple presence factor 1.2 that
    the table includes: the share of one lane's load an interior girder carries."""
    ft, inch = 0.3048, 0.0254
    s, length, ts = spacing / ft, span / ft, slab / inch
    kg = (girder_i + girder_a * eg**2) / inch**4
    return (0.06 + (s / 14) ** 0.4 * (s / length) ** 0.3 * (kg / (12 * length * ts**3)) ** 0.1) / 1.2


def _lanes(ax: Any) -> None:
    ax.axvspan(-EDGE, EDGE, color="0.93", zorder=0)
    for lane, label in ((LANES_Y[0], "→ eastbound\nlane (+x)"), (LANES_Y[1], "← westbound\nlane (−x)")):
        ax.axvline(lane, color="tab:orange", ls="--", lw=1.0)
        ax.text(lane, 0.02, label, transform=ax.get_xaxis_transform(), ha="center", va="bottom", fontsize=8, zorder=3,
                color="tab:orange", bbox={"fc": "0.93", "ec": "none", "pad": 1.0})
    ax.set_xlim(EDGE + 0.3, -EDGE - 0.3)  # the view along +x: the right-hand side (y < 0) on the right
    ax.set_xticks(GIRDERS_Y, [f"g{k + 1}\n{y:+.1f}" for k, y in enumerate(GIRDERS_Y)])
    ax.set_xlabel("girder, lateral position y (m), looking along +x")


def plot(modal: np.ndarray, beam: np.ndarray, static: np.ndarray, beam_static: np.ndarray, aashto: float,
         minutes: float, path: Path) -> None:
    """Left: each girder's peak under the traffic, both models; right: the shares of a point load on the
    eastbound lane's centre at mid-span (static), both models, the lever rule and AASHTO's interior factor."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.4), gridspec_kw={"width_ratios": [1.15, 1]})
    _lanes(left)
    left.plot(GIRDERS_Y, 1e3 * modal, "o-", color="tab:blue", lw=2, ms=8, label="slab on five girders (50 modes)")
    left.plot(GIRDERS_Y, 1e3 * beam, "s--", color="0.35", ms=6, label="one beam of the same section (50 modes)")
    for y, w in zip(GIRDERS_Y, modal):
        left.annotate(f"{100 * w / modal.sum():.1f} %", (y, 1e3 * w), textcoords="offset points", xytext=(0, 9),
                      ha="center", fontsize=8, color="tab:blue")
    left.set_ylim(0, 1.45e3 * max(modal.max(), beam.max()))
    left.set_ylabel("peak mid-span deflection, mm")
    left.set_title(f"{minutes:g} min of two-way SUMO traffic (medium demand):\neach girder's peak and its share "
                   "of the five peaks' sum", fontsize=9)
    left.legend(loc="upper center", fontsize=8, framealpha=0.9)
    _lanes(right)
    right.plot(GIRDERS_Y, 100 * static, "o-", color="tab:blue", lw=2, ms=8, label="slab on five girders")
    right.plot(GIRDERS_Y, 100 * beam_static, "s--", color="0.35", ms=6, label="one beam (w + y θx)")
    right.plot(GIRDERS_Y, 100 * lever_rule(LANES_Y[0]), "^:", color="tab:red", ms=6, label="lever rule")
    right.axhline(100 * aashto, color="tab:green", lw=1.0,
                  label="AASHTO LRFD interior girder, one lane (÷ 1.2)")
    right.set_ylim(0, 100)
    right.set_ylabel("share of the girders' deflection sum, %")
    right.set_title("static: a point load at mid-span on the eastbound lane's centre", fontsize=9)
    right.legend(loc="upper left", fontsize=8, framealpha=0.9)
    fig.suptitle("40 m slab on five concrete girders (OpenSeesPy model, ShellMITC4 slab), its modes driven by cosim",
                 fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--end", type=float, default=None, help="SUMO's end time, s (default: the scenarios' 600)")
    parser.add_argument("--logs", type=Path, default=ROOT / "runs")
    parser.add_argument("--plot", type=Path, default=ROOT / "docs" / "img" / "girders-peaks.png")
    args = parser.parse_args()
    modal = peaks(HERE / "girders.toml", args.end, args.logs / "girders.mcap")
    beam = peaks(HERE / "girders-beam.toml", args.end, args.logs / "girders-beam.mcap")
    minutes = (args.end if args.end is not None else 600.0) / 60
    static = static_shares(read_modes(HERE / "girders-modes.npz"))
    # the beam's own 50 modes on five lines across the deck (w + y theta_x is linear in y: the spline is exact)
    beam_static = static_shares(from_beam(testing.scenario(HERE / "girders-beam.toml"), n_modes=50, lateral=5))
    plot(modal, beam, static[LANES_Y[0]], beam_static[LANES_Y[0]], aashto_interior_one_lane(), minutes, args.plot)
    print(f"{minutes:g} min of traffic; peak mid-span deflection (mm) and share of the sum of the five peaks")
    print("| girder | y (m) | slab on girders | share | one beam | share | static, load on the eastbound lane | "
          "westbound | one beam, static, eastbound | lever rule, eastbound |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    east = lever_rule(LANES_Y[0])
    for k, y in enumerate(GIRDERS_Y):
        print(f"| {NAMES[k]} | {y:+.1f} | {1e3 * modal[k]:.3f} | {100 * modal[k] / modal.sum():.1f} % | "
              f"{1e3 * beam[k]:.3f} | {100 * beam[k] / beam.sum():.1f} % | {100 * static[LANES_Y[0]][k]:.1f} % | "
              f"{100 * static[LANES_Y[1]][k]:.1f} % | {100 * beam_static[LANES_Y[0]][k]:.1f} % | "
              f"{100 * east[k]:.0f} % |")
    print(f"AASHTO LRFD interior girder, one lane, without the multiple presence factor: "
          f"{100 * aashto_interior_one_lane():.1f} % of the lane's load")
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
