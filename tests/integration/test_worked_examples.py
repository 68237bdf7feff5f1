"""The worked examples of docs/analysis.md, on short durations, with real SUMO and real MCAP logs.

1. Fatigue of a steel detail at three volumes (examples/studies/fatigue-volumes.toml): each run's damage
   equals an independent count (fatpack) of the history exported from its log, and per year is the day's
   scaled by the stated rule.
2. A characteristic mid-span moment (examples/studies/characteristic-moment.toml): the 1000-year value is
   the Gumbel quantile of an independent scipy fit of the table's maxima, inside its interval.
4. Fixed vType weights against Auxerre's loads (examples/studies/loads-fixed-vs-auxerre.toml and
   loads_side_by_side.py): on a short study, the same SUMO traffic under both, the fixed vehicles at their
   vTypes' weights and the drawn ones not, a run's damage fatpack's count of its log; on the committed
   study, the docs' table is its files', each characteristic moment scipy's Gumbel fit of its maxima.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

import fatpack
import numpy as np
import pandas as pd
import pytest
from scipy import stats

import cosim
from cosim.analysis import SECONDS_PER_YEAR
from cosim.log import sensor_series
from cosim.study import parse_study, run_study

EXAMPLES = Path(cosim.__file__).resolve().parents[1] / "examples" / "studies"
#: The bundled mix's vTypes' own masses (sumo_networks/vtypes.add.xml), kg: what fixed weights give.
VTYPE_MASSES = {"car": 1500.0, "van": 3000.0, "bus": 16000.0, "truck_loaded": 26000.0, "truck_empty": 11000.0,
                "artic_loaded": 40000.0, "artic_empty": 15000.0}


def _study(name: str, tmp_path, **replace: str):
    path = EXAMPLES / name
    text = path.read_text()
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    return parse_study(text, str(path), base_dir=EXAMPLES, output=tmp_path / "out")


def _fatpack_damage(history, category):
    """Miner sum by fatpack: its rainflow on the reversals, the residue as half cycles, its EN 1993-1-9 curve."""
    y = np.asarray(history, float)
    d = np.diff(y)
    keep = np.concatenate([[0], np.flatnonzero(d[:-1] * d[1:] < 0) + 1, [len(y) - 1]])
    cycles, residue = fatpack.find_rainflow_cycles(y[keep])
    ranges = np.abs(cycles[:, 1] - cycles[:, 0]) / 1e6 if len(cycles) else np.zeros(0)
    half = np.abs(np.diff(residue)) / 1e6
    counts = np.concatenate([np.ones(len(ranges)), 0.5 * np.ones(len(half))])
    pairs = np.column_stack([np.concatenate([ranges, half]), counts])
    return fatpack.TriLinearEnduranceCurve(float(category)).find_miner_sum(pairs)


def test_fatigue_of_a_steel_detail_at_three_volumes(tmp_path):
    study = _study("fatigue-volumes.toml", tmp_path, **{"duration = 86400.0": "duration = 30.0"})
    outcome = run_study(study, workers=0)
    table = outcome.table()
    assert list(table["status"]) == ["ok"] * 3
    for column in ("flange_east.damage", "flange_east.damage_per_year", "flange_east.equivalent_stress_range"):
        assert column in table and np.all(np.isfinite(table[column]))
    assert (outcome.study.output / "plots" / "flange_east.damage_per_year.png").is_file()
    for row in outcome.rows:
        _, series = sensor_series(outcome.study.output / row["log"], ["flange_east"])
        assert row["flange_east.damage"] == pytest.approx(_fatpack_damage(series["flange_east"], 71), rel=1e-9)
        # The stated rule: the run's traffic all year.
        assert row["flange_east.damage_per_year"] == pytest.approx(
            row["flange_east.damage"] * SECONDS_PER_YEAR / 30.0, rel=1e-12)
    assert table["vehicles"].iloc[-1] > table["vehicles"].iloc[0]  # 1000 vph brings more vehicles than 250


def test_a_characteristic_mid_span_moment(tmp_path):
    study = _study("characteristic-moment.toml", tmp_path,
                   **{"duration = 600.0": "duration = 60.0", "seeds = 20": "seeds = 6"})
    outcome = run_study(study, workers=0)
    assert outcome.characteristic is not None
    result = pd.read_csv(outcome.characteristic)
    assert len(result) == 1
    row = result.iloc[0]
    maxima = outcome.table()["mid_moment.max"].to_numpy(dtype=float)
    loc, scale = stats.gumbel_r.fit(maxima)  # independent: scipy directly on the table's column
    blocks = 1000.0 * SECONDS_PER_YEAR / 60.0
    assert row["value"] == pytest.approx(stats.gumbel_r.ppf(1 - 1 / blocks, loc, scale), rel=1e-9)
    assert row["lower"] < row["value"] < row["upper"]
    assert row["value"] > maxima.max()
    assert list((outcome.study.output / "plots").glob("return_level_mid_moment*.png"))


def _side_by_side():
    spec = importlib.util.spec_from_file_location("loads_side_by_side", EXAMPLES / "loads_side_by_side.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _frames(log):
    """Each logged SUMO frame as {t: {vehicle: (speed, y)}} (a vehicle's first contact point stands for it)."""
    from cosim.core.traffic import vehicle_of
    from cosim.log import iter_messages
    from cosim.log.schemas import TOPIC_TRAFFIC

    frames = {}
    for _, m in iter_messages(log, [TOPIC_TRAFFIC]):
        vehicles = {}
        for contact, speed, y in zip(m["ids"], m["speed"], m["y"]):
            vehicles.setdefault(vehicle_of(contact), (speed, y))
        frames[round(m["t"], 9)] = vehicles
    return frames


def test_fixed_vtype_weights_against_auxerre_loads(tmp_path):
    """Example 4's study, 2 seeds of 45 s: the same SUMO traffic under both cases (speeds bit for bit, wheel
    paths to 1e-9 m), the fixed vehicles at their vTypes' weights (sumo_networks/vtypes.add.xml), the drawn ones
    Auxerre's with axles adding up to their gross weight (1e-9); a drawn run's damage is fatpack's count of its
    log (1e-9); the example's collect step keeps every heavy vehicle's record and counts the moment's
    up-crossings as an independent loop does."""
    from cosim.log import iter_messages
    from cosim.log.schemas import TOPIC_VEHICLE_LOADS

    study = _study("loads-fixed-vs-auxerre.toml", tmp_path,
                   **{"duration = 1200.0": "duration = 45.0\nplots = false", "seeds = 20": "seeds = 2"})
    outcome = run_study(study, workers=0)
    table = outcome.table()
    assert list(table["status"]) == ["ok"] * 4
    assert list(table["run_id"]) == ["loads-fixed_seed-1", "loads-fixed_seed-2", "loads-Auxerre_seed-1",
                                     "loads-Auxerre_seed-2"]
    fixed, drawn = (table[table["loads"] == case].set_index("seed") for case in ("fixed", "Auxerre"))
    assert list(drawn["loads_seed"]) == list(drawn.index)  # the run's seed draws its loads
    assert fixed["loads_seed"].isna().all()  # no [traffic.loads] in the fixed runs
    heavy_records = 0
    for seed in fixed.index:
        logs = {case: outcome.study.output / rows.loc[seed, "log"] for case, rows in (("fixed", fixed),
                                                                                     ("Auxerre", drawn))}
        # The same traffic: SUMO drove the same vehicles at the same speeds on the same wheel paths (no wander).
        a, b = _frames(logs["fixed"]), _frames(logs["Auxerre"])
        assert set().union(*a.values()) == set().union(*b.values())
        common = [(t, v) for t in a.keys() & b.keys() for v in a[t].keys() & b[t].keys()]
        assert len(common) > 100
        assert all(a[t][v][0] == b[t][v][0] for t, v in common)  # the speed, bit for bit
        assert max(abs(a[t][v][1] - b[t][v][1]) for t, v in common) < 1e-9  # the wheel path (a contact's rounding)
        records = {case: {m["id"]: m for _, m in iter_messages(log, [TOPIC_VEHICLE_LOADS])}
                   for case, log in logs.items()}
        assert records["fixed"].keys() == records["Auxerre"].keys()
        assert fixed.loc[seed, "vehicles"] == drawn.loc[seed, "vehicles"] == len(records["fixed"])
        for vid, rec in records["fixed"].items():
            vtype = rec["source"].split()[1].rstrip(":")
            assert rec["gvw"] == pytest.approx(VTYPE_MASSES[vtype] * 9.81, rel=1e-12)  # its vType's weight
            other = records["Auxerre"][vid]
            assert sum(other["axle_loads"]) == pytest.approx(other["gvw"], rel=1e-9)
            if vtype == "van":  # mapped "fixed": the van keeps its 3 t
                assert other["gvw"] == rec["gvw"]
            else:
                assert other["source"].startswith("Auxerre") and other["gvw"] != rec["gvw"]
                assert other["class"] == ("car" if vtype == "car" else f"truck-{len(other['axle_loads'])}")
            heavy_records += vtype not in ("car", "van")
    # A drawn run's damage: fatpack's independent count of the history in its log.
    seed = int(drawn["flange_east.max_stress_range"].idxmax())
    _, series = sensor_series(outcome.study.output / drawn.loc[seed, "log"], ["flange_east"])
    assert drawn.loc[seed, "flange_east.damage"] == pytest.approx(_fatpack_damage(series["flange_east"], 71),
                                                                   rel=1e-9)
    # The example's collect step: every bus and lorry of both cases, named by its vType; the up-crossings.
    side = _side_by_side()
    data = tmp_path / "data"
    side.collect(outcome.study.output, data)
    heavy = pd.read_csv(data / "heavy-vehicles.csv")
    assert heavy_records > 0 and len(heavy) == 2 * heavy_records
    assert heavy["vtype"].isin([v for v in VTYPE_MASSES if v not in ("car", "van")]).all()
    fixed_heavy = heavy[heavy["loads"] == "fixed"]
    assert np.allclose(fixed_heavy["gvw_kN"] * 1e3, fixed_heavy["vtype"].map(VTYPE_MASSES) * 9.81, atol=1e-3)
    crossings = pd.read_csv(data / "moment-crossings.csv").set_index("level_MNm")
    for case, rows in (("fixed", fixed), ("Auxerre", drawn)):
        count = 0
        for log in rows["log"]:
            _, series = sensor_series(outcome.study.output / log, ["mid_moment"])
            m = series["mid_moment"]
            count += sum(1 for i in range(1, len(m)) if m[i - 1] < 1e6 <= m[i])
        assert crossings.loc[1.0, f"{case}_per_hour"] == pytest.approx(count / (2 * 45.0 / 3600.0), rel=1e-12)
        assert count > 0


def test_the_worked_example_table_is_the_committed_studys():
    """Example 4's numbers in docs/analysis.md are the committed study's (examples/studies/results/
    loads-fixed-vs-auxerre/): its table regenerated from the committed files, word for word in the docs; each
    case's characteristic moment is scipy's Gumbel fit of that case's 20 maxima (1e-9); the fixed case's heavy
    vehicles weigh only what the bundled vTypes say, Auxerre's do not; the reference moment of a lorry alone
    is the largest of its placements with one axle at mid-span (the influence line's peak; 1e-9)."""
    side = _side_by_side()
    numbers = side.summary(side.DATA)
    text = side.table_markdown(numbers)
    assert (side.DATA / "table.md").read_text() == text
    assert text in (EXAMPLES.parents[1] / "docs" / "analysis.md").read_text()
    table = pd.read_csv(side.DATA / "results.csv")
    characteristic = pd.read_csv(side.DATA / "characteristic.csv").set_index("loads")
    assert (table["status"] == "ok").all() and set(table["duration"]) == {1200.0}
    blocks = 1000.0 * SECONDS_PER_YEAR / 1200.0
    for case in ("fixed", "Auxerre"):
        rows = table[table["loads"] == case]
        assert sorted(rows["seed"]) == list(range(1, 21))
        loc, scale = stats.gumbel_r.fit(rows["mid_moment.max"].to_numpy(dtype=float))
        assert characteristic.loc[case, "value"] == pytest.approx(stats.gumbel_r.ppf(1 - 1 / blocks, loc, scale),
                                                                  rel=1e-9)
        assert numbers[case]["moment_char"] == pytest.approx(characteristic.loc[case, "value"] / 1e6, rel=1e-12)
        assert numbers[case]["damage_per_year"] == pytest.approx(rows["flange_east.damage_per_year"].mean(),
                                                                 rel=1e-12)
    heavy = pd.read_csv(side.DATA / "heavy-vehicles.csv")
    fixed_heavy = heavy[heavy["loads"] == "fixed"]
    assert np.allclose(fixed_heavy["gvw_kN"] * 1e3, fixed_heavy["vtype"].map(VTYPE_MASSES) * 9.81, atol=1e-3)
    assert heavy.loc[heavy["loads"] == "Auxerre", "gvw_kN"].max() > 40000.0 * 9.81 / 1e3
    # The reference: a lorry's largest static mid-span moment has one of its axles at mid-span.
    best = 0.0
    for axles, loads, _ in side.heavy_vtypes().values():
        for a in axles:
            x = 20.0 + a - axles  # axle a at mid-span, the others behind or ahead of it
            best = max(best, float(np.sum(loads * np.clip(np.minimum(x, 40.0 - x), 0.0, None) / 2.0)))
    reference = side.fixed_weight_moments()
    assert reference["alone"] == pytest.approx(best, rel=1e-9)
    assert reference["side_by_side"] == 2.0 * reference["alone"] < reference["packed"]
