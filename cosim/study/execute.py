"""Running a study: each run in a process of its own (a Dask worker), resuming, and the whole study.

Runs are plain functions (:func:`execute_run`) of a :class:`~cosim.study.spec.RunTask`
that carries every input as text, executed on a Dask cluster: a local one of
worker processes by default (one libsumo simulation per process), or an
existing scheduler. A run whose ``result.json`` matches its inputs and whose
log is complete is not run again (:func:`finished_row`): re-running a study
resumes it. A failing run is recorded in its row; the others go on. Nothing
here prints.
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

from cosim.errors import ConfigError, CosimError, Interrupted, interruption
from cosim.run.logged import run_logged
from cosim.run.scenario import load_scenario
from cosim.run.signals import StopGuard, stop_signals
from cosim.study.characteristic import write_characteristic
from cosim.study.folder import (
    LOG_FILE,
    PLOTS_FOLDER,
    RESULT_FILE,
    RUNS_FOLDER,
    SCENARIO_FILE,
    STOP_FILE,
    STUDY_FILE,
    STUDY_ID_FILE,
    write_file,
)
from cosim.study.logs import log_is_complete
from cosim.study.spec import RunTask, Study, error_text
from cosim.study.table import base_row, jsonable_row, plot_study, run_statistics, table_frame, write_table

__all__ = [
    "Progress",
    "StudyOutcome",
    "check_study_folder",
    "default_workers",
    "execute_run",
    "finished_row",
    "run_study",
    "summary_text",
]

#: How long to wait for a remote scheduler to have a worker, s.
WORKER_WAIT = 60.0
#: How often a run on a worker looks for the study's stop file, s of wall time.
STOP_CHECK_EVERY = 0.5
#: How long a stopped study waits for the runs in progress to finish their logs, s.
STOP_WAIT = 30.0
#: How often the study's main thread looks for finished runs and held signals while runs are on Dask, s.
POLL = 0.05
#: The Dask event topic a worker tells the study's client on when it starts compiling the solver.
COMPILE_TOPIC = "cosim-compiling"

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- one run (on a worker)


_relaying = False


def _once(callback: Callable[[Any], None]) -> Callable[[Any], None]:
    """``callback`` for the first call only (from any thread): a compilation is said once, not per function."""
    lock = threading.Lock()
    done = False

    def first(value: Any) -> None:
        nonlocal done
        with lock:
            if done:
                return
            done = True
        callback(value)

    return first


def relay_compilation() -> None:
    """On a Dask worker: the first time numba compiles in this process, tell the study's client (Dask event
    :data:`COMPILE_TOPIC`). After installing cosim each worker compiles the solver before its first run ends,
    about a minute in which the study's bar shows no run done; later runs load it from numba's cache."""
    global _relaying
    if _relaying:
        return
    from distributed import get_worker

    from cosim.core.jit import on_compile

    worker = get_worker()
    # for the worker process's life: one event at most
    on_compile(_once(lambda name: worker.log_event(COMPILE_TOPIC, {"function": name})))
    _relaying = True


def execute_run_on_worker(task: RunTask) -> dict[str, Any]:
    """:func:`execute_run` on a Dask worker, its compilation of the solver told to the study's client."""
    relay_compilation()
    return execute_run(task)


