"""A deck given by its modes: points, frequencies, mass-normalised vertical mode shapes (docs/modal-decks.md).

An external finite-element model of any bridge (a shell deck on girders, a
curved or skewed deck, a frame) enters cosim through its modes only: the
vertical displacement of each mode at points of the deck's surface.
:class:`ModalDeck` holds them, checks them (every message starts with the file
it came from and names the array), and answers what the coupled step asks of a
deck at a contact point: each mode's ``w``, ``dw/dt`` and ``t^T H t`` along the
direction of travel ``t`` (:meth:`ModalDeck.rows`, docs/theory.md §13), and
whether a point is on the deck's surface (:meth:`ModalDeck.covers`).

Mass-normalised means ``phi_j^T M phi_k = delta_jk`` over the *whole* model
(every DOF of the source model, with its mass matrix in kg): the deck's points
are a few of those DOFs, so cosim cannot check the normalisation from them. A
file states it with ``modal_mass``, the generalised mass of each shape as
stored, which must then be 1; the importers (:mod:`cosim.bridges`) compute it.

Files and importers are in :mod:`cosim.bridges`; this module takes arrays.
"""
from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.errors import ConfigError

from .checks import one_of
from .deck_grid import DeckGrid, build_grid, grid_rows, local_coordinates
from .deck_surface import TriangleIndex, inside_triangles, triangle_index
from .limits import MAX_DECK_MODES, MAX_DECK_POINTS, MAX_MODE_VALUES
from .sensors import SENSOR_QUANTITIES, Sensor

__all__ = ["DECK_POINT_QUANTITIES", "FRAMES", "MODAL_QUANTITIES", "ModalDeck", "NORMALISATION_TOLERANCE",
           "QUANTITY_KEY"]

#: The frames a deck's points may be given in: the bridge frame (x along the bridge from the first support
#: line, y to the left) or SUMO's network frame.
FRAMES: tuple[str, ...] = ("bridge", "network")
#: Sensor quantities the modes give at any point of the deck's surface (its vertical motion).
DECK_POINT_QUANTITIES: tuple[str, ...] = ("displacement", "velocity", "acceleration")
#: Sensor quantities a deck's modes cannot give without the modal values of that quantity at the sensor.
MODAL_QUANTITIES: tuple[str, ...] = tuple(q for q in SENSOR_QUANTITIES if q not in DECK_POINT_QUANTITIES)
#: The key of a sensor's modal values: ``<quantity>:<sensor name>``.
QUANTITY_KEY = re.compile(r"^([a-z_]+):([A-Za-z0-9_.\-]{1,64})$")
#: ``modal_mass`` may differ from 1 by this much (relative): what the shapes' 6-7 printed digits allow.
NORMALISATION_TOLERANCE = 1e-6
#: Named modal quantities a deck may carry (one per sensor at most).
MAX_QUANTITIES = 10_000

Array = npt.NDArray[np.float64]


def _where(source: str) -> str:
    return f"{source}: " if source else "modal deck: "


