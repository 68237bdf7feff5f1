"""A bridge given by its deck's modes, ready for the coupled step (docs/modal-decks.md, docs/theory.md §13).

:class:`ModalBridge` is what :class:`cosim.core.coupling.CoupledSystem` and
:func:`cosim.core.simulation.simulate` take in place of a beam
(:class:`cosim.core.bridge.BridgeModel`) when the structure is an external
model's: a :class:`~cosim.core.modal_deck.ModalDeck` placed in the bridge frame
(x along the bridge from the first support line, y to the left), the modes the
run keeps, and each mode's damping ratio. The coupled step solves it on its
modes (:class:`cosim.core.bases.DeckModalBasis`); its contact rows come from the
deck's surface (:func:`cosim.core.surface_contact.surface_rows`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Union

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .bridge import ExplicitDamping, RayleighDamping
from .deck_grid import local_coordinates
from .kernels import NODE_SNAP, DeckArrays
from .modal_deck import ModalDeck
from .sensors import Sensor
from .surface_contact import SURFACE_DECK, SurfaceArrays

__all__ = ["ModalBridge", "ModalRatios", "place_deck"]

Array = npt.NDArray[np.float64]

#: A deck point this far before the first support line (x < 0, relative to the deck's length) is round-off.
_X_TOL = 1e-9


@dataclass(frozen=True)
class ModalRatios:
    """Modal damping: one ratio for every mode, or one per mode (fractions of critical, 0 <= zeta < 1)."""

    ratio: Union[float, tuple[float, ...]]


ModalDamping = Union[ModalRatios, RayleighDamping, ExplicitDamping]


def place_deck(deck: ModalDeck, origin: tuple[float, float], along: tuple[float, float]) -> ModalDeck:
    """A network-frame deck moved into the bridge frame of the axis that starts at ``origin`` (network m) and
    runs along the unit vector ``along``: x along it, y to its left. The move is rigid, so the modes and the
    surface are the same; the grid's own direction is still found from the points (docs/modal-decks.md)."""
    if deck.frame != "network":
        raise ConfigError(f"{deck.source or 'modal deck'}: the deck is in the bridge frame already")
    o = np.asarray(origin, dtype=float)
    e = np.asarray(along, dtype=float)
    x, y = local_coordinates(deck.points[:, 0], deck.points[:, 1], o, e)
    return replace(deck, points=np.column_stack([x, y]))


def _zeta(deck: ModalDeck, damping: ModalDamping | None) -> tuple[Array, str]:
    """Each mode's damping ratio and a sentence that says where it came from."""
    m = deck.n_modes
    where = f"{deck.source}: " if deck.source else ""
    omega = deck.omega
    if damping is None:
        if deck.zeta is not None:
            return np.array(deck.zeta), f"the modes file's zeta ({_span(deck.zeta)})"
        return np.zeros(m), "none (no zeta in the modes file, no [bridge.damping])"
    if isinstance(damping, ModalRatios):
        ratio = damping.ratio
        values = np.full(m, float(ratio)) if isinstance(ratio, (int, float)) else np.array(ratio, dtype=float)
        if values.shape != (m,):
            raise ConfigError(f"{where}damping `ratio`: expected one number or one per mode ({m}), got "
                              f"{values.size}")
        bad = np.flatnonzero(~((values >= 0) & (values < 1)))
        if len(bad):
            raise ConfigError(f"{where}damping `ratio`: {values[bad[0]]!r} at mode {bad[0] + 1}: a damping ratio "
                              "is a fraction of critical, 0 <= ratio < 1 (2 % is 0.02)")
        text = f"{values[0]:.3g} for every mode" if np.all(values == values[0]) else f"per mode ({_span(values)})"
        return values, text
    if isinstance(damping, ExplicitDamping):
        if not (damping.alpha >= 0 and damping.beta >= 0):
            raise ConfigError("Rayleigh `alpha` and `beta` must be >= 0")
        zeta = damping.alpha / (2.0 * omega) + damping.beta * omega / 2.0
        return zeta, f"Rayleigh, explicit alpha = {damping.alpha:g} 1/s, beta = {damping.beta:g} s"
    refs = []
    for ref in damping.modes:
        if isinstance(ref, str) or isinstance(ref, bool) or not 1 <= int(ref) <= m:
            raise ConfigError(f"{where}damping `modes`: {ref!r}: a deck given by its modes knows its modes by "
                              f"number only, 1 ... {m} (it cannot tell a vertical from a torsional one)")
        refs.append(int(ref) - 1)
    (z1, z2), (i1, i2) = damping.ratios, refs
    if omega[i1] == omega[i2]:
        raise ConfigError(f"{where}damping `modes`: modes {i1 + 1} and {i2 + 1} have one frequency; Rayleigh "
                          "damping needs two different ones")
    a = np.array([[1.0 / (2.0 * omega[i1]), omega[i1] / 2.0], [1.0 / (2.0 * omega[i2]), omega[i2] / 2.0]])
    alpha, beta = np.linalg.solve(a, [z1, z2])
    zeta = alpha / (2.0 * omega) + beta * omega / 2.0
    return zeta, (f"Rayleigh: {z1:.3g} at mode {i1 + 1} ({deck.f_hz[i1]:.4g} Hz), {z2:.3g} at mode {i2 + 1} "
                  f"({deck.f_hz[i2]:.4g} Hz)")


def _span(values: Array) -> str:
    lo, hi = float(np.min(values)), float(np.max(values))
    return f"{lo:.3g}" if lo == hi else f"{lo:.3g} to {hi:.3g}"


