"""numba for the numerical core: every compiled function of ``cosim.core`` is made with :func:`compiled`.

Compiled functions are cached on disk (a ``cosim run`` would otherwise spend
seconds compiling at every start). numba invalidates a cached function only
when *its own* source file changes, but the block loop inlines functions of
other core modules (the vehicle models): after editing one of those, a stale
loop would run. So the cache of a core function is keyed on the whole
``cosim/core`` folder (names, sizes and modification times of its files).
"""
from __future__ import annotations

import functools
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba import njit

CORE = Path(__file__).resolve().parent


@functools.cache  # once per process: numba asks for it per compiled function (49 folder walks, 0.2 s a start)
def _core_stamp() -> tuple[tuple[str, int, int], ...]:
    files = sorted(CORE.rglob("*.py"))
    return tuple((str(p.relative_to(CORE)), p.stat().st_mtime_ns, p.stat().st_size) for p in files)


def _install_core_locator() -> None:
    """Register a numba cache locator whose source stamp covers every file of the core.

    The one place cosim reaches into numba's private names (``CacheImpl._locator_classes``; the class was
    ``_CacheImpl`` before numba 0.61): numba has no public way to key a cache on more than the function's own
    file; tests/unit/test_jit.py fails if they move.
    """
    import numba.core.caching as caching
    from numba.core.caching import InTreeCacheLocator

    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)  # numba >= 0.61 | older
    if impl is None:  # another numba layout: the per-file stamps still apply (tests/unit/test_jit.py fails)
        return

    class CoreTreeLocator(InTreeCacheLocator):
        def get_source_stamp(self) -> Any:
            return _core_stamp()

        @classmethod
        def from_function(cls, py_func: Any, py_file: str) -> Any:
            if not os.path.abspath(py_file).startswith(str(CORE) + os.sep):
                return None
            return super().from_function(py_func, py_file)

    locators = getattr(impl, "_locator_classes", None)
    if isinstance(locators, list) and not any(c.__name__ == "CoreTreeLocator" for c in locators):
        locators.insert(0, CoreTreeLocator)


_install_core_locator()


def compiled(func: Callable[..., Any] | None = None, *, nogil: bool = False, inline: bool = False) -> Any:
    """``numba.njit(cache=True)`` (``nogil`` releases the GIL: for the block loops a log thread overlaps).

    ``inline``: inlined into its callers (numba's ``inline="always"``), for the block loop's per-step
    operations, which take records of many arrays: a call would pass and reference-count every one of them.
    """
    decorate = njit(cache=True, nogil=nogil, inline="always" if inline else "never")
    return decorate(func) if func is not None else decorate


def on_compile(callback: Callable[[str], None]) -> Callable[[], None]:
    """Call ``callback(name)`` each time numba starts compiling a function in this process (a compiled function
    loaded from its cache is not compiled: no call). Returns the function that stops it.

    For a notice while a first run after installing cosim compiles its kernels (about a minute, silent otherwise).
    Uses numba's event API (``numba:compile``).
    """
    from numba.core import event

    class _CompileListener(event.Listener):
        def on_start(self, ev: Any) -> None:
            dispatcher = ev.data.get("dispatcher")
            callback(getattr(getattr(dispatcher, "py_func", None), "__qualname__", "?"))

        def on_end(self, ev: Any) -> None:
            pass

    listener = _CompileListener()
    event.register("numba:compile", listener)
    return lambda: event.unregister("numba:compile", listener)
