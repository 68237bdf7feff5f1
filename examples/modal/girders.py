"""A 40 m simply supported slab on five concrete girders in OpenSeesPy, its modes written for cosim
(docs/modal-decks.md, "Worked example: a slab on five girders").

    python examples/modal/girders.py [--out FILE] [--modes N]

The model (:func:`build`), in cosim's bridge frame (x along the span from the first support line, y to the
left, z up), self-weight only (no surfacing, no parapets: the one-beam model of the same bridge,
``girders-beam.toml``, has exactly the same mass and material):

- the slab: 13.0 m wide (y = -6.5 ... 6.5 m: two 3.75 m lanes at y = +-1.875 m and 2.75 m margins for the
  sidewalks), 0.25 m of concrete (E = 36 GPa, nu = 0.2, 2500 kg/m^3), ShellMITC4 elements;
- five precast concrete I-girders (the bulb-tee shape of :data:`GIRDER`: 1.8 m deep, a 1.0 x 0.15 m top
  flange, a 0.16 m web, a 0.65 x 0.25 m bottom flange; the same concrete) 2.5 m apart at
  y = -5, -2.5, 0, 2.5, 5 m, elasticBeamColumn elements with consistent mass whose axes lie at the girder's
  own centroid, 1.0 m below the slab's mid-plane, tied to the slab's nodes by rigid joint offsets
  (``geomTransf ... -jntOffset``);
- end diaphragms (0.3 x 1.5 m, the same concrete, their axes 0.875 m below the slab) between the girders at
  both support lines; bearings under every girder at the slab's nodes: vertical at both ends, longitudinal at
  x = 0, lateral under the first girder (simply supported, free to rotate about y).

Why offset girders and not composite-T sections on the slab's nodes: with the girder's own section at its own
centroid, the slab's membrane stiffness and the girders' axial stiffness make the composite action themselves,
whatever width of the slab works with each girder (shear lag, the outer girders' shorter overhang); a T
section at the slab's nodes would need an effective width chosen beforehand and would count the slab's
bending stiffness twice (in the T and in the shells). The girder's constants are those of its plates by
cosim's own section solver (:func:`girder_section`), so that ``girders-beam.toml``'s plates are the same
concrete.

The mesh: 32 shells along the span (1.25 m) and 24 across (0.375 to 0.625 m: node lines at the edges, the
girders, midway between them and at the lanes' centres, y = +-1.875 m): 825 deck nodes, 4950 DOFs. The
script takes the first 50 modes (to about 60 Hz) with ``from_opensees`` and writes them, with the nodes'
slopes along the span and the shells' triangles, to ``girders-modes.npz`` (under 1 MB).
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cosim.bridges import from_opensees, write_modes
from cosim.core.modal_deck import ModalDeck
from cosim.core.section import Plate, SectionProperties, section_from_plates

HERE = Path(__file__).resolve().parent
MODES_FILE = HERE / "girders-modes.npz"
SPAN = 40.0  # m, the bundled network's bridge
EDGE = 6.5  # m: the deck is 13 m wide
GIRDERS_Y = (-5.0, -2.5, 0.0, 2.5, 5.0)  # m
LANES_Y = (-1.875, 1.875)  # m: the bundled network's eastbound (+x) and westbound (-x) lanes
E, NU, RHO = 36e9, 0.2, 2500.0  # concrete, Pa, -, kg/m^3 (slab, girders and diaphragms alike)
SLAB_T = 0.25  # m
#: A girder's plates, (y, z) of each midline's ends and the thickness, m, for a girder at y = 0 whose top
#: flange touches the slab's underside (z = -SLAB_T / 2); the web runs up into the top flange.
GIRDER = (((-0.5, -0.2), (0.5, -0.2), 0.15),  # top flange 1.0 x 0.15
          ((0.0, -0.2), (0.0, -1.8), 0.16),  # web
          ((-0.325, -1.8), (0.325, -1.8), 0.25))  # bottom flange 0.65 x 0.25 (the girder ends at z = -1.925)
DIAPHRAGM = dict(b=0.3, h=1.5, offset=SLAB_T / 2 + 0.75)  # m
N_MODES = 50
NX, ACROSS = 32, 2


def girder_plates(y: float, *, to_slab: bool = False) -> list[Plate]:
    """The plates of the girder at ``y``; with ``to_slab`` its web continues up to the slab's mid-plane, so that
    it joins the slab's plate in one section (the one-beam model's)."""
    plates = [Plate((a[0] + y, a[1]), (b[0] + y, b[1]), t) for a, b, t in GIRDER]
    if to_slab:
        (a, b, t) = GIRDER[1]
        plates[1] = Plate((y, 0.0), (y, b[1]), t)
    return plates


def girder_section() -> SectionProperties:
    """One girder's constants (A, I_y, I_z, J and its centroid's depth) from cosim's section solver."""
    return section_from_plates(girder_plates(0.0), nu=NU)


