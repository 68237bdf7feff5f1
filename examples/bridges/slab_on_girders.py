"""A simply supported slab-on-girders deck in OpenSeesPy, its modes imported into cosim, and a moving force
through those modes against OpenSees' own direct time integration (docs/modal-decks.md).

    python examples/bridges/slab_on_girders.py [--out DIR] [--quick]

The model (:func:`build`): a 24 m span, 9.6 m wide deck: a 0.22 m concrete slab of ShellMITC4 shells (C35/45,
E = 34 GPa, nu = 0.2, 2500 kg/m^3, plus 2 kN/m^2 of surfacing as mass) on four precast girders 2.5 m apart
(0.5 x 1.2 m, C50/60, E = 37 GPa; elastic beam-columns, consistent mass, their axes 0.71 m below the slab's
mid-plane through rigid joint offsets), end diaphragms (0.3 x 1.0 m), bearings under every girder at the
slab's level (vertical at both ends, longitudinal at x = 0, lateral under the first girder). x runs along the
span from the first support line, y to the left, z up: the model is built in cosim's bridge frame.

The check (:func:`direct_response`, :func:`modal_response`): a 100 kN force crosses the deck along a girder at
20 m/s. OpenSees integrates the full model (Newmark, average acceleration) with the force as the nodal loads
that do the same work as the force on the girder's element (Hermite: a vertical force and a moment about y at
each end node of the element under the force); the modal route integrates the imported modes (the same
Newmark, mode by mode) with the generalised forces from cosim's contact interpolation
(``ModalDeck.rows``), which along the girder is the girder element's own Hermite cubic. With every mode the
two would agree to round-off; with m modes they differ by the modal truncation error, which the script
tabulates at the loaded girder, a far girder and the deck edge at mid-span. The test
``tests/verification/test_modal_opensees.py`` runs the coarse mesh; this script's default is the finer one
and writes ``DIR/slab_on_girders.md`` (the committed one is ``examples/bridges/slab_on_girders.md``).
"""
from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cosim.bridges import from_opensees
from cosim.core.modal_deck import ModalDeck

SPAN = 24.0  # m
GIRDERS_Y = (-3.75, -1.25, 1.25, 3.75)  # m, four girders 2.5 m apart
EDGE = 4.8  # m: the deck is 9.6 m wide (1.05 m cantilevers)
SLAB = dict(E=34e9, nu=0.2, t=0.22, rho=2500.0, surfacing=200.0)  # Pa, -, m, kg/m^3, kg/m^2
GIRDER = dict(E=37e9, G=37e9 / 2.4, b=0.5, h=1.2, rho=2500.0, offset=0.11 + 0.6)  # the axis 0.71 m below
DIAPHRAGM = dict(E=34e9, G=34e9 / 2.4, b=0.3, h=1.0, rho=2500.0, offset=0.11 + 0.5)
FORCE = -100e3  # N, downward
SPEED = 20.0  # m/s


@dataclass(frozen=True)
class SlabOnGirders:
    """The built model: its grid of slab nodes (every node is on the deck) and where things are."""

    xs: np.ndarray  # (nx + 1,) node lines along the span, m
    ys: np.ndarray  # (ny,) node lines across, m
    girder_lines: tuple[int, ...]  # indices into ys of the girders
    girder_elements: dict[tuple[int, int], int]  # (girder line j, element i along the span) -> element tag

    def tag(self, i: int, j: int) -> int:
        """The node at xs[i], ys[j]."""
        return int(1 + i * len(self.ys) + j)

    @property
    def deck_nodes(self) -> list[int]:
        return [self.tag(i, j) for i in range(len(self.xs)) for j in range(len(self.ys))]

    def line(self, y: float) -> int:
        return int(np.argmin(np.abs(self.ys - y)))


def _rectangle(b: float, h: float) -> tuple[float, float, float, float]:
    """A, I about the horizontal axis, I about the vertical axis, J (St Venant, long side h) of b x h."""
    long, short = max(b, h), min(b, h)
    j = long * short**3 * (1 / 3 - 0.21 * short / long * (1 - short**4 / (12 * long**4)))
    return b * h, b * h**3 / 12, h * b**3 / 12, j


