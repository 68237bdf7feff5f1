"""Worked example 4 of docs/analysis.md: fixed vType weights against Auxerre's loads, side by side.

    cosim study examples/studies/loads-fixed-vs-auxerre.toml --workers 2 --out studies/loads-fixed-vs-auxerre
    python examples/studies/loads_side_by_side.py studies/loads-fixed-vs-auxerre

Two steps, both run by the second command:

1. **collect** (needs the study's output folder and its logs): copies its ``results.csv`` and
   ``characteristic.csv`` and writes ``heavy-vehicles.csv`` (every bus and lorry that came onto the deck, from
   each run's ``/cosim/vehicle_loads``: its gross weight, axles and heaviest axle; its vType from the run of
   the same seed with fixed weights, whose record names it) and ``moment-crossings.csv`` (how often the
   logged mid-span moment crossed each level upwards, per hour, over all the seeds) into ``--data``
   (default ``examples/studies/results/loads-fixed-vs-auxerre/``, committed);
2. **report** (needs only those four files: ``--report-only`` redoes it from the committed ones): the table
   of docs/analysis.md (``table.md`` in ``--data``) and its figure (``--figure``, default
   ``docs/img/loads-fixed-vs-auxerre.png``).

Heavy vehicles are the buses and the rigid and articulated lorries (the vTypes ``bus``, ``truck_*``,
``artic_*`` of the bundled mix: with fixed weights their vClass, with Auxerre's loads a drawn ``truck-N``);
cars and the 3 t vans are left out of the gross-weight statistics.

What fixed weights can give, for scale (:func:`fixed_weight_moments`): the static mid-span moment of the
simply supported 40 m span under the bundled lorries of ``sumo_networks/vtypes.add.xml`` at their own
weights, each placement at its worst position: the heaviest alone (the loaded articulated lorry, 40 t), two
of them side by side (one per lane), and both lanes packed nose to tail at SUMO's minimum gap (a jam).
"""
from __future__ import annotations

import argparse
import functools
import itertools
import math
import shutil
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DATA = HERE / "results" / "loads-fixed-vs-auxerre"
FIGURE = ROOT / "docs" / "img" / "loads-fixed-vs-auxerre.png"

#: The study's axis values, in the table's column order, and how the table and figure name them.
CASES = {"fixed": "fixed vType weights", "Auxerre": "Auxerre's loads"}
#: The detail (a stress sensor with an S-N curve) and the moment sensor of the study.
DETAIL, MOMENT = "flange_east", "mid_moment"
#: Slope of the S-N curve the equivalent stress range is taken with (EN 1993-1-9: m1 = 3).
M1 = 3.0
#: Record classes of the heavy vehicles: fixed weights give their vClass, drawn loads "truck-N".
HEAVY_VCLASSES = ("bus", "truck", "trailer", "coach")
#: Levels of the moment's up-crossing count, N m; those the table quotes, MN m.
LEVEL_STEP = 0.05e6
CROSSING_LEVELS = (3.0, 4.0, 5.0)
G = 9.81
#: The base's single simply supported span (examples/scenarios/steel-girder-auxerre.toml), m; the bundled
#: vTypes; SUMO's default gap between stopped vehicles (a vType's minGap unset), m.
SPAN = 40.0
VTYPES = ROOT / "sumo_networks" / "vtypes.add.xml"
MIN_GAP = 2.5


def is_heavy(vehicle_class: str) -> bool:
    return vehicle_class in HEAVY_VCLASSES or vehicle_class.startswith("truck-")


def mid_span_moment(positions: np.ndarray, loads: np.ndarray, span: float = SPAN) -> np.ndarray:
    """Static mid-span moments (N m) of a simply supported span under point loads: the influence line at
    mid-span is ``min(x, L - x) / 2`` for a unit load at ``x``, zero off the span. ``positions`` (m) may have
    leading axes (one moment per row of placements); ``loads`` (N) match its last axis."""
    x = np.asarray(positions, float)
    influence = np.where((x >= 0.0) & (x <= span), np.minimum(x, span - x) / 2.0, 0.0)
    return np.sum(influence * np.asarray(loads, float), axis=-1)