@dataclass(frozen=True)
class GirderDeck:
    """The built model: its grid of slab nodes (every one on the deck) and the girders' lines."""

    xs: np.ndarray  # (nx + 1,) node lines along the span, m
    ys: np.ndarray  # (ny,) node lines across, m
    girder_lines: tuple[int, ...]  # indices into ys
    section: SectionProperties = field(repr=False)

    def tag(self, i: int, j: int) -> int:
        """The slab node at xs[i], ys[j]."""
        return int(1 + i * len(self.ys) + j)

    @property
    def deck_nodes(self) -> list[int]:
        return [self.tag(i, j) for i in range(len(self.xs)) for j in range(len(self.ys))]

    def node(self, x: float, y: float) -> int:
        """The slab node nearest to (x, y)."""
        return self.tag(int(np.argmin(np.abs(self.xs - x))), int(np.argmin(np.abs(self.ys - y))))


def _rectangle(b: float, h: float) -> tuple[float, float, float, float]:
    """A, I about the horizontal axis, I about the vertical axis, J (St Venant, long side h) of b x h."""
    long, short = max(b, h), min(b, h)
    j = long * short**3 * (1 / 3 - 0.21 * short / long * (1 - short**4 / (12 * long**4)))
    return b * h, b * h**3 / 12, h * b**3 / 12, j


def build(ops: Any, nx: int = NX, across: int = ACROSS) -> GirderDeck:
    """Build the deck in OpenSeesPy (wipes the domain first).

    Args:
        nx: shells along the span (even: a node line at mid-span).
        across: shells between two neighbouring lines of the coarse set (the edges, the girders and the lines
            midway between neighbours).
    """
    coarse = sorted({-EDGE, EDGE, *GIRDERS_Y})
    coarse = sorted({*coarse, *((a + b) / 2 for a, b in zip(coarse, coarse[1:]))})
    ys = np.unique(np.concatenate([np.linspace(a, b, across + 1) for a, b in zip(coarse, coarse[1:])]))
    xs = np.linspace(0.0, SPAN, nx + 1)
    section = girder_section()
    model = GirderDeck(xs, ys, tuple(int(np.argmin(np.abs(ys - g))) for g in GIRDERS_Y), section)
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            ops.node(model.tag(i, j), float(x), float(y), 0.0)
    ops.section("ElasticMembranePlateSection", 1, E, NU, SLAB_T, RHO)
    element = 1
    for i in range(nx):
        for j in range(len(ys) - 1):
            ops.element("ShellMITC4", element, model.tag(i, j), model.tag(i + 1, j), model.tag(i + 1, j + 1),
                        model.tag(i, j + 1), 1)
            element += 1
    g = E / (2 * (1 + NU))
    # The girder's axis at its centroid: its local y (the section's horizontal axis) is the global Y, z up.
    dz = section.z_c  # negative: below the slab's mid-plane
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, dz, 0.0, 0.0, dz)
    for j in model.girder_lines:
        for i in range(nx):
            ops.element("elasticBeamColumn", element, model.tag(i, j), model.tag(i + 1, j), section.A, E, g,
                        section.J, section.I_y, section.I_z, 1, "-mass", RHO * section.A, "-cMass")
            element += 1
    a, i_y, i_z, j_t = _rectangle(DIAPHRAGM["b"], DIAPHRAGM["h"])
    dz = -DIAPHRAGM["offset"]
    ops.geomTransf("Linear", 2, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, dz, 0.0, 0.0, dz)
    first, last = model.girder_lines[0], model.girder_lines[-1]
    for i in (0, nx):
        for j in range(first, last):
            ops.element("elasticBeamColumn", element, model.tag(i, j), model.tag(i, j + 1), a, E, g, j_t, i_y, i_z,
                        2, "-mass", RHO * a, "-cMass")
            element += 1
    for j in model.girder_lines:
        lateral = 1 if j == first else 0
        ops.fix(model.tag(0, j), 1, lateral, 1, 0, 0, 0)
        ops.fix(model.tag(nx, j), 0, lateral, 1, 0, 0, 0)
    return model


