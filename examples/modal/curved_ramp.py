"""A curved ramp through ``frame = "network"``: a 55 m deck on an arc of radius 120 m under three minutes of
two-way SUMO traffic (docs/modal-decks.md, "Worked example: a curved ramp").

    python examples/modal/curved_ramp.py [--end SECONDS] [--out DIR] [--plot FILE]

Writes into ``--out`` (default: a folder ``curved-ramp`` beside this file, not committed):

- the network ``ramp.net.xml``, built by SUMO's netconvert: a two-way road, one 3.5 m lane per direction,
  turning left along a 55 m arc of radius R = 120 m (the edges ``deck`` and ``-deck``, their shape sampled
  every 0.5 m) between 100 m straight tangents;
- the modes file ``ramp-modes.npz``: the first 12 modes of a straight 55 m concrete girder (cosim's beam,
  ``from_beam``, every node of 110 elements on 17 lines across an 8 m deck) mapped onto the arc: the deck
  point (s, n) goes to the centre line's point at arc length s moved n along its left normal, in network
  coordinates, with the mapped grid's triangles as the deck's surface (values only: a network-frame file
  has no slopes);
- the demand ``ramp.rou.xml``: cars and lorries both ways (cosim's library vehicles of each vClass);
- the scenario ``ramp.toml``: ``frame = "network"``, ``[traffic] edges = ["deck", "-deck"]``, displacement
  sensors at mid-span on the inner edge, the centre line and the outer edge (in the bridge frame the
  placement defines: x along the lanes' chord from the deck's first point);

runs it, and plots docs/img/curved-ramp.png: the deck's plan view with the lanes and sensors, and the three
sensors' displacement over time. tests/integration/test_modal_curved.py verifies the same kind of deck: a
quarter-car on each lane gives the same response as on the straightened deck within 5e-6 of the peak.
"""
from __future__ import annotations

import argparse
import subprocess
from pathlib import Path

import numpy as np

from cosim import testing
from cosim.bridges import from_beam, write_modes
from cosim.run.api import run_scenario
from cosim.sumo.network import locate_bridge

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
R = 120.0  # m: the centre line's radius (the road turns left along +s)
S = 55.0  # m: the deck's length along its centre line
APPROACH = 100.0  # m
HALF_WIDTH = 4.0  # m: the deck each side of the centre line
SENSORS = {"inner": 3.9, "centre": 0.0, "outer": -3.9}  # n at mid-span, m (+: left of +s, the inside)


