"""The references themselves, against independent sources (before the model is compared with them).

Sources: Timoshenko & Goodier, Theory of Elasticity (3rd ed., 1970), sec. 109
(the torsion of a rectangle: series and table); sectionproperties (FE
Saint-Venant warping solution, quadratic triangles).
"""
from __future__ import annotations

import pytest
from sectionproperties.analysis import Section
from sectionproperties.pre.library import rectangular_section

from cosim.validation.references import rectangle_section, rectangle_torsion_constant

# Timoshenko & Goodier's table of k1 = J / (a c^3) (a the long side), printed to 3 decimals.
TABLE_ABS = 5e-4
# sectionproperties with triangles of at most 1/100 of the area (about 160 quadratic
# triangles): its J converges from above, measured 3e-4 to 6e-4 above the series.
SECTIONPROPERTIES_REL = 1e-3
SECTIONPROPERTIES_AREA_FRACTION = 1 / 100

GOODIER_TABLE = {1.0: 0.141, 1.5: 0.196, 2.0: 0.229, 2.5: 0.249, 3.0: 0.263, 4.0: 0.281, 5.0: 0.291, 10.0: 0.312}


@pytest.mark.parametrize("ratio", sorted(GOODIER_TABLE))
def test_rectangle_torsion_series_reproduces_timoshenko_and_goodiers_table(ratio: float) -> None:
    # Timoshenko & Goodier sec. 109, table of k1; tolerance: half a unit of its last printed digit.
    k1 = rectangle_torsion_constant(ratio, 1.0) / ratio
    assert k1 == pytest.approx(GOODIER_TABLE[ratio], abs=TABLE_ABS)
    assert rectangle_torsion_constant(1.0, ratio) == rectangle_torsion_constant(ratio, 1.0)  # either side the longer


@pytest.mark.parametrize("ratio", [1.0, 2.0, 6.0])
def test_rectangle_torsion_series_matches_sectionproperties(ratio: float) -> None:
    # sectionproperties' Saint-Venant warping solution; tolerance SECTIONPROPERTIES_REL (1e-3), from above.
    b, h = ratio, 1.0  # wide and flat, as the decks of the twist tests (6 x 1)
    geometry = rectangular_section(d=h, b=b).create_mesh(mesh_sizes=[b * h * SECTIONPROPERTIES_AREA_FRACTION])
    section = Section(geometry)
    section.calculate_geometric_properties()
    section.calculate_warping_properties()
    fe = section.get_j()
    series = rectangle_torsion_constant(b, h)
    assert fe == pytest.approx(series, rel=SECTIONPROPERTIES_REL)
    assert fe >= series, "a displacement-based warping function gives an upper bound of J"
    assert rectangle_section(b, h).J == series

