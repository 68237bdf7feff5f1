"""The contact interpolation of a deck given by its modes: a bicubic Hermite grid (docs/theory.md §13).

The coupled step needs, at a contact point of the deck and for every mode, the
deck's vertical displacement ``w`` and its first and second derivatives along
the direction of travel (docs/theory.md §5.1-5.2). A deck given by its modes
knows ``w`` at its points only, so cosim interpolates it on a structured grid
of lines ``s_i`` (along the deck) and ``r_k`` (across), in a local frame of the
deck's own (:class:`DeckGrid`): each grid cell holds the bicubic Hermite patch of
``w``, ``w_s``, ``w_r`` and ``w_sr`` at its four corners.

- Along ``s``: the slopes given by the source model (a beam's, a frame's nodal
  rotations), one-sided where the slope jumps (a Timoshenko beam's shear strain
  jumps between elements), else the slopes of the not-a-knot cubic spline
  through the values of each line (C2, exact for cubics).
- Across ``r``: the not-a-knot cubic spline through the lines (C2), whose
  slopes ``D w`` give ``w_r`` and ``w_sr`` (``D`` is the spline's derivative matrix).

This is the tensor product of the two 1-D interpolations, so it is exact for
any field that is cubic per cell along ``s`` with the given slopes and cubic
across: a beam's modes imported by :func:`cosim.bridges.from_beam` (cubic
per element, linear across: ``w = w_S + (y - y_S) theta_x``) are reproduced to
round-off. Points that are not a tensor grid (an unstructured shell mesh) are
fitted once by a least-squares bicubic spline, whose knot cells are the grid.

The evaluation (:func:`grid_rows`, :func:`contact_rows`) is compiled with numba
and takes plain arrays, so that the coupled step can inline it.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from cosim.errors import ConfigError

from .jit import compiled
from .limits import MAX_MODE_VALUES

__all__ = ["DeckGrid", "GRID_TOLERANCE", "build_grid", "cell_rows", "contact_rows", "grid_rows", "local_coordinates",
           "tensor_grid"]

#: Points within this share of the deck's extent of a grid line lie on it (a structured grid from a file
#: written with 6-7 significant digits is still one).
GRID_TOLERANCE = 1e-5

Array = npt.NDArray[np.float64]


class DeckGrid(NamedTuple):
    """A deck's modes on a structured grid: what the compiled contact rows read (docs/theory.md §13).

    The grid's frame: ``s = (p - origin) . axis`` along the deck, ``r = (p - origin) . normal`` across it, with
    ``normal = (-axis[1], axis[0])`` (to the left of ``axis``), for a point ``p`` in the deck's frame (the
    bridge frame: ``origin = (0, 0)``, ``axis = (1, 0)``, so ``s = x`` and ``r = y``). Mode values per grid
    node, mode index last (contiguous per node):

    Attributes:
        origin, axis: (2,) the grid frame in the deck's frame, m and a unit vector.
        s, r: (ns,), (nr,) the grid lines, ascending, m.
        w: (ns, nr, m) the vertical displacement of each mode at each node.
        w_s, w_s_minus: dw/ds at each node, the limit from +s and from -s (the same array where the slope
            is continuous); a cell [s_i, s_i+1] uses ``w_s`` at s_i and ``w_s_minus`` at s_i+1.
        w_r: dw/dr (the spline across the lines).
        w_sr, w_sr_minus: d2w/(ds dr), from +s and from -s.
    """

    origin: Array
    axis: Array
    s: Array
    r: Array
    w: Array
    w_s: Array
    w_s_minus: Array
    w_r: Array
    w_sr: Array
    w_sr_minus: Array

    @property
    def n_modes(self) -> int:
        return int(self.w.shape[2])

    @property
    def nbytes(self) -> int:
        """Memory the grid's arrays hold, bytes (a shared slope array counted once)."""
        seen: dict[int, int] = {}
        for a in self:
            seen[id(a)] = a.nbytes
        return sum(seen.values())


