"""Band storage of the bridge's symmetric matrices (a beam's matrices are banded: half-bandwidth ~ 2 x 7 DOFs)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def upper_band(a: sp.spmatrix | sp.sparray) -> np.ndarray:
    """LAPACK upper band storage of a symmetric sparse matrix: ``ab[bw + i - j, j] = A[i, j]`` for i <= j."""
    coo = sp.coo_matrix(a)
    n = coo.shape[0]
    bandwidth = int(np.max(np.abs(coo.col - coo.row))) if coo.nnz else 0
    upper = coo.row <= coo.col
    rows, cols, vals = coo.row[upper], coo.col[upper], coo.data[upper]
    ab = np.zeros((bandwidth + 1, n))
    np.add.at(ab, (bandwidth + rows - cols, cols), vals)
    return ab
