"""A small dense linear solve for compiled code: Gaussian elimination with partial pivoting, in place.

Hand-written rather than numba's ``np.linalg.solve``: for the few unknowns solved here (a capacitance
matrix, a vehicle's DOFs) LAPACK's call allocated and cost more than the elimination, and compiling numba's
wrapper of it took about 8 s of a first run's compilation (numba's compile events, a cold cache).
"""
from __future__ import annotations

from .jit import compiled


@compiled(inline=True)
def solve_small(S, b):  # noqa: ANN001, ANN201
    """b <- S^{-1} b for a small matrix S (q x q), by Gaussian elimination with partial pivoting in place (S is
    overwritten). For the capacitance matrix of the few vehicles on a deck LAPACK's solve cost about 2 us a
    step more (benchmarks/bench_step.py)."""
    q = b.shape[0]
    for c in range(q):
        pivot = c
        for r in range(c + 1, q):
            if abs(S[r, c]) > abs(S[pivot, c]):
                pivot = r
        if pivot != c:
            for k in range(c, q):
                S[c, k], S[pivot, k] = S[pivot, k], S[c, k]
            b[c], b[pivot] = b[pivot], b[c]
        inv = 1.0 / S[c, c]
        for r in range(c + 1, q):
            f = S[r, c] * inv
            if f != 0.0:
                for k in range(c + 1, q):
                    S[r, k] -= f * S[c, k]
                b[r] -= f * b[c]
    for r in range(q - 1, -1, -1):
        acc = b[r]
        for k in range(r + 1, q):
            acc -= S[r, k] * b[k]
        b[r] = acc / S[r, r]