# --------------------------------------------------------------------------------------------- the frame
def local_coordinates(x: npt.ArrayLike, y: npt.ArrayLike, origin: Array, axis: Array) -> tuple[Array, Array]:
    """(s, r) of deck-frame points (x, y) in the grid frame ``origin``, ``axis``."""
    dx = np.asarray(x, dtype=float) - origin[0]
    dy = np.asarray(y, dtype=float) - origin[1]
    return dx * axis[0] + dy * axis[1], -dx * axis[1] + dy * axis[0]


def _unit(v: Array) -> Array:
    u = np.asarray(v, dtype=float) / math.hypot(float(v[0]), float(v[1]))
    # one sign for a direction and its opposite (+x first, then +y): the same points give the same frame
    if u[0] < -1e-12 or (abs(u[0]) <= 1e-12 and u[1] < 0):
        u = -u
    return u


def _candidate_axes(points: Array) -> list[Array]:
    """Directions along which a network-frame deck's points may form a grid: the principal axes, and the
    direction from a point to its nearest neighbour and its normal (a square grid has no principal axis)."""
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    major = _unit(vt[0])
    axes = [major, _unit(np.array([-major[1], major[0]]))]
    from scipy.spatial import cKDTree  # here, not at import: a beam's run never loads it (start-up)

    _, idx = cKDTree(points).query(points[0], k=2)
    edge = points[int(idx[1])] - points[0]
    if math.hypot(*edge) > 0:
        near = _unit(edge)
        axes += [near, _unit(np.array([-near[1], near[0]]))]
    return axes


def _cluster(values: Array, tol: float) -> tuple[Array, npt.NDArray[np.int64]]:
    """Sorted cluster means of ``values`` (gaps over ``tol`` separate clusters) and each value's cluster."""
    order = np.argsort(values, kind="stable")
    sorted_v = values[order]
    labels_sorted = np.concatenate([[0], np.cumsum(np.diff(sorted_v) > tol)]).astype(np.int64)
    count = int(labels_sorted[-1]) + 1
    means = np.bincount(labels_sorted, weights=sorted_v, minlength=count) / np.bincount(labels_sorted,
                                                                                        minlength=count)
    labels = np.empty_like(labels_sorted)
    labels[order] = labels_sorted
    return means, labels


def tensor_grid(s: Array, r: Array, tol: float) -> tuple[Array, Array, npt.NDArray[np.int64],
                                                         npt.NDArray[np.int64]] | None:
    """The grid lines (s_knots, r_knots) and each point's (i, j) if the points are exactly the nodes of a
    tensor grid (every line crossing once, within ``tol``), else None."""
    s_knots, i = _cluster(s, tol)
    r_knots, j = _cluster(r, tol)
    n = len(s)
    if len(s_knots) < 2 or len(r_knots) < 2 or len(s_knots) * len(r_knots) != n:
        return None
    if len(np.unique(i * len(r_knots) + j)) != n:
        return None
    return s_knots, r_knots, i, j


# ------------------------------------------------------------------------------------------- building
def _spline_slopes(knots: Array, values: Array) -> Array:
    """d/dknot of the not-a-knot cubic spline through ``values`` (axis 0) at the knots (a line for 2 knots)."""
    from scipy.interpolate import CubicSpline  # here, not at import (start-up)

    return np.ascontiguousarray(CubicSpline(knots, values, axis=0, bc_type="not-a-knot").derivative()(knots))


def _across(r_knots: Array, *arrays: Array) -> list[Array]:
    """The r-slopes (axis 1) of each (ns, nr, m) array: the spline's derivative matrix applied across."""
    d = _spline_slopes(r_knots, np.eye(len(r_knots)))  # (nr, nr): row k = the slopes at r_k of each cardinal
    return [np.ascontiguousarray(np.einsum("kj,sjm->skm", d, a)) for a in arrays]