def build(ops: Any, nx: int = 12, across: int = 1) -> SlabOnGirders:
    """Build the deck in OpenSeesPy (wipes the domain first).

    Args:
        nx: elements along the span (even: a node line at mid-span).
        across: slab elements between two neighbouring lines of the coarse set (edges, girders, midway
            between girders).
    """
    coarse = sorted({-EDGE, EDGE, *GIRDERS_Y, *((a + b) / 2 for a, b in zip(GIRDERS_Y, GIRDERS_Y[1:]))})
    ys = np.unique(np.concatenate([np.linspace(a, b, across + 1) for a, b in zip(coarse, coarse[1:])]))
    xs = np.linspace(0.0, SPAN, nx + 1)
    model = SlabOnGirders(xs, ys, tuple(int(np.argmin(np.abs(ys - g))) for g in GIRDERS_Y), {})
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            ops.node(model.tag(i, j), float(x), float(y), 0.0)
    rho_slab = SLAB["rho"] + SLAB["surfacing"] / SLAB["t"]  # the surfacing's mass smeared into the slab
    ops.section("ElasticMembranePlateSection", 1, SLAB["E"], SLAB["nu"], SLAB["t"], rho_slab)
    element = 1
    for i in range(nx):
        for j in range(len(ys) - 1):
            ops.element("ShellMITC4", element, model.tag(i, j), model.tag(i + 1, j), model.tag(i + 1, j + 1),
                        model.tag(i, j + 1), 1)
            element += 1
    a, i_y, i_z, j_t = _rectangle(GIRDER["b"], GIRDER["h"])
    dz = -GIRDER["offset"]
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, dz, 0.0, 0.0, dz)
    for j in model.girder_lines:
        for i in range(nx):
            ops.element("elasticBeamColumn", element, model.tag(i, j), model.tag(i + 1, j), a, GIRDER["E"],
                        GIRDER["G"], j_t, i_y, i_z, 1, "-mass", GIRDER["rho"] * a, "-cMass")
            model.girder_elements[(j, i)] = element
            element += 1
    a, i_y, i_z, j_t = _rectangle(DIAPHRAGM["b"], DIAPHRAGM["h"])
    dz = -DIAPHRAGM["offset"]
    ops.geomTransf("Linear", 2, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, dz, 0.0, 0.0, dz)
    first, last = model.girder_lines[0], model.girder_lines[-1]
    for i in (0, nx):
        for j in range(first, last):
            ops.element("elasticBeamColumn", element, model.tag(i, j), model.tag(i, j + 1), a, DIAPHRAGM["E"],
                        DIAPHRAGM["G"], j_t, i_y, i_z, 2, "-mass", DIAPHRAGM["rho"] * a, "-cMass")
            element += 1
    for j in model.girder_lines:
        lateral = 1 if j == first else 0
        ops.fix(model.tag(0, j), 1, lateral, 1, 0, 0, 0)
        ops.fix(model.tag(nx, j), 0, lateral, 1, 0, 0, 0)
    return model


def rayleigh(f_hz: np.ndarray, ratio: float = 0.02, modes: tuple[int, int] = (0, 3)) -> tuple[float, float]:
    """alpha (1/s), beta (s) of Rayleigh damping with ``ratio`` at two modes (0-based)."""
    w1, w2 = 2 * np.pi * f_hz[modes[0]], 2 * np.pi * f_hz[modes[1]]
    beta = 2 * ratio / (w1 + w2)
    return float(w1 * w2 * beta), float(beta)


def hermite_loads(model: SlabOnGirders, x: float, force: float) -> list[tuple[int, float, float]]:
    """(node index i along the span, Fz, My) of a vertical force at x on a girder: the loads that do the
    force's work on the girder element's Hermite cubic (w' = -theta_y, so My = -F L G(xi))."""
    xs = model.xs
    if not 0.0 <= x <= xs[-1]:
        return []
    e = min(max(int(np.searchsorted(xs, x, side="right")) - 1, 0), len(xs) - 2)
    h = xs[e + 1] - xs[e]
    t = (x - xs[e]) / h
    return [(e, force * (1 - 3 * t**2 + 2 * t**3), -force * h * (t - 2 * t**2 + t**3)),
            (e + 1, force * (3 * t**2 - 2 * t**3), -force * h * (t**3 - t**2))]