@dataclass(frozen=True, eq=False)
class ModalBridge:
    """A bridge given by its deck's modes, in the bridge frame.

    Args:
        deck: the deck (:class:`~cosim.core.modal_deck.ModalDeck`), its points in the bridge frame (a
            network-frame deck placed by :func:`place_deck` first), with the modes the run keeps
            (:meth:`ModalDeck.select`).
        damping: :class:`ModalRatios`, Rayleigh damping (ratios at two modes by number, or explicit alpha and
            beta), or None: the deck's own ``zeta`` (else undamped).
        placement: how the deck was placed in the bridge frame (for the run's header).

    Attributes:
        length: the deck's extent along x, m (from the first support line, x = 0).
        deck_y: the deck's lateral extent (y_min, y_max), m.
        zeta: (m,) each mode's damping ratio; damping_note: where it came from.

    Raises:
        ConfigError: points before the first support line (x < 0); a damping that does not fit the modes.
    """

    deck: ModalDeck
    damping: ModalDamping | None = None
    placement: str = "the bridge frame"
    zeta: Array = field(init=False)
    damping_note: str = field(init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.deck, ModalDeck):
            raise ConfigError(f"ModalBridge: `deck` must be a ModalDeck (got {type(self.deck).__name__})")
        x = self.deck.points[:, 0]
        extent = float(np.ptp(x))
        if float(x.min()) < -_X_TOL * max(extent, 1.0):
            where = f"{self.deck.source}: " if self.deck.source else ""
            raise ConfigError(f"{where}points: the deck reaches x = {float(x.min()):.6g} m, before the first support "
                              "line; x is measured along the bridge from the first support line (x >= 0)"
                              + ("; give [traffic] axis starting at the deck's first support line"
                                 if self.deck.frame == "network" else ""))
        zeta, note = _zeta(self.deck, self.damping)
        zeta.flags.writeable = False
        object.__setattr__(self, "zeta", zeta)
        object.__setattr__(self, "damping_note", note)

    # ------------------------------------------------------------------------------------------ geometry
    @cached_property
    def length(self) -> float:
        """The deck's extent along x, m."""
        return float(self.deck.points[:, 0].max())

    @cached_property
    def deck_y(self) -> tuple[float, float]:
        """The deck's lateral extent (y_min, y_max), m."""
        y = self.deck.points[:, 1]
        return float(y.min()), float(y.max())

    @property
    def n_modes(self) -> int:
        return self.deck.n_modes

    @property
    def f_hz(self) -> Array:
        """Natural frequencies, Hz."""
        return self.deck.f_hz

    @property
    def omega(self) -> Array:
        """Circular frequencies, rad/s."""
        return self.deck.omega

    @property
    def source(self) -> str:
        return self.deck.source

    def covers(self, x: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Whether each point (x, y) lies on the deck's surface and its length (0 <= x <= length)."""
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        ys = np.atleast_1d(np.asarray(y, dtype=float))
        flat = self.deck.covers(xs.ravel(), ys.ravel()).reshape(xs.shape)
        return flat & (xs >= 0.0) & (xs <= self.length)

    # ----------------------------------------------------------------------------------- the coupled step
    def kernel_deck(self) -> DeckArrays:
        """What the compiled step reads of the deck (:data:`cosim.core.kernels.DeckArrays`, kind SURFACE)."""
        grid = self.deck.grid
        surface = self.deck.surface
        extent = max(float(np.ptp(grid.s)), float(np.ptp(grid.r)))
        tol = 1e-9 * extent
        if surface is None:
            tri = (np.zeros((0, 2)), np.zeros((0, 3), dtype=np.int64), np.zeros(2), 1.0,
                   np.zeros(2, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
        else:
            tri = (surface.points, surface.triangles, surface.lo, float(surface.size), surface.shape,
                   surface.start, surface.items)
        arrays = SurfaceArrays(grid.origin, grid.axis, grid.s, grid.r, grid.w, grid.w_s, grid.w_s_minus, grid.w_r,
                               grid.w_sr, grid.w_sr_minus, surface is None, tol, NODE_SNAP * float(np.ptp(grid.s)),
                               *tri)
        empty = np.zeros((0, 14, 4))
        return DeckArrays(np.zeros(0), empty, empty, 0.0, self.length, np.zeros(0, dtype=np.int64), 7, -math.inf,
                          math.inf, SURFACE_DECK, arrays)

    def sensor_row(self, sensor: Sensor) -> Array:
        """The (m,) modal row of a sensor (:meth:`ModalDeck.sensor_row`; (x, y) in the bridge frame).

        Raises:
            ConfigError: naming the sensor: off the deck, or a quantity the modes cannot give.
        """
        if sensor.z is not None and sensor.quantity in ("displacement", "velocity", "acceleration"):
            raise ConfigError(f"sensor {sensor.name}: a deck given by its modes has no section: give the sensor's "
                              "deck point (x, y) without z")
        if sensor.quantity in ("displacement", "velocity", "acceleration") and not self.covers(sensor.x,
                                                                                               sensor.y)[0]:
            raise ConfigError(f"sensor {sensor.name}: ({sensor.x:g}, {sensor.y:g}) m is not on the deck's surface "
                              f"(0 <= x <= {self.length:g} m, {self.source or 'its modes'}); move it onto the deck")
        return self.deck.sensor_row(sensor)

    def deck_w_row(self, x: float, y: float) -> Array:
        """Each mode's vertical displacement at the bridge-frame point (x, y) (zero off the deck), (m,)."""
        if not self.covers(x, y)[0]:
            return np.zeros(self.n_modes)
        return self.deck.rows(x, y)[0, 0]