def _grid(origin: Array, axis: Array, s_knots: Array, r_knots: Array, w: Array, w_s: Array | None,
          w_s_minus: Array | None) -> DeckGrid:
    w = np.ascontiguousarray(w)
    if w_s is None:
        w_s = _spline_slopes(s_knots, w)
    w_s = np.ascontiguousarray(w_s)
    if w_s_minus is None:
        w_r, w_sr = _across(r_knots, w, w_s)
        w_s_minus, w_sr_minus = w_s, w_sr
    else:
        w_s_minus = np.ascontiguousarray(w_s_minus)
        w_r, w_sr, w_sr_minus = _across(r_knots, w, w_s, w_s_minus)
    return DeckGrid(np.asarray(origin, dtype=float), np.asarray(axis, dtype=float), np.asarray(s_knots, float),
                    np.asarray(r_knots, float), w, w_s, w_s_minus, w_r, w_sr, w_sr_minus)


def build_grid(points: Array, frame: str, phi: Array, phi_x: Array | None = None,
               phi_x_minus: Array | None = None, where: str = "") -> tuple[DeckGrid, str, bool]:
    """The interpolation grid of a deck's modes, a sentence that says how it was made, and whether the points
    are its nodes (a structured grid) rather than fitted by it.

    Args:
        points: (n, 2) the deck points in the deck's frame, m.
        frame: "bridge" (the grid's axes are the bridge's x and y) or "network" (the grid's axis is found
            from the points: the direction along which they form a grid, else their principal axis).
        phi: (m, n) each mode's vertical displacement at each point.
        phi_x, phi_x_minus: (m, n) or None: dphi/dx (bridge frame only), from +x and from -x.
        where: the start of error messages (the file).

    Raises:
        ConfigError: the points do not span a surface; the grid would exceed ``COSIM_MAX_MODE_VALUES``.
    """
    n = len(points)
    extent = float(np.max(np.ptp(points, axis=0))) if n else 0.0
    tol = GRID_TOLERANCE * extent
    if frame == "bridge":
        axes = [np.array([1.0, 0.0])]
        origin = np.zeros(2)
    else:
        axes = _candidate_axes(points)
        origin = points.mean(axis=0)
    found = None
    for axis in axes:
        s, r = local_coordinates(points[:, 0], points[:, 1], origin, axis)
        grid = tensor_grid(s, r, tol)
        if grid is not None and (found is None or np.ptp(grid[0]) > np.ptp(found[1][0]) * (1 + 1e-9)):
            found = (axis, grid)
    m = phi.shape[0]
    if found is not None:
        axis, (s_knots, r_knots, i, j) = found
        ns, nr = len(s_knots), len(r_knots)
        MAX_MODE_VALUES.check(ns * nr * m, f"{where}phi", f"{ns} x {nr} grid nodes x {m} modes")

        def on_grid(values: Array) -> Array:
            out = np.empty((ns, nr, m))
            out[i, j, :] = values.T
            return out

        slopes = None if phi_x is None else on_grid(phi_x)
        behind = None if phi_x_minus is None else on_grid(phi_x_minus)
        how = "the given slopes" if phi_x is not None else "the cubic spline of each line"
        note = (f"a structured grid of {ns} x {nr} points: cubic Hermite along the deck with {how}, "
                f"cubic spline across")
        return _grid(origin, axis, s_knots, r_knots, on_grid(phi), slopes, behind), note, True
    fitted, note = _fitted(points, frame, axes[0], origin, phi, phi_x is not None, where)
    return fitted, note, False


#: Knots of the least-squares spline of scattered points every this many point spacings (docs/theory.md §13.4).
KNOTS_PER_SPACING = 2.0
#: Weight of the spline's curvature penalty, relative to the mean diagonal of the data's normal equations.
SMOOTHING = 1e-6


def _difference(count: int) -> sp.csr_matrix:
    """Second differences of ``count`` coefficients ((count - 2) x count; empty below 3)."""
    if count < 3:
        return sp.csr_matrix((0, count))
    return sp.diags([1.0, -2.0, 1.0], [0, 1, 2], shape=(count - 2, count), format="csr")