def _numbers(value: Any, name: str, shape: tuple[int | None, ...], where: str, what: str) -> Array:
    """``value`` as a float array of ``shape`` (None: any length), every entry finite."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}{name}: expected {what}, numbers (got {type(value).__name__})") from None
    if array.ndim != len(shape) or any(want is not None and got != want for got, want in zip(array.shape, shape)):
        sizes = ", ".join("any" if w is None else str(w) for w in shape)
        want_text = f"({sizes}{',' if len(shape) == 1 else ''})"
        raise ConfigError(f"{where}{name}: expected shape {want_text}: {what} (got {array.shape})")
    bad = np.argwhere(~np.isfinite(array))
    if len(bad):
        at = ", ".join(str(int(i)) for i in bad[0])
        raise ConfigError(f"{where}{name}: {name}[{at}] is {array[tuple(bad[0])]}; every value must be a finite "
                          "number")
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class ModalDeck:
    """A deck given by its modes (docs/modal-decks.md). Every array is checked when it is made; it never
    changes afterwards.

    Attributes:
        points: (n, 2) the deck points, m, in ``frame``: "bridge" (x along the bridge from the first support
            line, y lateral, positive to the left looking along +x) or "network" (SUMO's network x, y).
        f_hz: (m,) natural frequencies, Hz, > 0 and ascending (equal frequencies allowed).
        phi: (m, n) the vertical displacement (z up) of each mass-normalised mode at each point.
        phi_x: (m, n) or None: dphi/dx at each point (bridge frame only): the limit from +x (at the last
            grid line, from -x). From a source model that has slopes (a beam, a frame's nodal rotation
            about the lateral axis: ``phi_x = -theta_y``); else the interpolation finds them.
        phi_x_minus: (m, n) or None: the limit from -x where the slope jumps at the point (a Timoshenko
            beam's shear strain jumps between elements); default ``phi_x``. Needs ``phi_x``.
        zeta: (m,) or None: modal damping ratios in [0, 1); None: the scenario's damping applies.
        modal_mass: (m,) or None: the generalised mass ``phi_j^T M phi_j`` of each shape as stored, kg per
            unit modal coordinate squared: 1 (within 1e-6) for mass-normalised shapes, which the file's
            shapes must be; None: not stated (cosim cannot check it from the deck's points).
        triangles: (k, 3) or None: the deck's surface as triangles of point indices (0-based). Without
            them the surface is the grid's rectangle (points on a structured grid) or the points' convex
            hull (scattered points).
        quantities: ``"<quantity>:<sensor>"`` -> (m,): the modal values of a quantity the shapes cannot give
            (bending_moment N m, stress Pa, strain, shear stresses Pa) at the sensor of that name.
        source: where the deck came from (a file, an importer), first in every message.
    """

    points: Array
    f_hz: Array
    phi: Array
    frame: str = "bridge"
    phi_x: Array | None = None
    phi_x_minus: Array | None = None
    zeta: Array | None = None
    modal_mass: Array | None = None
    triangles: npt.NDArray[np.int64] | None = None
    quantities: Mapping[str, Array] = field(default_factory=dict)
    source: str = ""

    def __post_init__(self) -> None:
        where = _where(self.source)
        set_ = object.__setattr__
        one_of(self.frame, FRAMES, "frame", where)
        points = _numbers(self.points, "points", (None, 2), where, "(n, 2) deck points x, y in m")
        n = len(points)
        MAX_DECK_POINTS.check(n, f"{where}points")
        if n < 3:
            raise ConfigError(f"{where}points: a deck needs at least 3 points across its surface (got {n})")
        _distinct(points, where)
        f_hz = _numbers(self.f_hz, "f_hz", (None,), where, "(m,) natural frequencies in Hz")
        m = len(f_hz)
        MAX_DECK_MODES.check(m, f"{where}f_hz")
        if m < 1:
            raise ConfigError(f"{where}f_hz: a deck needs at least one mode (got none)")
        _frequencies(f_hz, where)
        MAX_MODE_VALUES.check(m * n, f"{where}phi", f"{m} modes x {n} points")
        set_(self, "points", points)
        set_(self, "f_hz", f_hz)
        shape = f"(m, n) = ({m}, {n}): one row per mode of f_hz, one column per point"
        set_(self, "phi", _numbers(self.phi, "phi", (m, n), where, shape))
        for name in ("phi_x", "phi_x_minus"):
            if getattr(self, name) is not None:
                set_(self, name, _numbers(getattr(self, name), name, (m, n), where, shape))
        if self.phi_x_minus is not None and self.phi_x is None:
            raise ConfigError(f"{where}phi_x_minus: the slopes from -x need phi_x, the slopes from +x; give both")
        if self.phi_x is not None and self.frame != "bridge":
            raise ConfigError(f"{where}phi_x: slopes are given along the bridge frame's x; a deck in the network "
                              "frame takes values only (drop phi_x, or give the points in the bridge frame)")
        if self.zeta is not None:
            zeta = _numbers(self.zeta, "zeta", (m,), where, "(m,) modal damping ratios, one per mode")
            bad = np.flatnonzero((zeta < 0) | (zeta >= 1))
            if len(bad):
                raise ConfigError(f"{where}zeta: zeta[{bad[0]}] = {zeta[bad[0]]:g}; a damping ratio is a fraction "
                                  "of critical, 0 <= zeta < 1 (2 % is 0.02)")
            set_(self, "zeta", zeta)
        if self.modal_mass is not None:
            set_(self, "modal_mass", _modal_mass(self.modal_mass, m, where))
        if self.triangles is not None:
            set_(self, "triangles", _triangles(self.triangles, points, where))
        set_(self, "quantities", _quantities(self.quantities, m, where))

    # ------------------------------------------------------------------------------------------- sizes
    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_modes(self) -> int:
        return int(self.f_hz.shape[0])

    @property
    def omega(self) -> Array:
        """Circular frequencies, rad/s."""
        return 2.0 * np.pi * self.f_hz

    # ---------------------------------------------------------------------------------- interpolation
    @cached_property
    def _interpolation(self) -> tuple[DeckGrid, str, bool]:
        return build_grid(self.points, self.frame, self.phi, self.phi_x, self.phi_x_minus, _where(self.source))

    @property
    def grid(self) -> DeckGrid:
        """The interpolation grid the contact rows read (docs/theory.md §13; built on first use)."""
        return self._interpolation[0]

    @property
    def interpolation(self) -> str:
        """How the grid was made, one sentence (a structured grid, or scattered points fitted)."""
        return self._interpolation[1]

    @cached_property
    def surface(self) -> TriangleIndex | None:
        """The deck's triangles, bucketed; None where the surface is the structured grid's rectangle (points on
        a structured grid and no triangles given). Scattered points without triangles: their convex hull."""
        if self.triangles is not None:
            return triangle_index(self.points, self.triangles)
        if self._interpolation[2]:
            return None
        from scipy.spatial import Delaunay, QhullError  # here, not at import: a beam's run never loads it

        try:
            hull = Delaunay(self.points)
        except QhullError:  # build_grid has refused points on a line already
            raise ConfigError(f"{_where(self.source)}points: the deck points cannot be triangulated") from None
        return triangle_index(self.points, hull.simplices.astype(np.int64))

    def covers(self, x: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Whether each point (x, y) of the deck's frame lies on the deck's surface (edges included)."""
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        ys = np.atleast_1d(np.asarray(y, dtype=float))
        if xs.shape != ys.shape or xs.ndim != 1:
            raise ConfigError(f"`x` and `y` must be two numbers or two 1-D arrays of one length (got shapes "
                              f"{xs.shape} and {ys.shape})")
        surface = self.surface
        if surface is not None:
            return inside_triangles(surface, xs, ys)
        grid = self.grid
        s, r = local_coordinates(xs, ys, grid.origin, grid.axis)
        tol = 1e-9 * max(float(np.ptp(grid.s)), float(np.ptp(grid.r)))
        return ((s >= grid.s[0] - tol) & (s <= grid.s[-1] + tol) & (r >= grid.r[0] - tol)
                & (r <= grid.r[-1] + tol))

    def rows(self, x: npt.ArrayLike, y: npt.ArrayLike, direction: npt.ArrayLike | None = None) -> Array:
        """The contact rows of q points: (q, 3, m) with ``w``, ``dw/dt`` and ``t^T H t`` of each mode.

        Args:
            x, y: the points in the deck's frame, m.
            direction: the unit direction of travel ``t`` in the deck's frame, (2,) for every point or (q, 2);
                default (1, 0): along +x (in the bridge frame, ``dw/dx`` and ``d2w/dx2``, what the beam's
                rows give). A path that curves also needs ``kappa (n . grad w)`` in its second derivative
                (its curvature kappa and normal n): that term is the caller's (docs/theory.md §13.2).

        Returns:
            Zero rows for points off the deck's surface (:meth:`covers`): the wheel rides on rigid ground.
        """
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        ys = np.atleast_1d(np.asarray(y, dtype=float))
        on = self.covers(xs, ys)
        t = np.array([1.0, 0.0]) if direction is None else np.asarray(direction, dtype=float)
        t = np.broadcast_to(t, (len(xs), 2)) if t.shape == (2,) else t
        if t.shape != (len(xs), 2) or not np.all(np.isfinite(t)):
            raise ConfigError(f"`direction` must be a unit vector (2,) or one per point (q, 2) (got shape {t.shape})")
        norm = np.hypot(t[:, 0], t[:, 1])
        if np.any(np.abs(norm - 1.0) > 1e-6):
            raise ConfigError("`direction` must be unit vectors (|t| = 1)")
        return grid_rows(self.grid, xs, ys, t[:, 0], t[:, 1], on)

    # ----------------------------------------------------------------------------------------- sensors
    def sensor_row(self, sensor: Sensor) -> Array:
        """The (m,) modal row a sensor reads (apply it to the modal coordinates, their rate or acceleration as
        :data:`cosim.core.sensors.TIME_DERIVATIVE` says); the sensor's (x, y) are in the deck's frame.

        Raises:
            ConfigError: naming the sensor: a deck point off the deck's surface; a quantity the modes cannot
                give (a bending moment, a stress) and the deck has no modal values ``<quantity>:<name>`` for.
        """
        if sensor.quantity in DECK_POINT_QUANTITIES:
            if not self.covers(sensor.x, sensor.y)[0]:
                raise ConfigError(f"sensor {sensor.name}: ({sensor.x:g}, {sensor.y:g}) m is not on the deck's "
                                  f"surface given by {self.source or 'its modes'}; move the sensor onto the deck")
            return self.rows(sensor.x, sensor.y)[0, 0]
        key = f"{sensor.quantity}:{sensor.name}"
        if key in self.quantities:
            return self.quantities[key]
        raise ConfigError(f"sensor {sensor.name}: a deck given by its modes gives its vertical displacement, "
                          f"velocity and acceleration only, not a {sensor.quantity}: give the modal values "
                          f"`{key}` (one per mode) in {self.source or 'the modes file'} (docs/modal-decks.md)")

    # ------------------------------------------------------------------------------------- truncation
    def select(self, n_modes: int | None = None, cutoff_hz: float | None = None) -> ModalDeck:
        """The deck with its first ``n_modes`` modes and/or those at or below ``cutoff_hz`` (the modal
        truncation of a run); the same deck if neither is given."""
        keep = self.n_modes
        if n_modes is not None:
            if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
                raise ConfigError(f"`n_modes` must be an integer >= 1 (got {n_modes!r})")
            keep = min(keep, int(n_modes))
        if cutoff_hz is not None:
            keep = min(keep, int(np.searchsorted(self.f_hz, float(cutoff_hz), side="right")))
            if keep < 1:
                raise ConfigError(f"no mode of {self.source or 'the deck'} at or below `cutoff_hz` = {cutoff_hz} Hz "
                                  f"(the first is {self.f_hz[0]:.4g} Hz)")
        if keep == self.n_modes:
            return self

        def cut(a: Array | None) -> Array | None:
            return None if a is None else a[:keep]

        return replace(self, f_hz=self.f_hz[:keep], phi=self.phi[:keep], phi_x=cut(self.phi_x),
                       phi_x_minus=cut(self.phi_x_minus), zeta=cut(self.zeta), modal_mass=cut(self.modal_mass),
                       quantities={k: v[:keep] for k, v in self.quantities.items()})


# --------------------------------------------------------------------------------------------- checks
def _distinct(points: Array, where: str) -> None:
    order = np.lexsort((points[:, 1], points[:, 0]))
    same = np.flatnonzero(np.all(np.diff(points[order], axis=0) == 0, axis=1))
    if len(same):
        a, b = sorted((int(order[same[0]]), int(order[same[0] + 1])))
        raise ConfigError(f"{where}points: points {a} and {b} coincide at ({points[a, 0]:g}, {points[a, 1]:g}) m; "
                          "give each deck point once")


def _frequencies(f_hz: Array, where: str) -> None:
    bad = np.flatnonzero(f_hz <= 0)
    if len(bad):
        raise ConfigError(f"{where}f_hz: f_hz[{bad[0]}] = {f_hz[bad[0]]:g} Hz; natural frequencies must be > 0 "
                          "(a rigid-body mode means the model's supports leave it free to move)")
    down = np.flatnonzero(np.diff(f_hz) < 0)
    if len(down):
        j = int(down[0]) + 1
        raise ConfigError(f"{where}f_hz: f_hz[{j}] = {f_hz[j]:g} Hz is below f_hz[{j - 1}] = {f_hz[j - 1]:g} Hz; "
                          "the modes must ascend in frequency (sort them, and phi's rows with them)")


def _modal_mass(value: Any, m: int, where: str) -> Array:
    mass = _numbers(value, "modal_mass", (m,), where, "(m,) the generalised mass of each shape, one per mode")
    off = np.flatnonzero(~(np.abs(mass - 1.0) <= NORMALISATION_TOLERANCE))
    if len(off):
        j = int(off[0])
        fix = f"divide mode {j + 1}'s phi (and phi_x) by sqrt({mass[j]:.6g})" if mass[j] > 0 else "re-export it"
        raise ConfigError(f"{where}modal_mass: mode {j + 1}'s shape is not mass-normalised: modal_mass[{j}] = "
                          f"{mass[j]:.6g}, expected 1 within {NORMALISATION_TOLERANCE:g}; export mass-normalised "
                          f"shapes (Abaqus: *FREQUENCY, NORMALIZATION=MASS) or {fix}")
    return mass


def _triangles(value: Any, points: Array, where: str) -> npt.NDArray[np.int64]:
    array = np.asarray(value)
    if array.dtype.kind not in "iu" or array.ndim != 2 or array.shape[1] != 3:
        raise ConfigError(f"{where}triangles: expected (k, 3) integer point indices, 0-based (got "
                          f"{array.dtype} {array.shape})")
    n = len(points)
    MAX_DECK_POINTS.check(len(array) / 4, f"{where}triangles", f"{len(array):,} triangles / 4")
    if len(array) == 0:
        raise ConfigError(f"{where}triangles: no triangles; give the deck's surface or leave triangles out")
    bad = np.argwhere((array < 0) | (array >= n))
    if len(bad):
        k, col = (int(i) for i in bad[0])
        raise ConfigError(f"{where}triangles: triangles[{k}, {col}] = {array[k, col]} is not a point index; "
                          f"indices are 0-based, 0 ... {n - 1}")
    tri = array.astype(np.int64)
    a, b, c = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
    area = np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / 2
    extent = float(np.max(np.ptp(points, axis=0)))
    flat = np.flatnonzero(~(area > 1e-12 * extent * extent))
    if len(flat):
        k = int(flat[0])
        raise ConfigError(f"{where}triangles: triangle {k} ({', '.join(str(int(i)) for i in tri[k])}) has no area; "
                          "its three points must not lie on a line")
    tri.flags.writeable = False
    return tri


def _quantities(value: Mapping[str, Any], m: int, where: str) -> dict[str, Array]:
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}quantities: expected a mapping '<quantity>:<sensor>' -> (m,) modal values")
    if len(value) > MAX_QUANTITIES:
        raise ConfigError(f"{where}quantities: {len(value):,} modal quantities is more than {MAX_QUANTITIES:,}")
    out = {}
    for key, array in value.items():
        match = QUANTITY_KEY.match(key) if isinstance(key, str) else None
        if match is None or match[1] not in MODAL_QUANTITIES:
            raise ConfigError(f"{where}{key}: a modal quantity is named '<quantity>:<sensor>', quantity one of "
                              f"{', '.join(MODAL_QUANTITIES)}, sensor of letters, digits, '_', '.', '-' "
                              f"(e.g. 'bending_moment:mid')")
        out[key] = _numbers(array, key, (m,), where, "(m,) the modal values of the quantity, one per mode")
    return out