def import_modes(ops: Any, model: GirderDeck, n_modes: int = N_MODES) -> ModalDeck:
    """The first ``n_modes`` mass-normalised modes at the slab's nodes (cosim.bridges.from_opensees)."""
    return from_opensees(model.deck_nodes, n_modes, ops=ops)


def static_deflections(ops: Any, model: GirderDeck, x: float, y: float, force: float,
                       points: list[tuple[float, float]]) -> np.ndarray:
    """OpenSees' linear static analysis: the vertical displacement (m) at the slab nodes nearest ``points``
    under a vertical ``force`` (N, negative down) at the slab node nearest (x, y). The load is removed and the
    domain reset afterwards."""
    ops.wipeAnalysis()
    ops.timeSeries("Constant", 900)
    ops.pattern("Plain", 900, 900)
    ops.load(model.node(x, y), 0.0, 0.0, force, 0.0, 0.0, 0.0)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        raise RuntimeError("OpenSees' static analysis failed")
    out = np.array([ops.nodeDisp(model.node(px, py), 3) for px, py in points])
    ops.remove("loadPattern", 900)
    ops.remove("timeSeries", 900)
    ops.wipeAnalysis()
    ops.reset()
    return out


def composite_f1(section_all: SectionProperties) -> float:
    """The first bending frequency of the whole cross-section as one simply supported Euler-Bernoulli beam,
    Hz: (pi / 2 L^2) sqrt(E I / m), with I and m = rho A of the slab and all five girders together."""
    return float(np.pi / (2 * SPAN**2) * np.sqrt(E * section_all.I_y / (RHO * section_all.A)))


def whole_section() -> SectionProperties:
    """The slab and the five girders as one section (the one-beam model's, ``girders-beam.toml``)."""
    plates = [Plate((-EDGE, 0.0), (EDGE, 0.0), SLAB_T)]
    for y in GIRDERS_Y:
        plates += girder_plates(y, to_slab=True)
    return section_from_plates(plates, nu=NU)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=MODES_FILE)
    parser.add_argument("--modes", type=int, default=N_MODES)
    args = parser.parse_args()
    import openseespy.opensees as ops

    model = build(ops)
    deck = import_modes(ops, model, args.modes)
    write_modes(args.out, deck)
    s = model.section
    print(f"girder: A = {s.A:.4f} m^2, I_y = {s.I_y:.4f} m^4, J = {s.J:.5f} m^4, centroid {-s.z_c:.3f} m below "
          "the slab's mid-plane")
    print(f"{len(model.deck_nodes)} deck nodes, {deck.n_modes} modes, {deck.f_hz[0]:.3f} to {deck.f_hz[-1]:.1f} Hz;"
          f" first: {', '.join(f'{f:.3f}' for f in deck.f_hz[:8])} Hz")
    print(f"one composite beam's first bending frequency: {composite_f1(whole_section()):.3f} Hz")
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