def _row_products(a: sp.csr_matrix, b: sp.csr_matrix) -> sp.csr_matrix:
    """The row-wise Kronecker product: row p is kron(a[p], b[p]) (column i * b.shape[1] + j)."""
    a_coo = a.tocoo()
    b = b.tocsr()
    repeat = np.diff(b.indptr)[a_coo.row]
    rows = np.repeat(a_coo.row, repeat)
    offset = np.arange(len(rows)) - np.repeat(np.cumsum(repeat) - repeat, repeat)
    entry = np.repeat(b.indptr[a_coo.row], repeat) + offset
    cols = np.repeat(a_coo.col, repeat) * b.shape[1] + b.indices[entry]
    vals = np.repeat(a_coo.data, repeat) * b.data[entry]
    return sp.csr_matrix((vals, (rows, cols)), shape=(a.shape[0], a.shape[1] * b.shape[1]))


def _fitted(points: Array, frame: str, axis: Array, origin: Array, phi: Array, had_slopes: bool,
            where: str) -> tuple[DeckGrid, str]:
    """Scattered points: the least-squares bicubic spline of their values, with knots every
    :data:`KNOTS_PER_SPACING` point spacings and a light curvature penalty (it fills the knot cells the
    points leave empty, beyond their hull, smoothly), written at its knots (docs/theory.md §13.4)."""
    # Here, not at import: a beam's run never loads them (0.3 s of every start).
    import scipy.sparse.linalg as spla
    from scipy.interpolate import BSpline
    from scipy.spatial import cKDTree

    s, r = local_coordinates(points[:, 0], points[:, 1], origin, axis)
    local = np.column_stack([s, r])
    distance, _ = cKDTree(local).query(local, k=2)
    spacing = float(np.median(distance[:, 1]))
    length, width = float(np.ptp(s)), float(np.ptp(r))
    if not (spacing > 0 and length > 0 and width > 0):
        raise ConfigError(f"{where}points: the deck points lie on a line; a deck is a surface (give points "
                          "across its width too)")
    n, m = len(points), phi.shape[0]

    def cells(h: float) -> tuple[int, int]:
        return max(1, int(math.ceil(length / h - 1e-9))), max(1, int(math.ceil(width / h - 1e-9)))

    knot = KNOTS_PER_SPACING * spacing
    cs, cr = cells(knot)
    while (cs + 3) * (cr + 3) > n and (cs > 1 or cr > 1):  # fewer coefficients than points (the penalty
        # regularises a deck of fewer than 16 points)
        knot *= 1.25
        cs, cr = cells(knot)
    MAX_MODE_VALUES.check((cs + 1) * (cr + 1) * m, f"{where}phi",
                          f"a fitted grid of {cs + 1} x {cr + 1} nodes x {m} modes")
    s_knots = np.linspace(s.min(), s.max(), cs + 1)
    r_knots = np.linspace(r.min(), r.max(), cr + 1)
    ts = np.concatenate([[s_knots[0]] * 3, s_knots, [s_knots[-1]] * 3])
    tr = np.concatenate([[r_knots[0]] * 3, r_knots, [r_knots[-1]] * 3])
    bs = BSpline.design_matrix(np.clip(s, s_knots[0], s_knots[-1]), ts, 3).tocsr()  # (n, ks)
    br = BSpline.design_matrix(np.clip(r, r_knots[0], r_knots[-1]), tr, 3).tocsr()  # (n, kr)
    ks, kr = bs.shape[1], br.shape[1]
    design = _row_products(bs, br)  # (n, ks kr): each point's tensor B-splines
    normal = (design.T @ design).tocsc()
    penalty = (sp.kron(_difference(ks).T @ _difference(ks), sp.identity(kr))
               + sp.kron(sp.identity(ks), _difference(kr).T @ _difference(kr)))
    weight = SMOOTHING * float(normal.diagonal().mean())
    try:
        coefficients = spla.splu((normal + weight * penalty).tocsc()).solve(np.asarray(design.T @ phi.T))
    except RuntimeError as exc:
        raise ConfigError(f"{where}points: the deck points do not determine a surface ({exc})") from None
    c = coefficients.reshape(ks, kr, m)

    def at_knots(nu_s: int, nu_r: int) -> Array:
        along = BSpline(ts, c, 3, axis=0)(s_knots, nu=nu_s)  # (ns, kr, m)
        return np.ascontiguousarray(BSpline(tr, along, 3, axis=1)(r_knots, nu=nu_r))

    w, w_s, w_r, w_sr = at_knots(0, 0), at_knots(1, 0), at_knots(0, 1), at_knots(1, 1)
    note = (f"{n} scattered points fitted by a least-squares bicubic spline with knots every {knot:.3g} m "
            f"({cs + 1} x {cr + 1}){' (their slopes are not used)' if had_slopes else ''}")
    if frame == "network":
        note += f", along ({axis[0]:.6g}, {axis[1]:.6g})"
    grid = DeckGrid(np.asarray(origin, dtype=float), np.asarray(axis, dtype=float), s_knots, r_knots, w, w_s, w_s,
                    w_r, w_sr, w_sr)
    return grid, note


