"""Root pytest configuration.

BLAS is pinned to one thread before numpy is imported: the test suite (and the
time stepping it drives) does thousands of small dense operations, which a
multi-threaded BLAS slows down by thread start-up and contention.
"""
import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

try:  # pragma: no cover - threadpoolctl is optional
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)
except ImportError:
    pass