def execute_run(task: RunTask) -> dict[str, Any]:
    """Run one study run in this process and return its row of results (also stored as ``result.json``).

    Writes the task's files and ``scenario.toml`` into ``task.folder``, runs the
    scenario into ``run.mcap`` (replacing one left by an interrupted attempt),
    then reduces the log to the row. Any failure is recorded in the row
    (``status = "error"``, ``error`` = the message); it never raises, except for
    Ctrl-C.
    """
    started = time.perf_counter()
    folder = Path(task.folder)
    stop = folder.parent.parent / STOP_FILE  # <output>/runs/<run id> -> <output>/.stop
    row = base_row(task)
    if stop.exists():  # the study was stopped before this run began: nothing to do
        row["status"], row["error"] = "interrupted", "the study was stopped before this run began"
        return jsonable_row(row)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / RESULT_FILE).unlink(missing_ok=True)
        if task.error is not None:
            raise ConfigError(task.error)
        for name, content in task.files.items():
            pure = PurePosixPath(name)
            if pure.is_absolute() or ".." in pure.parts:
                raise ConfigError(f"unsafe file name in the run's inputs: {name!r}")
            write_file(folder.joinpath(*pure.parts), content)
        write_file(folder / SCENARIO_FILE, task.scenario_text)
        scenario = load_scenario(folder / SCENARIO_FILE)
        bridge = scenario.build_bridge()
        # a study's runs are reduced to numbers: no 3D scene unless its scenario asks for one
        outcome = run_logged(scenario, folder / LOG_FILE, force=True, bridge=bridge, progress=_StopCheck(stop),
                             scene_by_default=False)
        row.update(run_statistics(scenario, bridge, outcome, task.percentiles, task.vehicles_per_year))
        row["status"] = "ok"
        row["error"] = ""
    except KeyboardInterrupt as exc:
        if not stop.exists():
            raise  # a signal to this process (a study run in-process): the study stops
        # Stopped by the study (on a worker): the log is finished, status "interrupted"; not a result.
        row["status"], row["error"] = "interrupted", f"stopped by {interruption(exc)[1]}"
    except Exception as exc:  # noqa: BLE001 - a failing run is recorded, the study goes on
        row["status"] = "error"
        row["error"] = error_text(exc)
        if not isinstance(exc, CosimError):
            log.debug("run %s failed:\n%s", task.run_id, traceback.format_exc())
    row["wall_time_total"] = time.perf_counter() - started
    row["log"] = f"{RUNS_FOLDER}/{task.run_id}/{LOG_FILE}"
    row = jsonable_row(row)
    try:
        write_file(folder / RESULT_FILE, json.dumps({"fingerprint": task.fingerprint, "row": row}, indent=1))
    except OSError as exc:
        row["status"] = "error"
        row["error"] = error_text(exc)
    return row


class _StopCheck:
    """A run's progress callback that stops it (with a finished log) once the study's stop file appears.

    A run on a Dask worker cannot be reached by the signal that stops the
    study; the file in the shared output folder can. Checked at most every
    :data:`STOP_CHECK_EVERY` seconds of wall time.
    """

    def __init__(self, stop: Path) -> None:
        self.stop = stop
        self._next = time.monotonic() + STOP_CHECK_EVERY

    def __call__(self, fraction: float) -> None:
        now = time.monotonic()
        if now < self._next:
            return
        self._next = now + STOP_CHECK_EVERY
        if self.stop.exists():
            try:
                name = self.stop.read_text(encoding="utf-8").strip()[:20] or "SIGTERM"
            except OSError:
                name = "SIGTERM"
            signum = signal.Signals[name] if name in signal.Signals.__members__ else signal.SIGTERM
            raise Interrupted(int(signum), f"{name} to the study")


