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
