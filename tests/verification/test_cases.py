"""Every registered validation case meets its stated tolerance (docs/validation.md, docs/theory.md §8).

The cases are the ones ``cosim validate`` reports (:data:`cosim.validation.STUDIES`,
quick settings): each names its reference's source and its tolerance, stated
with its reason in :mod:`cosim.validation.cases.common`. The tests below
the first assert what else the same computed cases must show.
"""
from __future__ import annotations

import pytest

from cosim.validation import STUDIES, Study

# Tolerances of the extra checks (the cases' own ones live in cosim.validation.cases.common).
EXACT_POSITION_ABS = 1e-9  # m: the scripted stop at mid-span


@pytest.mark.parametrize("study", STUDIES, ids=[s.name for s in STUDIES])
def test_every_case_meets_its_tolerance(study: Study, computed) -> None:
    # Source and tolerance: each case's `reference` and `tolerance` (cosim/validation/cases/common.py, TOL_*).
    result = computed(study.name)
    assert result.cases, f"{study.name} computed no case"
    for case in result.cases:
        assert case.group == study.title
        assert case.reference and case.metric, f"{case.name}: the reference's source and the metric must be named"
        if case.informational:
            assert case.passed and case.error is None, case.name
            continue
        assert case.error is not None and case.error <= case.tolerance, (
            f"{case.name}: error {case.error:.3g} > tolerance {case.tolerance:.3g} ({case.reference}; {case.metric})")
        assert case.passed, f"{case.name}: {case.details}"


def test_case_names_are_unique_across_studies(all_computed) -> None:
    names = [c.name for result in all_computed for c in result.cases]
    assert len(set(names)) == len(names)


def test_paper_case_twists_towards_the_loaded_edge_and_factorises_once(computed) -> None:
    # docs/validation.md: the lane at y = +3.325 m twists the deck (Node 2 lowest, then Node 3, Node 1).
    nodes = [c for c in computed("paper").cases if not c.informational]
    w1, w2, w3 = (c.values["min_direct"] for c in nodes)
    assert w2 < w3 < w1 < 0
    # One factorisation of the effective matrix per run, direct and modal (scipy OdeSolver-style counters).
    assert all(c.values["factorizations_direct"] == 1 and c.values["factorizations_modal"] == 1 for c in nodes)


def test_simply_supported_static_case_exercises_shear_deformation(computed) -> None:
    # Gere & Timoshenko: the shear part P a b / (kGA L) must be a real share of the deflection (> 10 %).
    ss = computed("timoshenko-static").case("Timoshenko static deflection, simply supported")
    assert ss.values["shear_share_at_0.5L"] > 0.1 and ss.values["shear_share_at_0.3L"] > 0.1


def test_timoshenko_frequency_case_is_a_deep_beam(computed) -> None:
    # Han, Benaroya & Wei (1999): shear and rotary inertia must matter (Euler-Bernoulli 2 % high at n = 1, 30 % at 4).
    values = computed("timoshenko-frequencies").cases[0].values
    assert values["f1_euler_bernoulli"] / values["f1_ref"] > 1.02
    assert values["f4_euler_bernoulli"] / values["f4_ref"] > 1.3


def test_torsion_cases_are_in_the_mixed_regime_and_warping_restraint_stiffens(computed) -> None:
    # Kollbrunner & Basler: 1 < lambda L < 10 is mixed torsion; restraining warping must cut the twist by > 10 %.
    free = computed("torsion-static").case("Non-uniform torsion, warping free").values
    restrained = computed("torsion-static").case("Non-uniform torsion, warping restrained").values
    assert 1 < free["lambda_L"] < 10
    assert restrained["theta_mid_fe"] < 0.9 * free["theta_mid_fe"]


def test_lateral_torsional_case_is_really_coupled(computed) -> None:
    # Timoshenko & Gere: the shear-centre offset must move the first frequency by more than 1 %.
    assert abs(computed("lateral-torsional").cases[0].values["coupling_shift"]) > 0.01


def test_parked_vehicle_stops_at_mid_span(computed) -> None:
    # The scripted speed profile: uniform deceleration from 10 m/s over 10 m; position exact to 1e-9 m.
    assert computed("parked-vehicle").cases[0].values["x_end"] == pytest.approx(10.0, abs=EXACT_POSITION_ABS)


def test_roughness_fits_lie_in_their_class_bands(computed) -> None:
    # ISO 8608: the fitted G_d(n0) inside the class band (a factor 2 either way of the class value).
    for case in computed("roughness").cases:
        assert case.values["band_low"] <= case.values["gd0_fit"] <= case.values["band_high"], case.name


def test_benscoter_cases_exercise_the_warping_shear(computed) -> None:
    # Benscoter (1954), docs/theory.md §10.4: the stocky girder's warping shear must matter (restrained mid-span twist
    # > 2 % above Vlasov's, third torsional frequency > 5 % below), or the cases could not tell the theories apart.
    result = computed("benscoter")
    restrained = result.case("Benscoter torsion, mid-span torque, warping restrained").values
    assert restrained["theta_mid_ref"] > 1.02 * restrained["theta_mid_vlasov"]
    frequencies = result.case("Benscoter torsional frequencies").values
    assert frequencies["f3_ref"] < 0.95 * frequencies["f3_vlasov"]


def test_paper_bridge_with_benscoter_torsion_is_softer_in_torsion_only(computed) -> None:
    # docs/theory.md §10.5: Benscoter lowers the paper bridge's torsion-1 (by 7 %, within 3-10 %), the loaded edge
    # (Node 2) deflects more, and the axis (Node 1), which does not twist, is unchanged (to 0.1 %).
    values = computed("paper-torsion-theories").cases[0].values
    assert 0.90 * values["torsion1_vlasov"] < values["torsion1_benscoter"] < 0.97 * values["torsion1_vlasov"]
    assert values["min_node2_benscoter"] < values["min_node2_vlasov"]
    assert values["min_node1_benscoter"] == pytest.approx(values["min_node1_vlasov"], rel=1e-3)