def finished_row(task: RunTask) -> dict[str, Any] | None:
    """The stored row of a run that need not run again: status ok, same inputs, complete log; else None."""
    folder = Path(task.folder)
    try:
        stored = json.loads((folder / RESULT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(stored, dict) or stored.get("fingerprint") != task.fingerprint:
        return None
    row = stored.get("row")
    if not isinstance(row, dict) or row.get("status") != "ok":
        return None
    if not log_is_complete(folder / LOG_FILE):
        return None
    return row


# --------------------------------------------------------------------------- the whole study


@dataclass
class StudyOutcome:
    """What :func:`run_study` did.

    Attributes:
        study: the study.
        rows: one row per run, in sweep order.
        ran: run ids executed now; skipped: run ids whose stored results were reused.
        failed: run ids whose status is "error".
        table_csv, table_parquet: the results table.
        plots: the PNG files written.
        wall_time: s, the whole study (cluster start-up included).
        workers: how many workers ran the runs (0: in this process).
        characteristic: ``characteristic.csv`` when the study asks for ``[extremes]``.
    """

    study: Study
    rows: list[dict[str, Any]]
    ran: list[str]
    skipped: list[str]
    failed: list[str]
    table_csv: Path
    table_parquet: Path
    plots: list[Path]
    wall_time: float
    workers: int
    characteristic: Path | None = None

    def table(self):  # noqa: ANN201 - pandas is imported lazily
        """The results as a pandas DataFrame (the rows of ``results.csv``)."""
        return table_frame(self.rows)


Progress = Callable[[int, int, "dict[str, Any] | None"], None]


def summary_text(outcome: StudyOutcome) -> str:
    """What a study did, for the command line to print: runs, workers, files, failures."""
    study = outcome.study
    rows = outcome.rows
    axes = ", ".join(f"{a} ({len(v)})" for a, v in study.axes.items()) or "none (the base scenario once)"
    if outcome.ran:
        where = f"on {outcome.workers} worker{'s' if outcome.workers != 1 else ''}" if outcome.workers \
            else "in this process"
        done = f"{len(outcome.ran)} run now {where}, {len(outcome.skipped)} reused from earlier"
    else:
        done = "all reused from earlier (nothing to run; --redo runs them again)"
    lines = [
        f"Study: {study.name} ({study.source}), base {study.base.source}",
        f"Axes: {axes}",
        f"Runs: {len(rows)}: {done}, {len(outcome.failed)} failed",
        f"Wall time: {outcome.wall_time:.3g} s",
        f"Table: {outcome.table_csv} and {outcome.table_parquet.name} ({len(rows)} rows)",
    ]
    if outcome.characteristic is not None:
        lines.append(f"Characteristic values: {outcome.characteristic}")
    if outcome.plots:
        lines.append(f"Plots: {len(outcome.plots)} PNG in {outcome.plots[0].parent}")
    if outcome.failed:
        lines.append("Failed runs (their logs and scenarios are in runs/<run id>/):")
        for row in rows:
            if row.get("status") != "ok":
                first = (row.get("error") or "unknown error").strip().splitlines()[0]
                lines.append(f"  {row['run_id']}: {first}")
    return "\n".join(lines)


def default_workers() -> int:
    """Worker processes of a local cluster by default: the CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def run_study(
    study: Study,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
    redo: bool = False,
    plots: bool | None = None,
    compiling: Callable[[], None] | None = None,
) -> StudyOutcome:
    """Run every run of ``study`` that has no up-to-date result, then write the table and plots.

    Args:
        study: from :func:`load_study`.
        workers: size of the local Dask cluster (default: one per CPU, at most one per
            run); 0 runs one after another in this process, without Dask.
        scheduler: address of an existing Dask scheduler (``tcp://host:8786``) instead
            of a local cluster; its workers need cosim installed and the output folder
            at the same path.
        progress: called with (runs done, runs in total, the row just finished or None)
            at the start and after every run.
        redo: run every run again, even those with up-to-date results.
        plots: write the plots (default: ``study.plots``).
        compiling: called once, from any thread, when a run starts compiling the solver rather than loading it
            from numba's cache (after installing or upgrading cosim: about a minute before the first runs end).

    Returns:
        The rows, what ran and what was reused, and the files written.

    Raises:
        KeyboardInterrupt: Ctrl-C, or SIGTERM/SIGHUP while runs are in progress (then an
            :class:`Interrupted` naming the signal); the table of the runs finished so far is written first.
        CosimError: the output folder cannot be written, or the scheduler cannot be reached.
    """
    started = time.perf_counter()
    output = study.output
    check_study_folder(study)
    try:
        output.mkdir(parents=True, exist_ok=True)
        write_file(output / STUDY_FILE, study.text)
        write_file(output / STUDY_ID_FILE, json.dumps({"name": study.name, "source": _source(study)}, indent=1))
        (output / STOP_FILE).unlink(missing_ok=True)  # left by a study killed while it was stopping
    except OSError as exc:
        raise CosimError(f"{output}: cannot write the study's output folder ({exc.strerror or exc})") from None
    tasks = study.tasks()
    rows: dict[str, dict[str, Any]] = {}
    todo: list[RunTask] = []
    for task in tasks:
        stored = None if redo else finished_row(task)
        if stored is not None:
            rows[task.run_id] = stored
        else:
            todo.append(task)
    skipped = [t.run_id for t in tasks if t.run_id in rows]
    total = len(tasks)
    if progress is not None:
        progress(len(rows), total, None)

    def finished(row: dict[str, Any]) -> None:
        rows[row["run_id"]] = row
        if progress is not None:
            progress(len(rows), total, row)

    used = 0
    try:
        if todo:
            if workers == 0 and scheduler is None:
                stop = _told_once(compiling)
                try:
                    for task in todo:
                        finished(execute_run(task))
                finally:
                    stop()
            else:
                used = _run_on_dask(study, todo, workers, scheduler, finished, compiling)
    except KeyboardInterrupt:
        # The table of the runs completed so far (ok or failed); runs that finished on a worker but
        # whose result had not come back yet count too; runs stopped half-way do not.
        for task in todo:
            if task.run_id not in rows and (stored := finished_row(task)) is not None:
                rows[task.run_id] = stored
        completed = [rows[t.run_id] for t in tasks
                     if t.run_id in rows and rows[t.run_id].get("status") in ("ok", "error")]
        write_table(completed, output)
        raise
    ordered = [rows[t.run_id] for t in tasks]
    csv_path, parquet_path = write_table(ordered, output)
    draw = study.plots if plots is None else plots
    pngs = plot_study(ordered, study, output / PLOTS_FOLDER) if draw else []
    characteristic, level_plots = write_characteristic(ordered, study, output, plots=draw)
    pngs += level_plots
    return StudyOutcome(
        study=study, rows=ordered, ran=[t.run_id for t in todo], skipped=skipped,
        failed=[r["run_id"] for r in ordered if r.get("status") != "ok"],
        table_csv=csv_path, table_parquet=parquet_path, plots=pngs,
        wall_time=time.perf_counter() - started, workers=used, characteristic=characteristic,
    )


def _told_once(compiling: Callable[[], None] | None) -> Callable[[], None]:
    """``compiling`` called at the first compilation in this process; returns the function that stops it."""
    if compiling is None:
        return lambda: None
    from cosim.core.jit import on_compile

    return on_compile(_once(lambda name: compiling()))


def listen_for_compilation(client: Any, compiling: Callable[[], None] | None) -> None:
    """``compiling`` called (in the client's event thread) at the first :data:`COMPILE_TOPIC` event from the
    workers (:func:`relay_compilation`), once however many workers compile."""
    if compiling is None:
        return
    client.subscribe_topic(COMPILE_TOPIC, _once(lambda event: compiling()))


def _run_on_dask(study: Study, todo: list[RunTask], workers: int | None, scheduler: str | None,
                 finished: Callable[[dict[str, Any]], None], compiling: Callable[[], None] | None = None) -> int:
    """Submit the runs to a Dask cluster and hand every row to ``finished`` as it arrives; returns the workers."""
    from dask.distributed import Client, LocalCluster, as_completed

    # Signals are held and polled, never raised inside a Dask call: a KeyboardInterrupt within
    # distributed's sync() makes its event loop log a NameError traceback (distributed 2026.8). Only
    # connecting to a remote scheduler (up to 80 s) stays interruptible at once.
    cluster = None
    futures: list[Any] = []
    with stop_signals(hold=scheduler is None) as guard:
        try:
            if scheduler is not None:
                try:
                    client = Client(scheduler, timeout="20s")
                except (OSError, TimeoutError) as exc:
                    raise CosimError(f"--scheduler {scheduler}: cannot connect to the Dask scheduler ({exc})") \
                        from None
                try:
                    client.wait_for_workers(1, timeout=WORKER_WAIT)
                except TimeoutError:
                    client.close()
                    raise CosimError(f"--scheduler {scheduler}: the scheduler has no workers (waited "
                                     f"{WORKER_WAIT:g} s; start some with: dask worker ADDRESS --nthreads 1)") from None
                guard.closing = True  # connected: hold signals from here on
            else:
                n = min(workers or default_workers(), len(todo))
                # The scheduler always serves HTTP (None means its default, 8787: taken by a second study
                # or a notebook's cluster, it prints a warning); a free port, on this machine only.
                with _terminal_signals_ignored():  # the worker processes start with these ignored
                    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR)
                client = Client(cluster)
        except BaseException:
            if cluster is not None:
                cluster.close()
            raise
        try:
            if guard.held is not None:  # a signal while the cluster started: nothing submitted yet
                raise guard.held
            n_workers = len(client.scheduler_info(n_workers=-1).get("workers", {})) if scheduler else \
                len(cluster.workers)  # type: ignore[union-attr]
            listen_for_compilation(client, compiling)
            by_key: dict[str, RunTask] = {}
            for task in todo:
                key = f"cosim-run-{study.name}-{task.run_id}-{task.fingerprint[:12]}"
                future = client.submit(execute_run_on_worker, task, key=key, pure=False, retries=0)
                by_key[str(future.key)] = task
                futures.append(future)
            pending = as_completed(futures)
            while not pending.is_empty():
                if guard.held is not None:
                    _stop_runs(client, futures, study.output / STOP_FILE, guard, finished)
                    raise guard.held
                batch = pending.next_batch(block=False)
                if not batch:
                    time.sleep(POLL)
                for future in batch:
                    task = by_key[future.key]
                    try:
                        row = future.result()
                    except Exception as exc:  # noqa: BLE001 - e.g. the worker died (KilledWorker)
                        row = _lost_row(task, exc)
                    finished(row)
        except Interrupted:
            raise
        except BaseException:
            client.cancel(futures)
            raise
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return n_workers


def _stop_runs(client: Any, futures: list[Any], stop: Path, guard: StopGuard,
               finished: Callable[[dict[str, Any]], None]) -> None:
    """Stop a study on Dask: runs not yet begun are cancelled, runs in progress stop with finished logs.

    The stop file tells the runs on the workers (which the signal does not
    reach) to stop at their next block; they come back within a second or two
    with status "interrupted" (not a result: the same command runs them again).
    Runs that completed meanwhile are handed to ``finished``. A second signal
    while waiting stops the waiting.
    """
    # Which runs are in progress, asked before the stop file exists: a run that sees the file can end before
    # the scheduler answers, and it would then be neither waited for nor kept (its row lost).
    try:
        assigned = {key for keys in client.processing().values() for key in keys}
    except Exception:  # noqa: BLE001 - the scheduler is gone: nothing to wait for
        assigned = set()
    try:
        stop.write_text(guard.held.name if guard.held else "SIGTERM", encoding="utf-8")
    except OSError:
        client.cancel(futures)
        return
    try:
        client.cancel([f for f in futures if str(f.key) not in assigned and not f.done()])
        running = [f for f in futures if str(f.key) in assigned]
        deadline = time.monotonic() + STOP_WAIT
        while guard.received < 2 and time.monotonic() < deadline and not all(f.done() for f in running):
            time.sleep(POLL)
        for future in running:
            if future.done() and future.status == "finished":
                row = future.result()
                if row.get("status") in ("ok", "error"):
                    finished(row)
    finally:
        with contextlib.suppress(OSError):
            stop.unlink()


@contextlib.contextmanager
def _terminal_signals_ignored() -> Iterator[None]:
    """SIGINT and SIGHUP ignored while worker processes start, so that they inherit it.

    Ctrl-C (or a closed terminal) signals every process of the terminal's
    group: the workers would die with tracebacks. The study's own process
    handles the signal and stops the runs on them (:func:`_stop_runs`).
    Only in the main thread; a signal in these few seconds is lost.
    """
    names = [n for n in ("SIGINT", "SIGHUP") if hasattr(signal, n)]
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {name: signal.signal(getattr(signal, name), signal.SIG_IGN) for name in names}
    try:
        yield
    finally:
        for name, handler in old.items():
            signal.signal(getattr(signal, name), handler)


def check_study_folder(study: Study) -> None:
    """Refuse an output folder that holds another study: its ``study.toml`` and table would be replaced.

    The folder's ``study.json`` names its study; a folder from before it was
    written is judged by ``[study].name`` in its ``study.toml``, if given.

    Raises:
        CosimError: the folder belongs to a study of another name, or is not a folder.
    """
    output = study.output
    if output.exists() and not output.is_dir():
        raise CosimError(f"{output}: is a file, expected the study's output folder")
    owner: str | None = None
    try:
        owner = json.loads((output / STUDY_ID_FILE).read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        try:
            with open(output / STUDY_FILE, "rb") as handle:
                owner = tomllib.load(handle).get("study", {}).get("name")
        except (OSError, ValueError, AttributeError):
            owner = None
    if isinstance(owner, str) and owner != study.name:
        raise CosimError(f"{output}: holds the results of study {owner!r}, not {study.name!r}; refusing to replace "
                         "its study.toml and table: give another --out (a study's folder holds one study)")


def _source(study: Study) -> str:
    path = Path(study.source)
    return str(path.resolve()) if path.is_file() else study.source


def _lost_row(task: RunTask, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose worker failed without returning one (recorded by the caller)."""
    row = base_row(task)
    row["error"] = f"the Dask worker failed: {error_text(exc)}"
    row["log"] = f"{RUNS_FOLDER}/{task.run_id}/{LOG_FILE}"
    row = jsonable_row(row)
    try:
        write_file(Path(task.folder) / RESULT_FILE, json.dumps({"fingerprint": task.fingerprint, "row": row}, indent=1))
    except OSError:
        pass
    return row