def heavy_vtypes(path: Path = VTYPES) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """The bundled vTypes with their own axles: id -> (axle positions behind the front bumper m, axle loads N,
    length plus SUMO's minGap m)."""
    out = {}
    for node in ET.parse(path).getroot().iter("vType"):
        params = {p.get("key"): p.get("value") for p in node.findall("param")}
        if "cosim.axles" not in params:
            continue
        axles = np.array([float(v) for v in params["cosim.axles"].split()])
        loads = np.array([float(v) for v in params["cosim.axle_loads"].split()]) * float(node.get("mass")) * G
        out[str(node.get("id"))] = (axles, loads, float(node.get("length")) + float(node.get("minGap", MIN_GAP)))
    return out


@functools.lru_cache(maxsize=4)
def fixed_weight_moments(path: Path = VTYPES, step: float = 0.01) -> dict[str, float]:
    """What fixed weights can give at most, statically (N m), each at its worst position on a ``step`` grid:
    ``alone``: the heaviest lorry on its own; ``side_by_side``: it beside another in the other lane (twice
    alone: the beam's moment does not depend on the lane); ``packed``: both lanes full of the bundled lorries
    nose to tail at SUMO's minGap, the worst sequence of four (a 40 m lane holds at most four of them)."""
    types = heavy_vtypes(path)
    fronts = np.arange(0.0, 2.0 * SPAN, step)
    alone = max(float(mid_span_moment(fronts[:, None] - axles, loads).max()) for axles, loads, _ in types.values())
    packed = 0.0
    for sequence in itertools.product(types.values(), repeat=4):
        behind, positions, loads = 0.0, [], []
        for axles, axle_loads, period in sequence:  # each vehicle's front a period behind the one ahead
            positions.append(fronts[:, None] - behind - axles)
            loads.append(axle_loads)
            behind += period
        packed = max(packed, float(mid_span_moment(np.hstack(positions), np.concatenate(loads)).max()))
    return {"alone": alone, "side_by_side": 2.0 * alone, "packed": 2.0 * packed}


# --------------------------------------------------------------------------- collect: from the study's output


def collect(study: Path, data: Path) -> None:
    """The four files of ``data`` from the study's output folder (its table and its runs' logs)."""
    from cosim.log import iter_messages, sensor_series
    from cosim.log.schemas import TOPIC_VEHICLE_LOADS

    table = pd.read_csv(study / "results.csv")
    if set(table["loads"]) != set(CASES) or (table["status"] != "ok").any():
        raise SystemExit(f"{study}: expected every run ok and loads = {list(CASES)}")
    data.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(study / "results.csv", data / "results.csv")
    shutil.copyfile(study / "characteristic.csv", data / "characteristic.csv")
    vtypes: dict[tuple[int, str], str] = {}  # (seed, vehicle id) -> vType, from the fixed runs' records
    rows = []
    levels = np.arange(0.0, 20e6 + LEVEL_STEP / 2, LEVEL_STEP)
    crossings = {case: np.zeros(len(levels)) for case in CASES}
    hours = dict.fromkeys(CASES, 0.0)
    for case in CASES:  # fixed first: its records name each vehicle's vType
        for _, run in table[table["loads"] == case].iterrows():
            log = study / run["log"]
            seed = int(run["seed"])
            for _, msg in iter_messages(log, [TOPIC_VEHICLE_LOADS]):
                source = str(msg["source"])
                if case == "fixed" and source.startswith("vType "):
                    vtypes[(seed, msg["id"])] = source.split()[1].rstrip(":")
                if not is_heavy(str(msg["class"])):
                    continue
                rows.append({"loads": case, "seed": seed, "id": msg["id"],
                             "vtype": vtypes.get((seed, msg["id"]), ""), "class": msg["class"],
                             "axles": len(msg["axle_loads"]), "gvw_kN": round(float(msg["gvw"]) / 1e3, 3),
                             "max_axle_kN": round(max(msg["axle_loads"]) / 1e3, 3)})
            _, series = sensor_series(log, [MOMENT])
            m = series[MOMENT]
            # up-crossings of each level: a sample below it followed by one at or above it
            crossings[case] += ((m[:-1, None] < levels) & (m[1:, None] >= levels)).sum(axis=0)
            hours[case] += float(run["duration"]) / 3600.0
    pd.DataFrame(rows).to_csv(data / "heavy-vehicles.csv", index=False)
    frame = pd.DataFrame({"level_MNm": levels / 1e6})
    for case in CASES:
        frame[f"{case}_per_hour"] = crossings[case] / hours[case]
    frame.to_csv(data / "moment-crossings.csv", index=False, float_format="%.6g")


