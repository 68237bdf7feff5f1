"""Plain-JSON documents of a bridge: section constants, modes, damping (log attachments, ``--json`` outputs).

The same payloads go into a log (``section.json``, ``modes.json``), the
``cosim modes --json`` output and the static summary of ``cosim run``.
"""
from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

from cosim.core.bridge import BridgeModel, ModalResult
from cosim.core.section import SectionProperties


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
    """Every section constant by name (SI units)."""
    return jsonable(asdict(section))


def modes_payload(modal: ModalResult) -> list[dict[str, Any]]:
    """One entry per mode: ``n`` (1-based), ``f_hz``, ``kind`` and the effective modal mass fractions."""
    f_hz = modal.f_hz
    return [
        {
            "n": i + 1,
            "f_hz": float(f_hz[i]),
            "kind": modal.kinds[i],
            "participation": {kind: float(values[i]) for kind, values in modal.participation.items()},
        }
        for i in range(len(f_hz))
    ]


def damping_payload(bridge: BridgeModel) -> dict[str, Any]:
    """The Rayleigh coefficients ``alpha`` (1/s), ``beta`` (s) and how they were chosen."""
    return {"alpha": float(bridge.alpha), "beta": float(bridge.beta), "note": bridge.damping_note}
