"""Where a deck given by its modes has a surface: its triangles, found in O(1) per point (docs/theory.md §13.5).

A wheel loads the deck where the deck is: inside one of the deck's triangles (a
modes file's ``triangles``, or the triangles of its points' Delaunay
triangulation), or, for a structured grid given without triangles, inside the
grid's rectangle. :class:`TriangleIndex` puts the triangles into the buckets of
a uniform grid over their bounding box (about one triangle per bucket), so a
point is tested against the few triangles of its bucket only.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from .jit import compiled

__all__ = ["BARYCENTRIC_TOLERANCE", "TriangleIndex", "inside_triangles", "point_in_triangles", "triangle_index"]

#: A point whose barycentric coordinates are all >= -this lies in the triangle (its edges included).
BARYCENTRIC_TOLERANCE = 1e-9
#: Bucket entries per triangle at most (a mesh of slivers across the whole deck gets coarser buckets).
MAX_ENTRIES_PER_TRIANGLE = 64


class TriangleIndex(NamedTuple):
    """Triangles and the uniform buckets that list the triangles overlapping each.

    Attributes:
        points: (n, 2) the vertices, m; triangles: (k, 3) their indices.
        lo: (2,) the buckets' lower corner; size: the bucket's side, m; shape: (2,) buckets along x and y.
        start: (buckets + 1,) where each bucket's list starts in ``items``; items: triangle indices.
    """

    points: npt.NDArray[np.float64]
    triangles: npt.NDArray[np.int64]
    lo: npt.NDArray[np.float64]
    size: float
    shape: npt.NDArray[np.int64]
    start: npt.NDArray[np.int64]
    items: npt.NDArray[np.int64]


def triangle_index(points: npt.NDArray[np.float64], triangles: npt.NDArray[np.int64]) -> TriangleIndex:
    """Bucket the triangles (about one per bucket; built once per deck)."""
    points = np.ascontiguousarray(points, dtype=float)
    triangles = np.ascontiguousarray(triangles, dtype=np.int64)
    corners = points[triangles]  # (k, 3, 2)
    t_lo, t_hi = corners.min(axis=1), corners.max(axis=1)
    lo, hi = t_lo.min(axis=0), t_hi.max(axis=0)
    k = len(triangles)
    width, height = max(float(hi[0] - lo[0]), 1e-12), max(float(hi[1] - lo[1]), 1e-12)
    size = max(math.sqrt(width * height / k), 1e-9 * max(width, height))
    while True:
        shape = np.array([int(width // size) + 1, int(height // size) + 1], dtype=np.int64)
        first = np.minimum(((t_lo - lo) // size).astype(np.int64), shape - 1)
        last = np.minimum(((t_hi - lo) // size).astype(np.int64), shape - 1)
        entries = int(np.sum((last[:, 0] - first[:, 0] + 1) * (last[:, 1] - first[:, 1] + 1)))
        if entries <= MAX_ENTRIES_PER_TRIANGLE * k:
            break
        size *= 2.0
    start, items = _fill(first, last, shape, entries)
    return TriangleIndex(points, triangles, lo.astype(float), float(size), shape, start, items)


@compiled
def _fill(first: np.ndarray, last: np.ndarray, shape: np.ndarray, entries: int) -> tuple[np.ndarray, np.ndarray]:
    n_buckets = shape[0] * shape[1]
    count = np.zeros(n_buckets + 1, dtype=np.int64)
    for t in range(first.shape[0]):
        for bx in range(first[t, 0], last[t, 0] + 1):
            for by in range(first[t, 1], last[t, 1] + 1):
                count[bx * shape[1] + by + 1] += 1
    start = np.cumsum(count)
    fill = start[:-1].copy()
    items = np.empty(entries, dtype=np.int64)
    for t in range(first.shape[0]):
        for bx in range(first[t, 0], last[t, 0] + 1):
            for by in range(first[t, 1], last[t, 1] + 1):
                b = bx * shape[1] + by
                items[fill[b]] = t
                fill[b] += 1
    return start, items


@compiled(inline=True)
def _in_triangle(points: np.ndarray, tri: np.ndarray, px: float, py: float) -> bool:
    ax, ay = points[tri[0], 0], points[tri[0], 1]
    bx, by = points[tri[1], 0], points[tri[1], 1]
    cx, cy = points[tri[2], 0], points[tri[2], 1]
    area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    if area == 0.0:
        return False
    la = ((bx - px) * (cy - py) - (by - py) * (cx - px)) / area
    lb = ((cx - px) * (ay - py) - (cy - py) * (ax - px)) / area
    lc = 1.0 - la - lb
    tol = -BARYCENTRIC_TOLERANCE
    return la >= tol and lb >= tol and lc >= tol


@compiled(inline=True)
def point_in_triangles(points: np.ndarray, triangles: np.ndarray, lo: np.ndarray, size: float, shape: np.ndarray,
                       start: np.ndarray, items: np.ndarray, x: float, y: float) -> bool:
    """Whether (x, y) lies in one of a :class:`TriangleIndex`'s triangles (its arrays, in its order): the
    compiled test of one point, for the coupled step to inline."""
    # a point on a bucket's edge may sit in a triangle listed in the next bucket only: look in the buckets
    # within the barycentric tolerance's reach too (the point's bucket, and its neighbours if that close)
    reach = 1e-9 * size
    fx = (x - lo[0]) / size
    fy = (y - lo[1]) / size
    if not (fx >= -reach and fy >= -reach and fx <= shape[0] + reach and fy <= shape[1] + reach):
        return False
    bx0 = min(max(int(math.floor(fx - reach)), 0), shape[0] - 1)
    bx1 = min(max(int(math.floor(fx + reach)), 0), shape[0] - 1)
    by0 = min(max(int(math.floor(fy - reach)), 0), shape[1] - 1)
    by1 = min(max(int(math.floor(fy + reach)), 0), shape[1] - 1)
    for bx in range(bx0, bx1 + 1):
        for by in range(by0, by1 + 1):
            b = bx * shape[1] + by
            for q in range(start[b], start[b + 1]):
                if _in_triangle(points, triangles[items[q]], x, y):
                    return True
    return False


@compiled
def _inside(points: np.ndarray, triangles: np.ndarray, lo: np.ndarray, size: float, shape: np.ndarray,
            start: np.ndarray, items: np.ndarray, x: np.ndarray, y: np.ndarray, out: np.ndarray) -> None:
    for p in range(len(x)):
        out[p] = point_in_triangles(points, triangles, lo, size, shape, start, items, x[p], y[p])


def inside_triangles(index: TriangleIndex, x: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.bool_]:
    """Whether each point (x, y) lies in one of the triangles (edges included)."""
    xs = np.ascontiguousarray(np.atleast_1d(np.asarray(x, dtype=float)))
    ys = np.ascontiguousarray(np.atleast_1d(np.asarray(y, dtype=float)))
    out = np.empty(len(xs), dtype=np.bool_)
    _inside(index.points, index.triangles, index.lo, index.size, index.shape, index.start, index.items, xs, ys,
            out)
    return out
