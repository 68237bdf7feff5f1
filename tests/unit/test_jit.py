"""The compiled core's disk cache is keyed on the whole core (cosim.core.jit): numba's private names it needs."""
from __future__ import annotations

import numba.core.caching as caching

from cosim.core import jit, kernels


def test_the_core_cache_locator_is_installed_first_in_numbas_locators():
    # cosim.core.jit reaches into numba's private CacheImpl._locator_classes (no public API keys a cache on more
    # than one file). If numba renames or restructures it, the core's cache would silently go stale after an edit
    # of an inlined module: this test fails first.
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    locators = getattr(impl, "_locator_classes")  # noqa: B009 - the private name is the point
    assert isinstance(locators, list) and locators[0].__name__ == "CoreTreeLocator"
    assert issubclass(locators[0], caching.InTreeCacheLocator)
    # And it keys a core function's cache on every core file: its stamp is the core's.
    located = locators[0].from_function(kernels.band_solve.py_func, kernels.__file__)
    assert located is not None and located.get_source_stamp() == jit._core_stamp()


def _fresh_function():
    """A function numba has never compiled (a new one at each call, no disk cache)."""
    import numba

    def twice(x):
        return 2.0 * x

    return numba.njit(cache=False)(twice)


def test_on_compile_calls_back_when_numba_compiles_and_not_once_stopped():
    names: list[str] = []
    stop = jit.on_compile(names.append)
    try:
        f = _fresh_function()
        assert f(1.5) == 3.0
        assert "_fresh_function.<locals>.twice" in names  # compiled here: its name reported
        before = len(names)
        assert f(2.5) == 5.0  # already compiled for a float: nothing compiled, nothing reported
        assert len(names) == before
    finally:
        stop()
    _fresh_function()(1.0)
    assert len(names) == before  # stopped: a later compilation is not reported


def test_a_cached_kernel_loads_without_a_compile_notice():
    # The notice of a first run must not show at every run: a kernel in numba's disk cache is loaded, not compiled.
    # Warmed in a process of its own (numba's in-memory copy would hide the disk cache's), then loaded in another.
    import subprocess
    import sys

    code = ("from cosim.core import jit, kernels; import numpy as np; names = []; stop = jit.on_compile(names.append);"
            "u = np.ones((3, 2)); b = np.ones(3); kernels.band_solve(u, b); print(len(names))")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)  # fills the cache
    again = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert again.stdout.strip() == "0"
