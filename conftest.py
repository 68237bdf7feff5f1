"""Root pytest configuration: BLAS pinned to one thread for the whole suite.

The suite (and the time stepping it drives) does thousands of small dense
operations, which a multi-threaded BLAS slows down by thread start-up and
contention. The environment variables cover BLAS libraries loaded after this
file; threadpoolctl (in the test extra) also limits those already loaded,
e.g. by numpy imported through cosim's pytest plugin, which pytest loads
before any conftest.
"""
import os
import tempfile

# Solved sections go to a folder of this session's, not the user's cache (cosim.core.section_cache): a test that
# counts solves starts from an empty cache.
os.environ.setdefault("COSIM_CACHE_DIR", tempfile.mkdtemp(prefix="cosim-test-cache-"))

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

try:
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)
except ImportError:  # an install without the test extra: the variables above still apply to later loads
    pass