# --------------------------------------------------------------------------- report: from the committed files


def summary(data: Path) -> dict[str, dict[str, float]]:
    """Per case: the table's numbers (SI units but t for weights, MPa for stresses, MN m for moments); the
    Auxerre case also the seeds where its run's damage and largest moment exceed the fixed run's of that seed."""
    table = pd.read_csv(data / "results.csv")
    characteristic = pd.read_csv(data / "characteristic.csv").set_index("loads")
    heavy = pd.read_csv(data / "heavy-vehicles.csv")
    crossings = pd.read_csv(data / "moment-crossings.csv").set_index("level_MNm")
    out: dict[str, dict[str, float]] = {}
    for case in CASES:
        runs = table[table["loads"] == case]
        gvw = heavy.loc[heavy["loads"] == case, "gvw_kN"].to_numpy() * 1e3 / G / 1e3  # t
        axle = heavy.loc[heavy["loads"] == case, "max_axle_kN"].to_numpy() * 1e3 / G / 1e3
        cycles = runs[f"{DETAIL}.cycles"].to_numpy(dtype=float)
        ranges = runs[f"{DETAIL}.equivalent_stress_range"].to_numpy(dtype=float)
        per_year = runs[f"{DETAIL}.damage_per_year"].to_numpy(dtype=float)
        maxima = runs[f"{MOMENT}.max"].to_numpy(dtype=float)
        fit = characteristic.loc[case]
        out[case] = {
            "runs": len(runs), "hours": float(runs["duration"].sum()) / 3600.0,
            "vehicles": float(runs["vehicles"].sum()), "heavy": len(gvw),
            "gvw_mean": float(np.mean(gvw)), "gvw_sd": float(np.std(gvw, ddof=1)),
            "gvw_p95": float(np.percentile(gvw, 95)), "gvw_p99": float(np.percentile(gvw, 99)),
            "gvw_max": float(np.max(gvw)), "over_40": float(np.mean(gvw > 40.0 + 1e-9)),
            "over_44": float(np.mean(gvw > 44.0 + 1e-9)), "axle_max": float(np.max(axle)),
            "damage_per_year": float(np.mean(per_year)),
            "damage_se": float(np.std(per_year, ddof=1) / math.sqrt(len(per_year))),
            # the equivalent range of all the runs' cycles together: sum n ds^m / sum n over the runs
            "eq_range": float((np.sum(cycles * ranges**M1) / np.sum(cycles)) ** (1 / M1)) / 1e6,
            "max_range": float(runs[f"{DETAIL}.max_stress_range"].max()) / 1e6,
            "moment_char": float(fit["value"]) / 1e6, "moment_lower": float(fit["lower"]) / 1e6,
            "moment_upper": float(fit["upper"]) / 1e6, "moment_max": float(np.max(maxima)) / 1e6,
            "moment_mean_max": float(np.mean(maxima)) / 1e6, "block": float(fit["block"]),
            **{f"crossings_{level:g}": float(crossings.loc[level, f"{case}_per_hour"]) for level in CROSSING_LEVELS},
        }
    paired = {case: table[table["loads"] == case].set_index("seed").sort_index() for case in CASES}
    fixed, drawn = paired["fixed"], paired["Auxerre"]
    if list(fixed.index) != list(drawn.index):
        raise SystemExit(f"{data}: the two cases do not have the same seeds")
    for key, column in (("damage", f"{DETAIL}.damage"), ("moment", f"{MOMENT}.max")):
        out["Auxerre"][f"seeds_{key}_larger"] = float((drawn[column] > fixed[column]).sum())
    out["fixed"].update({f"reference_{k}": v / 1e6 for k, v in fixed_weight_moments().items()})
    return out


