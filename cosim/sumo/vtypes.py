"""What a SUMO vType is for the beam: its vehicle model and its axles.

SUMO's own ``mass`` (kg) is the gross weight; ``param`` entries prefixed
``cosim.`` give the quarter-car (``cosim.model``, ``cosim.m_w``, ``cosim.k_v``,
``cosim.c_v``, ``cosim.k_t``, ``cosim.c_t``) and the axles (``cosim.axles``,
``cosim.axle_loads``); without them the vClass defaults below apply. Plain
functions of the values libsumo reports: no libsumo here.
"""
from __future__ import annotations

import math
from dataclasses import asdict, replace

from cosim.core.vehicles import MovingForce, QuarterCar, TyreQuarterCar, VehicleModel
from cosim.errors import ConfigError, SumoError

__all__ = [
    "FALLBACK_DEFAULTS",
    "HEAVY_VCLASSES",
    "PARAM_KEYS",
    "PARAM_PREFIX",
    "VCLASS_DEFAULTS",
    "axles_from_parameters",
    "model_from_parameters",
    "scaled_model",
]

PARAM_PREFIX = "cosim."
#: The vType params cosim reads (without the prefix).
PARAM_KEYS = ("model", "m_w", "k_v", "c_v", "k_t", "c_t", "axles", "axle_loads")

# Defaults for vTypes without cosim.* params: body bounce frequency (Hz), damping ratio,
# unsprung share of the gross mass. Cars ride softer than trucks.
VCLASS_DEFAULTS: dict[str, tuple[float, float, float]] = {
    "passenger": (1.2, 0.30, 0.10),
    "private": (1.2, 0.30, 0.10),
    "taxi": (1.2, 0.30, 0.10),
    "evehicle": (1.2, 0.30, 0.10),
    "motorcycle": (1.5, 0.30, 0.15),
    "delivery": (1.3, 0.30, 0.11),
    "bus": (1.5, 0.25, 0.12),
    "coach": (1.5, 0.25, 0.12),
    "truck": (1.8, 0.20, 0.12),
    "trailer": (1.8, 0.20, 0.12),
    "emergency": (1.4, 0.25, 0.12),
}
FALLBACK_DEFAULTS = (1.5, 0.25, 0.12)
#: SUMO vehicle classes that count as trucks (a study's ``truck_share``).
HEAVY_VCLASSES = ("bus", "coach", "truck", "trailer")


def model_from_parameters(
    type_id: str, mass: float, vclass: str, params: dict[str, str]
) -> VehicleModel:
    """Vehicle model of a vType from SUMO's ``mass`` and its ``cosim.*`` params (or vClass defaults).

    Raises:
        SumoError: a param is not a number or the parameters are not physical.
    """
    def number(key: str) -> float | None:
        text = params.get(PARAM_PREFIX + key)
        if text is None or text == "":
            return None
        try:
            value = float(text)
        except ValueError:
            raise SumoError(f"vType {type_id}: param `{PARAM_PREFIX}{key}` must be a number (got {text!r})") from None
        return value

    if not (mass > 0 and math.isfinite(mass)):
        raise SumoError(f"vType {type_id}: `mass` must be > 0 kg (got {mass})")
    kind = params.get(PARAM_PREFIX + "model", "quarter-car")
    f_body, zeta, share = VCLASS_DEFAULTS.get(vclass, FALLBACK_DEFAULTS)
    m_w = number("m_w")
    m_w = share * mass if m_w is None else m_w
    m_v = mass - m_w
    if not m_v > 0:
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}m_w` = {m_w} kg leaves no body mass (mass = {mass} kg)")
    omega = 2 * math.pi * f_body
    k_v = number("k_v")
    k_v = m_v * omega**2 if k_v is None else k_v
    c_v = number("c_v")
    c_v = 2 * zeta * math.sqrt(k_v * m_v) if c_v is None else c_v
    try:
        if kind == "moving-force":
            return MovingForce(mass)
        if kind == "quarter-car":
            return QuarterCar(m_v=m_v, m_w=m_w, k_v=k_v, c_v=c_v)
        if kind == "tyre-quarter-car":
            k_t = number("k_t")
            k_t = 10.0 * k_v if k_t is None else k_t  # a tyre ~10x stiffer than the suspension
            return TyreQuarterCar(m_v=m_v, m_w=m_w, k_v=k_v, c_v=c_v, k_t=k_t, c_t=number("c_t") or 0.0)
    except ConfigError as exc:
        raise SumoError(f"vType {type_id}: {exc}") from None
    raise SumoError(
        f"vType {type_id}: param `{PARAM_PREFIX}model` must be moving-force, quarter-car or tyre-quarter-car "
        f"(got {kind!r})"
    )


def axles_from_parameters(type_id: str, length: float, params: dict[str, str]) -> tuple[tuple[float, float], ...]:
    """The vType's axles as (distance behind the front bumper m, share of the load), or one at mid-length.

    ``cosim.axles`` lists the distances (m, space-separated), ``cosim.axle_loads``
    the shares of the vehicle's weight and suspension (summing to 1).

    Raises:
        SumoError: the lists do not match, are not numbers, or are not physical.
    """
    spacing = params.get(PARAM_PREFIX + "axles", "").split()
    loads = params.get(PARAM_PREFIX + "axle_loads", "").split()
    if not spacing and not loads:
        return ((0.5 * length, 1.0),)
    try:
        where = [float(v) for v in spacing]
        share = [float(v) for v in loads]
    except ValueError:
        raise SumoError(f"vType {type_id}: params `{PARAM_PREFIX}axles` and `{PARAM_PREFIX}axle_loads` must be "
                        "space-separated numbers") from None
    if len(where) != len(share):
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axles` has {len(where)} value(s), "
                        f"`{PARAM_PREFIX}axle_loads` {len(share)}: give one load share per axle")
    if any(not 0.0 <= d <= length for d in where):
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axles` must lie on the vehicle, 0 to {length:g} m "
                        f"behind the front bumper (got {spacing})")
    if any(not f > 0 for f in share) or abs(sum(share) - 1.0) > 1e-6:
        raise SumoError(f"vType {type_id}: `{PARAM_PREFIX}axle_loads` must be positive and sum to 1 (got {loads})")
    return tuple(zip(where, share))


def scaled_model(model: VehicleModel, share: float) -> VehicleModel:
    """The part of ``model`` carried by one axle: masses, stiffnesses and dampings times ``share``."""
    if isinstance(model, MovingForce):
        return MovingForce(model.mass * share)
    return replace(model, **{k: v * share for k, v in asdict(model).items()})
