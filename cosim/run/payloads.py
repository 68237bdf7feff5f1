"""Plain-JSON documents of a bridge: section constants, modes, damping (log attachments, ``--json`` outputs).

The same payloads go into a log (``section.json``, ``modes.json``), the
``cosim modes --json`` output and the static summary of ``cosim run``.
"""
from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

from cosim.core.bridge import BridgeModel, ModalResult
from cosim.core.element import DOF_INDEX, NODE_DOFS
from cosim.core.modal_bridge import ModalBridge
from cosim.core.section import SectionProperties

#: What the mode shapes of :func:`modes_payload` hold and in which units.
SHAPE_NOTE = (
    "mass-normalised (phi^T M phi = 1) nodal values at nodes_x: w on the bridge axis y = 0 (w_S - y_S theta_x) "
    "and v of the shear centre in m/sqrt(kg), theta_x in rad/sqrt(kg); the sign makes each mode's largest DOF positive"
)


def jsonable(value: Any) -> Any:
    """Plain JSON types from numpy scalars/arrays, tuples and dataclass fields (non-finite -> None)."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if hasattr(value, "tolist"):
        return jsonable(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def section_payload(section: SectionProperties) -> dict[str, Any]:
    """Every section constant by name (SI units); not the FE mesh and fields of a section of plates."""
    return jsonable({f.name: getattr(section, f.name) for f in fields(section) if f.name != "stress_field"})


def modes_payload(modal: ModalResult, shapes: bool = False) -> list[dict[str, Any]]:
    """One entry per mode: ``n`` (1-based), ``f_hz``, ``kind`` and the effective modal mass fractions.

    With ``shapes``, each entry also has ``shape``: the nodal values (at
    ``modal.bridge.nodes_x``) of ``w`` on the bridge axis, the twist ``theta_x``
    and the lateral ``v``, mass-normalised (:data:`SHAPE_NOTE`).
    """
    f_hz = modal.f_hz
    entries = [
        {
            "n": i + 1,
            "f_hz": float(f_hz[i]),
            "kind": modal.kinds[i],
            "participation": {kind: float(values[i]) for kind, values in modal.participation.items()},
        }
        for i in range(len(f_hz))
    ]
    if shapes:
        nodal = modal.shapes.reshape(modal.bridge.n_nodes, NODE_DOFS, -1)  # (node, DOF, mode)
        w_s, twist, v = (nodal[:, DOF_INDEX[name], :] for name in ("w", "theta_x", "v"))
        # The deck point on the axis: w(x, 0) = w_S + (0 - y_S) theta_x (docs/theory.md (1.4)), exact at the nodes.
        w_axis = w_s - modal.bridge.section.y_s * twist
        for i, entry in enumerate(entries):
            entry["shape"] = {"w": w_axis[:, i].tolist(), "theta_x": twist[:, i].tolist(), "v": v[:, i].tolist()}
    return entries


def modal_deck_payload(bridge: ModalBridge) -> dict[str, Any]:
    """A deck given by its modes: where its modes came from, each mode's frequency and damping ratio, the deck's
    extent and how it was placed."""
    return {
        "source": bridge.source,
        "placement": bridge.placement,
        "length": float(bridge.length),
        "deck_y": [float(v) for v in bridge.deck_y],
        "points": int(bridge.deck.points.shape[0]),
        "modes": [{"n": i + 1, "f_hz": float(f), "zeta": float(z)} for i, (f, z) in enumerate(zip(bridge.f_hz,
                                                                                                 bridge.zeta))],
        "damping": {"note": bridge.damping_note},
    }


def damping_payload(bridge: BridgeModel) -> dict[str, Any]:
    """The Rayleigh coefficients ``alpha`` (1/s), ``beta`` (s) and how they were chosen."""
    return {"alpha": float(bridge.alpha), "beta": float(bridge.beta), "note": bridge.damping_note}