def centre_line(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The centre line at arc length s (network m; from (0, 0) heading +x, turning left) and its unit tangent."""
    s = np.asarray(s, dtype=float)
    return (np.column_stack([R * np.sin(s / R), R * (1.0 - np.cos(s / R))]),
            np.column_stack([np.cos(s / R), np.sin(s / R)]))


def on_arc(s: np.ndarray, n: np.ndarray) -> np.ndarray:
    point, tangent = centre_line(s)
    return point + np.asarray(n, dtype=float)[:, None] * np.column_stack([-tangent[:, 1], tangent[:, 0]])


def write_network(folder: Path) -> None:
    import sumo

    end, tangent = (a[0] for a in centre_line(np.array([S])))
    far = end + APPROACH * tangent
    shape = centre_line(np.linspace(0.0, S, 111))[0]
    there = " ".join(f"{x:.6f},{y:.6f}" for x, y in shape)
    back = " ".join(f"{x:.6f},{y:.6f}" for x, y in shape[::-1])
    (folder / "ramp.nod.xml").write_text(
        f'<nodes>\n    <node id="W" x="{-APPROACH}" y="0.0"/>\n    <node id="A" x="0.0" y="0.0" type="priority"/>\n'
        f'    <node id="B" x="{end[0]:.6f}" y="{end[1]:.6f}" type="priority"/>\n'
        f'    <node id="E" x="{far[0]:.6f}" y="{far[1]:.6f}"/>\n</nodes>\n')
    road = 'numLanes="1" speed="22.22" width="3.5"'
    (folder / "ramp.edg.xml").write_text(
        "<edges>\n"
        f'    <edge id="in" from="W" to="A" {road}/>\n    <edge id="deck" from="A" to="B" {road} shape="{there}"/>\n'
        f'    <edge id="out" from="B" to="E" {road}/>\n    <edge id="-out" from="E" to="B" {road}/>\n'
        f'    <edge id="-deck" from="B" to="A" {road} shape="{back}"/>\n    <edge id="-in" from="A" to="W" {road}/>\n'
        "</edges>\n")
    subprocess.run([str(Path(sumo.SUMO_HOME) / "bin" / "netconvert"), "--node-files", "ramp.nod.xml",
                    "--edge-files", "ramp.edg.xml", "-o", "ramp.net.xml", "--offset.disable-normalization", "true",
                    "--no-turnarounds", "true", "--no-warnings", "true", "--precision", "6"],
                   cwd=folder, check=True, capture_output=True, timeout=120)


ROUTES = """<routes>
    <vType id="car" vClass="passenger" maxSpeed="22" sigma="0.5"/>
    <vType id="lorry" vClass="truck" maxSpeed="22" sigma="0.5"/>
    <route id="up" edges="in deck out"/>
    <route id="down" edges="-out -deck -in"/>
    <flow id="up_cars" type="car" route="up" begin="0" end="{end}" vehsPerHour="500" departSpeed="max"/>
    <flow id="up_lorries" type="lorry" route="up" begin="0" end="{end}" vehsPerHour="120" departSpeed="max"/>
    <flow id="down_cars" type="car" route="down" begin="0" end="{end}" vehsPerHour="400" departSpeed="max"/>
    <flow id="down_lorries" type="lorry" route="down" begin="0" end="{end}" vehsPerHour="150" departSpeed="max"/>
</routes>
"""
SCENARIO = """\
# A 55 m curved ramp (R = 120 m) given by its modes in SUMO's network coordinates: examples/modal/curved_ramp.py
# writes this file, the network and the modes, and runs it (docs/modal-decks.md, "Worked example: a curved ramp").
name = "curved-ramp"
[bridge]
modes = "ramp-modes.npz"
frame = "network"
[bridge.damping]
ratio = 0.02
{sensors}
[traffic]
sumo_config = "ramp.sumocfg"
edges = ["deck", "-deck"]
end = {end}
seed = 7
[solver]
dt = 0.005
"""


def build(folder: Path, end: float) -> Path:
    """Writes the network, modes, demand and scenario into ``folder``; returns the scenario's path."""
    from scipy.spatial import Delaunay

    folder.mkdir(parents=True, exist_ok=True)
    write_network(folder)
    # A torsionally soft girder (J = 0.1 m^4), so that the deck twists under a lane's load.
    bridge = testing.bridge(S, elements_per_span=110, deck_y=(-HALF_WIDTH, HALF_WIDTH), J=0.1)
    beam = testing.scenario({"bridge": bridge, "solver": {"duration": 1.0}}).build_beam()
    deck = from_beam(beam, n_modes=12, lateral=17)
    write_modes(folder / "straight-modes.npz", deck, force=True)
    arrays = {k: v for k, v in np.load(folder / "straight-modes.npz").items()
              if k not in ("frame", "phi_x", "phi_x_minus", "x", "y")}
    network = on_arc(deck.points[:, 0], deck.points[:, 1])
    np.savez(folder / "ramp-modes.npz", x=network[:, 0], y=network[:, 1], frame="network",
             triangles=Delaunay(deck.points).simplices.astype(np.int64), **arrays)
    (folder / "ramp.rou.xml").write_text(ROUTES.format(end=end))
    (folder / "ramp.sumocfg").write_text('<configuration>\n    <input><net-file value="ramp.net.xml"/>'
                                         '<route-files value="ramp.rou.xml"/></input>\n</configuration>\n')
    start, along = placement(folder, network)
    left = np.array([-along[1], along[0]])
    lines = []
    for name, n in SENSORS.items():
        p = on_arc(np.array([S / 2]), np.array([n]))[0] - start
        lines.append(f'[[sensors]]\nname = "{name}"\nx = {float(p @ along):.6f}\ny = {float(p @ left):.6f}')
    path = folder / "ramp.toml"
    path.write_text(SCENARIO.format(sensors="\n".join(lines), end=end))
    return path


def placement(folder: Path, network: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The bridge frame of the deck (docs/modal-decks.md, frames): its origin in the network and its direction."""
    axis = locate_bridge(folder / "ramp.net.xml", ["deck", "-deck"]).axis
    along, _ = axis.unit()
    return np.asarray(axis.start) + float(np.min((network - axis.start) @ along)) * along, along


def plot(folder: Path, log: Path, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cosim.log.reader import sensor_series

    t, series = sensor_series(log, list(SENSORS))
    fig, (plan, ax) = plt.subplots(1, 2, figsize=(12, 4.2), gridspec_kw={"width_ratios": [1, 1.6]})
    s = np.linspace(0.0, S, 200)
    for n, style in ((HALF_WIDTH, "k-"), (-HALF_WIDTH, "k-"), (0.0, "k:")):
        p = on_arc(s, np.full_like(s, n))
        plan.plot(p[:, 0], p[:, 1], style, lw=1)
    for n, label, colour in ((-1.75, "deck (+s), outer lane", "tab:blue"), (1.75, "-deck (-s), inner lane",
                                                                          "tab:orange")):
        p = on_arc(s, np.full_like(s, n))
        plan.plot(p[:, 0], p[:, 1], "--", color=colour, lw=1, label=label)
    for (name, n), colour in zip(SENSORS.items(), ("tab:red", "tab:green", "tab:purple")):
        p = on_arc(np.array([S / 2]), np.array([n]))[0]
        plan.plot(*p, "o", color=colour, label=f"sensor {name}")
    for s0 in (0.0, S):
        p = on_arc(np.array([s0, s0]), np.array([-HALF_WIDTH, HALF_WIDTH]))
        plan.plot(p[:, 0], p[:, 1], "k-", lw=1)
    plan.set_aspect("equal")
    plan.set_xlabel("network x (m)")
    plan.set_ylabel("network y (m)")
    plan.set_title(f"plan: 55 m deck on R = {R:g} m")
    plan.legend(fontsize=7, loc="upper left")
    for (name, values), colour in zip(series.items(), ("tab:red", "tab:green", "tab:purple")):
        ax.plot(t, 1e3 * values, color=colour, lw=0.7, label=f"{name} (n = {SENSORS[name]:+g} m)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("displacement at mid-span (mm, up)")
    ax.set_title("two-way SUMO traffic, frame = \"network\"")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--end", type=float, default=180.0, help="simulated seconds (default 180)")
    parser.add_argument("--out", type=Path, default=HERE / "curved-ramp")
    parser.add_argument("--plot", type=Path, default=ROOT / "docs" / "img" / "curved-ramp.png")
    args = parser.parse_args()
    path = build(args.out, args.end)
    run = run_scenario(testing.scenario(path), out=args.out / "ramp.mcap", force=True)
    result = run.outcome.result  # type: ignore[union-attr]
    print(f"{len(result.vehicle_ids)} vehicles on the deck; off the deck's surface: {result.offdeck_events}")
    for name in SENSORS:
        low, high = 1e3 * result.sensor_min[name], 1e3 * result.sensor_max[name]
        print(f"{name:>6}: lowest {low:.3f} mm, highest {high:.3f} mm")
    plot(args.out, args.out / "ramp.mcap", args.plot)
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