# -------------------------------------------------------------------------------------- the compiled rows
@compiled(inline=True)
def _cell(knots: np.ndarray, v: float) -> int:
    """The grid cell [knots[e], knots[e + 1]] that holds v (the first or last cell beyond the ends)."""
    e = int(np.searchsorted(knots, v, side="right")) - 1
    return min(max(e, 0), len(knots) - 2)


@compiled(inline=True)
def _hermite(t: float, h: float, out: np.ndarray) -> None:
    """The cubic Hermite basis of a cell of length h at t in [0, 1] and its first and second derivatives with
    respect to the coordinate: out[d] = (H0, h G0, H1, h G1) differentiated d times (values and slopes at
    the cell's two ends)."""
    t2 = t * t
    t3 = t2 * t
    out[0, 0] = 1.0 - 3.0 * t2 + 2.0 * t3
    out[0, 1] = h * (t - 2.0 * t2 + t3)
    out[0, 2] = 3.0 * t2 - 2.0 * t3
    out[0, 3] = h * (t3 - t2)
    out[1, 0] = 6.0 * (t2 - t) / h
    out[1, 1] = 1.0 - 4.0 * t + 3.0 * t2
    out[1, 2] = 6.0 * (t - t2) / h
    out[1, 3] = 3.0 * t2 - 2.0 * t
    out[2, 0] = (12.0 * t - 6.0) / (h * h)
    out[2, 1] = (6.0 * t - 4.0) / h
    out[2, 2] = (6.0 - 12.0 * t) / (h * h)
    out[2, 3] = (6.0 * t - 2.0) / h


@compiled(inline=True)
def cell_rows(sk: np.ndarray, rk: np.ndarray, w: np.ndarray, w_s: np.ndarray, w_s_minus: np.ndarray,
              w_r: np.ndarray, w_sr: np.ndarray, w_sr_minus: np.ndarray, e: int, k: int, s: float, r: float,
              ts: float, tr: float, cs: float, cr: float, bs: np.ndarray, br: np.ndarray, coef: np.ndarray,
              out: np.ndarray) -> None:
    """One contact point's rows from the patch of cell (e, k): out[0, j] = w, out[1, j] = dw/dt and
    out[2, j] = t^T H t + c . grad w of mode j at grid coordinates (s, r), for the direction of travel
    (ts, tr) and the path's curvature vector (cs, cr) = kappa n (zero on a straight path), both in the grid
    frame (docs/theory.md §13.2). ``bs``, ``br`` (3, 4) and ``coef`` (3, 4, 4) are work arrays; ``out`` is
    (3, m)."""
    hs = sk[e + 1] - sk[e]
    hr = rk[k + 1] - rk[k]
    xi = min(max((s - sk[e]) / hs, 0.0), 1.0)
    eta = min(max((r - rk[k]) / hr, 0.0), 1.0)
    _hermite(xi, hs, bs)
    _hermite(eta, hr, br)
    for a_ in range(4):
        for b_ in range(4):
            coef[0, a_, b_] = bs[0, a_] * br[0, b_]
            coef[1, a_, b_] = ts * bs[1, a_] * br[0, b_] + tr * bs[0, a_] * br[1, b_]
            coef[2, a_, b_] = (ts * ts * bs[2, a_] * br[0, b_] + 2.0 * ts * tr * bs[1, a_] * br[1, b_]
                               + tr * tr * bs[0, a_] * br[2, b_] + cs * bs[1, a_] * br[0, b_]
                               + cr * bs[0, a_] * br[1, b_])
    m = w.shape[2]
    for o in range(3):
        for mode in range(m):
            out[o, mode] = 0.0
    for a in range(2):
        i = e + a
        slope = w_s if a == 0 else w_s_minus
        twist = w_sr if a == 0 else w_sr_minus
        for b in range(2):
            j = k + b
            for o in range(3):
                c_w = coef[o, 2 * a, 2 * b]
                c_s = coef[o, 2 * a + 1, 2 * b]
                c_r = coef[o, 2 * a, 2 * b + 1]
                c_sr = coef[o, 2 * a + 1, 2 * b + 1]
                for mode in range(m):
                    out[o, mode] += (c_w * w[i, j, mode] + c_s * slope[i, j, mode] + c_r * w_r[i, j, mode]
                                     + c_sr * twist[i, j, mode])