def girder_moment(model: SlabOnGirders, y: float) -> tuple[int, Any]:
    """The element of the girder at y that ends at mid-span, and a function of the OpenSeesPy module that reads
    its bending moment there in the current displacements (N m, sagging positive: -My at the element's end j)."""
    element = model.girder_elements[(model.line(y), (len(model.xs) - 1) // 2 - 1)]
    return element, lambda ops: -ops.eleResponse(element, "localForce")[10]


#: The girders whose own bending moment at mid-span is compared (sensor name -> y): the loaded one and the far one.
MOMENTS = {"loaded": GIRDERS_Y[1], "far": GIRDERS_Y[3]}


def direct_response(ops: Any, model: SlabOnGirders, y_load: float, outputs: list[tuple[float, float]],
                    dt: float, duration: float, alpha: float, beta: float) -> np.ndarray:
    """OpenSees' Newmark (average acceleration) integration of the full model: w at the output nodes, m, and
    the girders' bending moments at mid-span (:data:`MOMENTS`), N m: (steps + 1, k + 2). The force's nodal loads
    are a Path time series per node and DOF."""
    steps = int(round(duration / dt))
    t = np.arange(steps + 1) * dt
    j = model.line(y_load)
    fz = np.zeros((len(model.xs), steps + 1))
    my = np.zeros_like(fz)
    for k, time_k in enumerate(t):
        for i, f, m in hermite_loads(model, SPEED * time_k, FORCE):
            fz[i, k] += f
            my[i, k] += m
    series = 100
    for i in range(len(model.xs)):
        for dof, history in ((3, fz[i]), (5, my[i])):
            if np.any(history):
                ops.timeSeries("Path", series, "-dt", dt, "-values", *history.tolist())
                ops.pattern("Plain", series, series)
                load = [0.0] * 6
                load[dof - 1] = 1.0
                ops.load(model.tag(i, j), *load)
                series += 1
    ops.rayleigh(alpha, beta, 0.0, 0.0)
    ops.wipeAnalysis()
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear", "-factorOnce")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    nodes = [model.tag(int(np.argmin(np.abs(model.xs - x))), model.line(y)) for x, y in outputs]
    moments = [girder_moment(model, y)[1] for y in MOMENTS.values()]
    out = np.zeros((steps + 1, len(nodes) + len(moments)))
    for k in range(1, steps + 1):
        if ops.analyze(1, dt) != 0:
            raise RuntimeError(f"OpenSees failed at step {k}")
        out[k] = [*(ops.nodeDisp(n, 3) for n in nodes), *(moment(ops) for moment in moments)]
    return out


def modal_response(deck: ModalDeck, y_load: float, outputs: list[tuple[float, float]], dt: float,
                   duration: float, n_modes: int, alpha: float, beta: float) -> np.ndarray:
    """The first ``n_modes`` imported modes integrated by Newmark (average acceleration), mode by mode, with
    the generalised forces of cosim's contact rows: w at the outputs, m, and the girders' moments from their
    modal values ``bending_moment:<name>`` (:data:`MOMENTS`), N m: (steps + 1, k + 2)."""
    steps = int(round(duration / dt))
    t = np.arange(1, steps + 1) * dt
    x = SPEED * t
    on = x <= deck.points[:, 0].max()
    rows = deck.rows(np.where(on, x, 0.0), np.full(steps, y_load))[:, 0, :n_modes]  # (steps, m)
    forces = FORCE * rows * on[:, None]
    omega = deck.omega[:n_modes]
    c = alpha + beta * omega**2
    k_eff = omega**2 + 2 * c / dt + 4 / dt**2
    shapes = np.stack([deck.rows(px, py)[0, 0, :n_modes] for px, py in outputs]
                      + [deck.quantities[f"bending_moment:{name}"][:n_modes] for name in MOMENTS], axis=1)
    eta, rate, acc = np.zeros(n_modes), np.zeros(n_modes), np.zeros(n_modes)
    out = np.zeros((steps + 1, shapes.shape[1]))
    for k in range(steps):
        rhs = forces[k] + (4 / dt**2) * eta + (4 / dt) * rate + acc + c * ((2 / dt) * eta + rate)
        new = rhs / k_eff
        new_acc = (4 / dt**2) * (new - eta) - (4 / dt) * rate - acc
        rate = rate + dt / 2 * (acc + new_acc)
        eta, acc = new, new_acc
        out[k + 1] = eta @ shapes
    return out


def truncation_study(ops: Any, nx: int, across: int, counts: list[int], dt: float = 0.005,
                     free: float = 0.5) -> tuple[dict[str, Any], ModalDeck]:
    """Build, import ``max(counts)`` modes, run both integrations; the peak-normalised error per mode count of w
    at the loaded girder, a far girder and the deck edge at mid-span, and of the loaded girder's moment there."""
    model = build(ops, nx=nx, across=across)
    y_load = GIRDERS_Y[1]
    started = time.perf_counter()
    quantities = {f"bending_moment:{name}": girder_moment(model, y)[1] for name, y in MOMENTS.items()}
    deck = from_opensees(model.deck_nodes, max(counts), quantities=quantities, ops=ops)
    imported = time.perf_counter() - started
    alpha, beta = rayleigh(deck.f_hz)
    outputs = [(SPAN / 2, y_load), (SPAN / 2, GIRDERS_Y[3]), (SPAN / 2, -EDGE)]
    duration = SPAN / SPEED + free
    started = time.perf_counter()
    reference = direct_response(ops, model, y_load, outputs, dt, duration, alpha, beta)
    direct_s = time.perf_counter() - started
    peaks = np.max(np.abs(reference), axis=0)
    errors = {}
    for count in counts:
        response = modal_response(deck, y_load, outputs, dt, duration, count, alpha, beta)
        errors[count] = np.max(np.abs(response - reference), axis=0) / peaks
    result = {"nodes": len(model.deck_nodes), "dofs": 6 * len(model.deck_nodes), "f_hz": deck.f_hz,
              "peaks": peaks, "errors": errors, "import_s": imported, "direct_s": direct_s,
              "outputs": outputs, "interpolation": deck.interpolation}
    return result, deck


def report(result: dict[str, Any], nx: int, across: int) -> str:
    f = result["f_hz"]
    lines = [
        "# Slab on girders: modal truncation against OpenSees' direct integration",
        "",
        "Written by `python examples/bridges/slab_on_girders.py` (docs/modal-decks.md). A 100 kN force at "
        "20 m/s along the girder at y = -1.25 m of the 24 m x 9.6 m slab-on-girders deck "
        f"({nx} elements along the span, {across} across between girders and edges: {result['nodes']} nodes, "
        f"{result['dofs']} DOFs); Rayleigh damping 2 % at modes 1 and 4; Newmark, dt = 5 ms. The error is the "
        "largest difference over the run (the crossing and 0.5 s after it) between the modal route and "
        "OpenSees' direct integration, as a share of the direct response's peak at that point.",
        "",
        f"First frequencies: {', '.join(f'{v:.3f}' for v in f[:6])} Hz. Interpolation: {result['interpolation']}.",
        "",
        "| modes | highest f (Hz) | w, loaded girder (y = -1.25 m) | w, far girder (y = 3.75 m) | "
        "w, deck edge (y = -4.8 m) | moment, loaded girder | moment, far girder |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for count, err in result["errors"].items():
        lines.append(f"| {count} | {f[count - 1]:.1f} | " + " | ".join(f"{100 * e:.3f} %" for e in err) + " |")
    peaks = result["peaks"]
    lines += ["", f"Peaks (direct): w {1e3 * peaks[0]:.3f}, {1e3 * peaks[1]:.3f}, {1e3 * peaks[2]:.3f} mm; the "
              f"girders' own moments {peaks[3] / 1e3:.1f} and {peaks[4] / 1e3:.1f} kN m (the slab carries the rest "
              "of the composite section's). "
              f"Import (eigen and normalisation): {result['import_s']:.1f} s; direct integration: "
              f"{result['direct_s']:.1f} s.", ""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent)
    parser.add_argument("--quick", action="store_true", help="the test's coarse mesh")
    args = parser.parse_args()
    import openseespy.opensees as ops

    nx, across = (12, 1) if args.quick else (24, 2)
    counts = [5, 10, 20, 50, 100, 200] if args.quick else [5, 10, 20, 50, 100, 200, 400]
    result, _ = truncation_study(ops, nx, across, counts)
    text = report(result, nx, across)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "slab_on_girders.md").write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
