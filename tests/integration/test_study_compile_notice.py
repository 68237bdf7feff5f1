"""A study after installing cosim: each Dask worker compiles the solver (about a minute) while the study's bar
shows no run done, so the study says so, once; a worker that loads the solver from numba's cache says nothing.
Real Dask worker processes, real numba compilations (new functions) and a real cached kernel."""
from __future__ import annotations

import logging
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

from cosim.study import execute


@pytest.fixture()
def client() -> Iterator[Any]:
    # a cluster per test: a worker process relays its first compilation only, once in its life
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as c:
        yield c


def _wait_for(calls: list[str], seconds: float = 20.0) -> None:
    deadline = time.monotonic() + seconds
    while not calls and time.monotonic() < deadline:
        time.sleep(0.05)


def test_a_worker_compiling_the_solver_is_told_to_the_study_once(client: Any) -> None:
    calls: list[str] = []
    execute.listen_for_compilation(client, lambda: calls.append("compiling"))

    def compile_two() -> bool:  # on the worker, as execute_run_on_worker starts a run
        import numba

        execute.relay_compilation()
        numba.njit(cache=False)(lambda x: x + 1)(1.0)
        numba.njit(cache=False)(lambda x: x + 2)(1.0)  # a second compilation: no second notice
        return True

    assert client.submit(compile_two, pure=False).result()
    _wait_for(calls)
    time.sleep(0.3)
    assert calls == ["compiling"]
    assert len(client.get_events(execute.COMPILE_TOPIC)) == 1  # the worker told once, not once per function


def test_a_worker_loading_the_solver_from_the_cache_tells_nothing(client: Any) -> None:
    def solve(relay: bool) -> float:
        from cosim.core.small_solve import solve_small

        if relay:
            execute.relay_compilation()
        b = np.array([1.0, 2.0])
        solve_small(np.array([[2.0, 0.0], [0.0, 4.0]]), b)
        return float(b[0] + b[1])

    # a first worker process puts it in numba's cache (compiled or loaded: the worker's copy of cosim, which is
    # the installed one, not necessarily the tests'), then a new worker process asks for it
    assert client.submit(solve, False, pure=False).result() == pytest.approx(1.0)  # diag(2, 4) x = (1, 2)
    client.restart()
    calls: list[str] = []
    execute.listen_for_compilation(client, lambda: calls.append("compiling"))
    assert client.submit(solve, True, pure=False).result() == pytest.approx(1.0)
    time.sleep(0.5)
    # the scheduler has every event sent before the run's result came back (one ordered stream per worker)
    assert not client.get_events(execute.COMPILE_TOPIC)
    assert calls == []


def test_a_study_run_in_this_process_tells_its_first_compilation_once() -> None:
    # workers = 0: the runs go one after another in the study's process, watched the same way
    import numba

    calls: list[str] = []
    stop = execute._told_once(lambda: calls.append("compiling"))
    try:
        numba.njit(cache=False)(lambda x: x + 3)(1.0)
        numba.njit(cache=False)(lambda x: x + 4)(1.0)
    finally:
        stop()
    numba.njit(cache=False)(lambda x: x + 5)(1.0)  # stopped: nothing
    assert calls == ["compiling"]
