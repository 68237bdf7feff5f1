"""The beam model's own modes as a deck given by its modes (:func:`from_beam`, docs/modal-decks.md).

A beam scenario moves to the modal route and back: its modes, sampled at
every node of the beam on lines across the deck, with each element's own end
slopes, give the interpolation of docs/theory.md §13 exactly what the beam's
contact rows give (§5.1, §6.8): the deck's ``w = w_S + (y - y_S) theta_x`` is
cubic per element along x and linear across.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Union

import numpy as np
import numpy.typing as npt

from cosim.core.bridge import BridgeModel
from cosim.core.element import ELEMENT_DOFS, NODE_DOFS
from cosim.core.modal_deck import MODAL_QUANTITIES, ModalDeck
from cosim.core.sensors import Sensor, sensor_row
from cosim.errors import ConfigError

__all__ = ["DEFAULT_BEAM_MODES", "from_beam"]

#: Modes taken when neither ``n_modes`` nor the scenario's modal basis says how many (the scenario's default).
DEFAULT_BEAM_MODES = 30
#: Slopes from both sides of a node that differ by less than this share of the largest are one slope.
SLOPE_JUMP = 1e-12


def _inputs(model: Any) -> tuple[BridgeModel, Any, Sequence[Sensor], str]:
    """(bridge, solver settings or None, sensors, name) of a BridgeModel or of a scenario (anything with
    ``build_bridge()``; its ``solver_settings()`` and ``sensors_core()`` are used when it has them)."""
    if isinstance(model, BridgeModel):
        return model, None, (), "beam model"
    if not callable(getattr(model, "build_bridge", None)):
        raise ConfigError(f"from_beam: expected a BridgeModel or a scenario (got {type(model).__name__})")
    bridge = model.build_bridge()
    settings = model.solver_settings() if callable(getattr(model, "solver_settings", None)) else None
    sensors = model.sensors_core() if callable(getattr(model, "sensors_core", None)) else ()
    name = str(getattr(model, "source", "") or "scenario")
    return bridge, settings, sensors, name


def _lines(bridge: BridgeModel, lateral: Union[int, Sequence[float]]) -> npt.NDArray[np.float64]:
    y_min, y_max = bridge.section.deck_y
    if isinstance(lateral, bool):
        raise ConfigError("from_beam: `lateral` must be a number of lines or the lines' y, m")
    if isinstance(lateral, (int, np.integer)):
        if lateral < 2:
            raise ConfigError(f"from_beam: `lateral` must be >= 2 lines across the deck (got {lateral})")
        return np.linspace(y_min, y_max, int(lateral))
    try:
        ys = np.array(sorted(float(v) for v in lateral))
    except (TypeError, ValueError):
        raise ConfigError("from_beam: `lateral` must be a number of lines or the lines' y, m") from None
    if len(ys) < 2 or not np.all(np.isfinite(ys)) or np.any(np.diff(ys) <= 0):
        raise ConfigError(f"from_beam: `lateral` must be two or more distinct finite y, m (got {list(lateral)})")
    return ys


def from_beam(model: Any, *, n_modes: int | None = None, lateral: Union[int, Sequence[float]] = 5,
              sensors: Sequence[Sensor] | None = None) -> ModalDeck:
    """The beam's modes as a :class:`~cosim.core.modal_deck.ModalDeck` in the bridge frame.

    Args:
        model: a :class:`~cosim.core.bridge.BridgeModel`, or a scenario (``cosim.load_scenario(...)``).
        n_modes: how many of the lowest modes; default: the scenario's modal basis (``[solver] modes`` or
            ``cutoff_hz``, the same modes its modal-basis run uses), else :data:`DEFAULT_BEAM_MODES`.
        lateral: lines across the deck the modes are sampled on: a number of equally spaced lines between
            the deck's edges (``section.deck_y``), or their y, m. The deck's w is linear across, so any two
            lines reproduce it; more lines only draw it finer.
        sensors: sensors whose quantity the modes cannot give (a bending moment, a stress) get their modal
            values as ``<quantity>:<name>``; default: the scenario's sensors.

    Returns:
        Points on the grid (every beam node x every line), mass-normalised shapes (the beam's modal basis),
        their slopes from each element (``phi_x``, and ``phi_x_minus`` where the shear strain makes them
        jump), ``zeta`` from the bridge's Rayleigh damping (``alpha / (2 omega) + beta omega / 2``) and
        ``modal_mass`` = 1.
    """
    bridge, settings, own_sensors, name = _inputs(model)
    count, cutoff = n_modes, None
    if count is None and settings is not None and getattr(settings, "basis", "") == "modal":
        count, cutoff = settings.modes, settings.cutoff_hz
        if count is None and cutoff is not None:
            count = min(len(bridge.free), 400)  # as cosim.core.bases.ModalBasis does
    if count is None:
        count = DEFAULT_BEAM_MODES
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ConfigError(f"from_beam: `n_modes` must be an integer >= 1 (got {count!r})")
    modal = bridge.modes(int(count))
    keep = np.ones(len(modal.omega), dtype=bool) if cutoff is None else modal.f_hz <= cutoff
    if not keep.any():
        raise ConfigError(f"from_beam: no mode of {name} below cutoff_hz = {cutoff} Hz")
    shapes = modal.shapes[:, keep]  # (ndof, m), mass-normalised
    omega = modal.omega[keep]
    ys = _lines(bridge, lateral)

    c_w, c_t, lengths = bridge.deck_coefficients  # (n_el, 14, 4) each, (n_el,)
    n_el = bridge.n_elements
    dofs = NODE_DOFS * np.arange(n_el)[:, None] + np.arange(ELEMENT_DOFS)[None, :]
    element_shapes = shapes[dofs]  # (n_el, 14, m)
    a = np.einsum("edp,edj->epj", c_w, element_shapes)  # w at the shear centre: cubic in xi per element
    b = np.einsum("edp,edj->epj", c_t, element_shapes)  # theta_x
    lever = ys - bridge.section.y_s  # (ny,)
    poly = a[:, None, :, :] + lever[None, :, None, None] * b[:, None, :, :]  # (n_el, ny, 4, m)
    start_value = poly[:, :, 0, :]
    end_value = poly.sum(axis=2)
    start_slope = poly[:, :, 1, :] / lengths[:, None, None]
    end_slope = np.einsum("p,eypj->eyj", np.arange(4.0), poly) / lengths[:, None, None]
    value = np.concatenate([start_value, end_value[-1:]])  # (n_nodes, ny, m): each node from its right element
    slope = np.concatenate([start_slope, end_slope[-1:]])  # the limit from +x (at the last node, from -x)
    behind = np.concatenate([start_slope[:1], end_slope])  # the limit from -x (at the first node, from +x)

    n_nodes, ny, m = value.shape
    xs = bridge.nodes_x
    points = np.column_stack([np.repeat(xs, ny), np.tile(ys, n_nodes)])
    phi = value.reshape(n_nodes * ny, m).T
    phi_x = slope.reshape(n_nodes * ny, m).T
    phi_x_minus: npt.NDArray[np.float64] | None = behind.reshape(n_nodes * ny, m).T
    if np.max(np.abs(behind - slope)) <= SLOPE_JUMP * max(float(np.max(np.abs(slope))), 1e-300):
        phi_x_minus = None
    zeta = bridge.alpha / (2.0 * omega) + bridge.beta * omega / 2.0
    quantities = {}
    for sensor in own_sensors if sensors is None else sensors:
        if sensor.quantity in MODAL_QUANTITIES:
            row = sensor_row(bridge, sensor)
            quantities[f"{sensor.quantity}:{sensor.name}"] = row.values[0] @ shapes[row.dofs]
    return ModalDeck(points=points, f_hz=omega / (2.0 * np.pi), phi=phi, frame="bridge", phi_x=phi_x,
                     phi_x_minus=phi_x_minus, zeta=zeta, modal_mass=np.ones(m), quantities=quantities,
                     source=f"from_beam({name})")