def table_markdown(s: dict[str, dict[str, float]]) -> str:
    f, a = s["fixed"], s["Auxerre"]

    def row(label: str, key: str, fmt: str, ratio: bool = True) -> str:
        r = f" | x {a[key] / f[key]:.2f}" if ratio and f[key] else " |"
        return f"| {label} | {format(f[key], fmt)} | {format(a[key], fmt)}{r} |"

    runs = f"{f['runs']:.0f} seeds x {f['block'] / 60:g} min"
    return "\n".join([
        f"| {runs} each | {CASES['fixed']} | {CASES['Auxerre']} | Auxerre / fixed |",
        "|---|---:|---:|---:|",
        row("vehicles on the deck (the same traffic)", "vehicles", ".0f"),
        row("heavy vehicles (buses, lorries) on the deck", "heavy", ".0f"),
        row("their gross weight: mean [t]", "gvw_mean", ".1f"),
        row("standard deviation [t]", "gvw_sd", ".1f"),
        row("95th percentile [t]", "gvw_p95", ".1f"),
        row("99th percentile [t]", "gvw_p99", ".1f"),
        row("heaviest [t]", "gvw_max", ".1f"),
        f"| share above 40 t | {f['over_40']:.1%} | {a['over_40']:.1%} | |",
        f"| share above 44 t | {f['over_44']:.1%} | {a['over_44']:.1%} | |",
        row("heaviest axle [t]", "axle_max", ".1f"),
        f"| {DETAIL} (EN 1993-1-9 cat. 71): damage per year, mean of the seeds (standard error) | "
        f"{f['damage_per_year']:.4f} ({f['damage_se']:.4f}) | {a['damage_per_year']:.4f} ({a['damage_se']:.4f}) | "
        f"x {a['damage_per_year'] / f['damage_per_year']:.2f} |",
        f"| seeds whose run did more damage with Auxerre's loads than with fixed weights | | "
        f"{a['seeds_damage_larger']:.0f} of {a['runs']:.0f} | |",
        f"| fatigue life at that rate [years] | {1 / f['damage_per_year']:.0f} | {1 / a['damage_per_year']:.0f} | |",
        row("equivalent stress range, m = 3, all cycles [MPa]", "eq_range", ".2f"),
        row("largest stress range [MPa]", "max_range", ".1f"),
        f"| {MOMENT}: characteristic (1000-year) moment, Gumbel [MN m] | {f['moment_char']:.2f} | "
        f"{a['moment_char']:.2f} | x {a['moment_char'] / f['moment_char']:.2f} |",
        f"| its 95 % bootstrap interval [MN m] | {f['moment_lower']:.2f} - {f['moment_upper']:.2f} | "
        f"{a['moment_lower']:.2f} - {a['moment_upper']:.2f} | |",
        row("largest moment seen [MN m]", "moment_max", ".2f"),
        row("mean of the runs' largest moments [MN m]", "moment_mean_max", ".2f"),
        f"| seeds whose largest moment was larger with Auxerre's loads | | {a['seeds_moment_larger']:.0f} of "
        f"{a['runs']:.0f} | |",
        f"| fixed weights, static, at the worst position: one 40 t articulated lorry / two side by side / both "
        f"lanes packed nose to tail [MN m] | {f['reference_alone']:.2f} / {f['reference_side_by_side']:.2f} / "
        f"{f['reference_packed']:.2f} | | |",
        *(row(f"up-crossings of {level:g} MN m per hour", f"crossings_{level:g}", ".2f")
          for level in CROSSING_LEVELS),
    ]) + "\n"


