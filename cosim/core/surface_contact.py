"""Contact rows on a deck given by its modes (docs/theory.md §13): where a wheel is on the deck's surface and
each mode's w, dw/dt and d2w/dt2 factors along its path, from the bicubic Hermite grid of
:mod:`cosim.core.deck_grid`. The compiled step (:mod:`cosim.core.kernels`) calls :func:`surface_rows` at its
deck seam for a :data:`SURFACE_DECK`.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from .deck_grid import cell_rows
from .deck_surface import point_in_triangles
from .jit import compiled
from .traffic import on_deck

#: The kind of a deck given by its modes (:data:`cosim.core.kernels.BEAM_DECK` is the beam line).
SURFACE_DECK = 1

#: A deck given by its modes (docs/theory.md §13): the interpolation grid (:class:`cosim.core.deck_grid.DeckGrid`'s
#: arrays: its frame ``origin`` and ``axis``, lines ``s`` and ``r``, the values and slopes per node and mode) and
#: where the deck's surface is: the grid's rectangle (``rect``, within ``tol`` m) or the bucketed triangles of a
#: :class:`cosim.core.deck_surface.TriangleIndex` (``t_*``); ``snap``: a contact point this close (m) to a grid
#: line is on it (round-off of x).
SurfaceArrays = namedtuple("SurfaceArrays", [
    "origin", "axis", "s", "r", "w", "w_s", "w_s_minus", "w_r", "w_sr", "w_sr_minus", "rect", "tol", "snap",
    "t_points", "t_tris", "t_lo", "t_size", "t_shape", "t_start", "t_items",
])
_E1, _E2, _E3 = np.zeros(0), np.zeros((0, 2)), np.zeros((0, 0, 0))
_EI1, _EI2 = np.zeros(0, dtype=np.int64), np.zeros((0, 3), dtype=np.int64)
#: The surface arrays of a beam deck (none).
NO_SURFACE = SurfaceArrays(np.zeros(2), np.array([1.0, 0.0]), _E1, _E1, _E3, _E3, _E3, _E3, _E3, _E3, True, 0.0,
                           0.0, _E2, _EI2, np.zeros(2), 1.0, np.zeros(2, dtype=np.int64), _EI1, _EI1)

_on_deck = compiled(on_deck)


@compiled(inline=True)
def surface_rows(kin, step, deck, elems, rv, bs, br, coef):  # noqa: ANN001, ANN201
    """The contact rows of a deck given by its modes, in modal coordinates: ``rv[i]`` (3, m) = each mode's w,
    dw/dt and t^T H t + kappa n . grad w along the wheel's path (docs/theory.md §13.2); ``elems[i]`` = 0 on
    the deck's surface, -1 off it (beyond its ends, or beside it: rigid ground).

    A contact point on a grid line where the slope jumps takes the cell ahead of it in its direction of
    travel, as the beam's rows take the element ahead (mirrored crossings see mirrored rows).
    """
    # The surface's arrays taken out of their named tuple once: a function that takes a named tuple costs a
    # reference count on every array in it at each call, and a call per contact point was most of a step's time.
    sf = deck.surface
    sk, rk, rect, tol, snap, origin = sf.s, sf.r, sf.rect, sf.tol, sf.snap, sf.origin
    w, w_s, w_s_minus, w_r, w_sr, w_sr_minus = sf.w, sf.w_s, sf.w_s_minus, sf.w_r, sf.w_sr, sf.w_sr_minus
    t_points, t_tris, t_lo, t_size, t_shape, t_start, t_items = sf.t_points, sf.t_tris, sf.t_lo, sf.t_size, \
        sf.t_shape, sf.t_start, sf.t_items
    kx, kv, ky, path, length = kin.x, kin.v, kin.y, kin.path, deck.length
    a0, a1 = sf.axis[0], sf.axis[1]
    ns = sk.shape[0]
    with_path = path.shape[0] > 0
    for i in range(elems.shape[0]):
        x = kx[step, i]
        if with_path:
            y = path[step, i, 0]
            tx, ty, cx, cy = path[step, i, 1], path[step, i, 2], path[step, i, 3], path[step, i, 4]
        else:
            y, tx, ty, cx, cy = ky[i], 1.0, 0.0, 0.0, 0.0
        dx, dy = x - origin[0], y - origin[1]
        s = dx * a0 + dy * a1
        r = -dx * a1 + dy * a0
        # On the deck's surface: the grid's rectangle (within tol), or one of its triangles.
        if rect:
            on = sk[0] - tol <= s <= sk[-1] + tol and rk[0] - tol <= r <= rk[-1] + tol
        else:
            on = point_in_triangles(t_points, t_tris, t_lo, t_size, t_shape, t_start, t_items, x, y)
        if not (_on_deck(x, length) and on):
            elems[i] = -1
            for o in range(3):
                for j in range(rv.shape[2]):
                    rv[i, o, j] = 0.0
            continue
        elems[i] = 0
        ts, tr = tx * a0 + ty * a1, -tx * a1 + ty * a0
        cs, cr = cx * a0 + cy * a1, -cx * a1 + cy * a0
        e = np.searchsorted(sk, s, side="right") - 1
        e = min(max(e, 0), ns - 2)
        forward = ts * kv[step, i]
        if forward < 0.0 and e > 0 and s - sk[e] <= snap:
            e -= 1  # on the line starting cell e, moving towards -s: the cell ahead is e - 1
        elif forward >= 0.0 and e < ns - 2 and sk[e + 1] - s <= snap:
            e += 1
        k = np.searchsorted(rk, r, side="right") - 1
        k = min(max(k, 0), rk.shape[0] - 2)
        cell_rows(sk, rk, w, w_s, w_s_minus, w_r, w_sr, w_sr_minus, e, k, s, r, ts, tr, cs, cr, bs, br, coef, rv[i])