@compiled(inline=True)
def contact_rows(sk: np.ndarray, rk: np.ndarray, w: np.ndarray, w_s: np.ndarray, w_s_minus: np.ndarray,
                 w_r: np.ndarray, w_sr: np.ndarray, w_sr_minus: np.ndarray, s: float, r: float, ts: float,
                 tr: float, bs: np.ndarray, br: np.ndarray, coef: np.ndarray, out: np.ndarray) -> None:
    """One contact point's rows on a straight path (:func:`cell_rows`, in the cell that holds (s, r)): w, dw/dt
    and t^T H t of each mode for the unit direction of travel (ts, tr) in the grid frame.

    The point must lie on the grid (the caller checks the deck's surface); beyond its ends the end cells extend.
    """
    cell_rows(sk, rk, w, w_s, w_s_minus, w_r, w_sr, w_sr_minus, _cell(sk, s), _cell(rk, r), s, r, ts, tr, 0.0, 0.0,
              bs, br, coef, out)


@compiled
def _grid_rows(sk: np.ndarray, rk: np.ndarray, w: np.ndarray, w_s: np.ndarray, w_s_minus: np.ndarray,
               w_r: np.ndarray, w_sr: np.ndarray, w_sr_minus: np.ndarray, s: np.ndarray, r: np.ndarray,
               ts: np.ndarray, tr: np.ndarray, on: np.ndarray, out: np.ndarray) -> None:
    bs = np.empty((3, 4))
    br = np.empty((3, 4))
    coef = np.empty((3, 4, 4))
    for p in range(len(s)):
        if on[p]:
            contact_rows(sk, rk, w, w_s, w_s_minus, w_r, w_sr, w_sr_minus, s[p], r[p], ts[p], tr[p], bs, br,
                         coef, out[p])
        else:
            out[p, :, :] = 0.0


def grid_rows(grid: DeckGrid, x: Array, y: Array, tx: Array, ty: Array, on: npt.NDArray[np.bool_]) -> Array:
    """Rows (q, 3, m) of q deck-frame points (x, y) for the unit directions (tx, ty) in the deck's frame:
    ``w``, ``dw/dt`` and ``t^T H t`` per mode; zero where ``on`` is False (off the deck's surface)."""
    s, r = local_coordinates(x, y, grid.origin, grid.axis)
    ts, tr = local_coordinates(tx, ty, np.zeros(2), grid.axis)
    out = np.empty((len(s), 3, grid.n_modes))
    _grid_rows(grid.s, grid.r, grid.w, grid.w_s, grid.w_s_minus, grid.w_r, grid.w_sr, grid.w_sr_minus,
               np.ascontiguousarray(s), np.ascontiguousarray(r), np.ascontiguousarray(ts),
               np.ascontiguousarray(tr), np.ascontiguousarray(on, dtype=np.bool_), out)
    return out
