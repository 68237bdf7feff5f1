"""Mesh convergence of the first vertical frequency: the Euler-Bernoulli limit and a deep Timoshenko beam."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import build_bridge
from cosim.errors import CosimError

from ..references import STEEL, rectangle_section, timoshenko_ss_frequency_hz
from ..results import CaseResult, FigureData, StudyResult, Table, format_number
from .common import TOL_ORDER_MESH_EB, TOL_ORDER_MESH_TIMOSHENKO, first_kind, observed_orders

__all__ = [
    "MeshFigure",
    "mesh_convergence",
]


@dataclass(frozen=True)
class MeshFigure(FigureData):
    """Relative frequency errors against the element count, with the expected slopes."""

    title: str
    labels: tuple[str, ...]
    counts: tuple[npt.NDArray[np.int64], ...]
    errors: tuple[npt.NDArray[np.float64], ...]
    expected_orders: tuple[float, ...]


def mesh_convergence() -> StudyResult:
    """Convergence rate of the first vertical frequency: Euler-Bernoulli limit and a deep Timoshenko beam."""
    L = 6.0
    beams = (
        ("Euler-Bernoulli limit (no shear flexibility)", rectangle_section(0.3, 0.8, shear_factor=1e6),
         np.array([2, 4, 8, 16]), 4.0, TOL_ORDER_MESH_EB),
        ("Timoshenko (deep beam, shear flexible)", rectangle_section(0.3, 0.8), np.array([4, 8, 16, 32]), 2.0,
         TOL_ORDER_MESH_TIMOSHENKO),
    )
    file = "mesh_convergence.png"
    cases, all_errors = [], []
    for label, sec, counts, order, tol in beams:
        ref = float(timoshenko_ss_frequency_hz(1, L, STEEL, sec))
        fe = np.array([first_kind(build_bridge([L], int(n), STEEL, sec, ["pinned", "fork"]), "vertical", 1, 20)[0]
                       for n in counts])
        errors = fe / ref - 1.0
        if np.any(errors <= 0):
            raise CosimError(f"{label}: the consistent-mass frequency must converge from above (errors {errors})")
        orders = observed_orders(L / counts, errors)
        all_errors.append(errors)
        rows = [(str(n), f"{f:.6f}", format_number(e)) for n, f, e in zip(counts, fe, errors)]
        cases.append(CaseResult(
            name=f"Mesh convergence, first vertical frequency: {label}",
            reference=f"Timoshenko frequency equation (Han, Benaroya & Wei 1999) = {ref:.6f} Hz; expected order "
                      f"{order:g} (Strang & Fix: h^(2(p+1-m)))",
            metric=f"order shortfall max(0, {order:g} - min observed order) over "
                   f"{', '.join(map(str, counts))} elements",
            error=max(0.0, order - float(np.min(orders))), tolerance=tol, figures=(file,),
            details=(Table(("elements", "f1 FE [Hz]", "rel. error"), rows),
                     f"Observed orders: {', '.join(f'{p:.2f}' for p in orders)}."),
            values={"min_order": float(np.min(orders)), "max_order": float(np.max(orders)), "f1_ref": ref},
        ))
    figure = MeshFigure(file=file, title="Simply supported beam, L = 6 m, 0.3 x 0.8 m steel",
                        labels=tuple(b[0] for b in beams), counts=tuple(b[2] for b in beams),
                        errors=tuple(all_errors), expected_orders=tuple(b[3] for b in beams))
    return StudyResult(tuple(cases), (figure,))