def figure(data: Path, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy import stats

    from cosim.analysis import SECONDS_PER_YEAR

    heavy = pd.read_csv(data / "heavy-vehicles.csv")
    crossings = pd.read_csv(data / "moment-crossings.csv")
    table = pd.read_csv(data / "results.csv")
    characteristic = pd.read_csv(data / "characteristic.csv").set_index("loads")
    colors = {"fixed": "C0", "Auxerre": "C3"}
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(13.5, 4.0), constrained_layout=True)
    bins = np.arange(0.0, 70.0 + 1.0, 1.0)
    for case, label in CASES.items():
        gvw = heavy.loc[heavy["loads"] == case, "gvw_kN"] / G
        ax1.hist(gvw, bins=bins, histtype="stepfilled" if case == "Auxerre" else "step", alpha=0.45
                 if case == "Auxerre" else 1.0, color=colors[case], lw=1.6, label=f"{label} ({len(gvw)})")
        ax2.semilogy(crossings["level_MNm"], crossings[f"{case}_per_hour"].where(crossings[f"{case}_per_hour"] > 0),
                     color=colors[case], label=label)
        runs = table[table["loads"] == case]
        maxima = np.sort(runs[f"{MOMENT}.max"].to_numpy(dtype=float)) / 1e6
        n = len(maxima)
        prob = (np.arange(1, n + 1) - 0.44) / (n + 0.12)  # Gringorten
        block = float(characteristic.loc[case, "block"])
        per_year = SECONDS_PER_YEAR / block
        years = 1.0 / (1.0 - prob) / per_year
        ax3.semilogx(years, maxima, "o", color=colors[case], ms=4, label=f"{label}: largest of each run")
        loc, scale = characteristic.loc[case, "param_loc"], characteristic.loc[case, "param_scale"]
        curve = np.geomspace(years[0] * 0.5, 3000.0, 200)
        ax3.semilogx(curve, stats.gumbel_r.ppf(1.0 - 1.0 / (curve * per_year), loc, scale) / 1e6, color=colors[case],
                     lw=1.2)
        value, lo, hi = (characteristic.loc[case, k] / 1e6 for k in ("value", "lower", "upper"))
        ax3.errorbar([1000.0], [value], yerr=[[value - lo], [hi - value]], fmt="s", color=colors[case], capsize=4,
                     label=f"1000-year: {value:.2f} MN m ({lo:.2f}-{hi:.2f})")
    reference = fixed_weight_moments()
    for key, style, label in (("side_by_side", ":", "two 40 t lorries side by side"),
                              ("packed", "--", "both lanes packed")):
        ax3.axhline(reference[key] / 1e6, color=colors["fixed"], ls=style, lw=1.0,
                    label=f"fixed, static: {label} ({reference[key] / 1e6:.2f})")
    ax1.set(xlabel="gross weight [t]", ylabel="heavy vehicles per 1 t bin",
            title="buses and lorries that crossed the deck")
    ax1.legend(fontsize=8)
    ax2.set_xlim(0.5, None)
    ax2.set(xlabel="mid-span moment [MN m]", ylabel="up-crossings per hour",
            title="how often the mid-span moment exceeds a level")
    ax2.legend(fontsize=8)
    ax3.set(xlabel="return period [years]", ylabel="largest mid-span moment of a run [MN m]",
            title=f"Gumbel fit of the {n} runs' maxima")
    ax3.set_ylim(2.0, 31.0)  # room above the points for the legend
    ax3.legend(fontsize=7, loc="upper left")
    for ax in (ax1, ax2, ax3):
        ax.grid(alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def report(data: Path, figure_path: Path) -> str:
    text = table_markdown(summary(data))
    (data / "table.md").write_text(text)
    figure(data, figure_path)
    return text


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", type=Path, nargs="?", help="the study's output folder (not needed with --report-only)")
    ap.add_argument("--data", type=Path, default=DATA, help=f"the collected files and the table (default {DATA})")
    ap.add_argument("--figure", type=Path, default=FIGURE, help=f"the figure (default {FIGURE})")
    ap.add_argument("--report-only", action="store_true", help="the table and figure from the collected files")
    args = ap.parse_args(argv)
    if not args.report_only:
        if args.study is None:
            ap.error("give the study's output folder, or --report-only")
        collect(args.study, args.data)
    print(report(args.data, args.figure), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
