"""Where a sweep's cases run: in the driver, in a local process pool, or on a Dask cluster.

Every executor calls :func:`run_case` where the case runs and hands each record to ``emit`` in
the driver as its case finishes; only the driver writes files. A worker process that dies is a
record too (``WorkerCrash`` locally, ``KilledWorker`` on Dask), so one bad case never stops the
others.

An interruption (Ctrl-C, SIGTERM: a :class:`KeyboardInterrupt`) is never a record: it passes
through :func:`run_case`; the executors then emit the cases already finished, cancel the others
and stop the local workers at once (they ignore Ctrl-C themselves, so that the driver decides),
and re-raise it.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import time
import traceback
import uuid
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.io import to_jsonable
from cardan_exudyn.sweep.plan import Case
from cardan_exudyn.sweep.records import ERROR, RESERVED_OUTPUTS, error_record
from cardan_exudyn.sweep.spec import DEFAULT_FUNCTION, CaseFunction, SweepError, flatten_paths
from reference.scene import Scene, replace
from reference.schema import Status

__all__ = ["SweepIncomplete", "SweepInterrupted", "Emit", "default_workers", "run_case", "run_in_process",
           "run_pool", "ignore_interrupts", "connect", "run_dask"]

Emit = Callable[[dict[str, Any]], None]
"""The driver's callback receiving each record as its case finishes."""


class SweepIncomplete(RuntimeError):
    """The sweep stopped before every case had a record (e.g. the Dask cluster went away)."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C or SIGTERM stopped the sweep: every case finished before is recorded, no case was
    recorded as failed for it, and the same command resumes.

    Attributes: ``done`` and ``total`` cases, ``out`` folder, ``signum`` (the signal)."""

    def __init__(self, done: int, total: int, out: os.PathLike | str, signum: int = signal.SIGINT) -> None:
        super().__init__(f"{done} of {total} cases done (records in {out}); rerun the same command "
                         "to resume")
        self.done, self.total, self.out, self.signum = done, total, out, signum


def default_workers() -> int:
    """Cores available to this process."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def run_case(case: Case, base: Scene, function: CaseFunction | str = DEFAULT_FUNCTION) -> dict[str, Any]:
    """Run one case and return its record; an exception becomes a record with status ``error``.

    Runs where the case is executed (the driver, a pool process or a Dask worker); nothing is
    written here.

    Parameters
    ----------
    case : Case
        Id, engine and overrides of the base scene.
    base : Scene
        The sweep's base scene.
    function : CaseFunction or str
        The case function (a name alone: no arguments).

    Returns
    -------
    dict
        The record: :data:`cardan_exudyn.sweep.records.RECORD_KEYS`, the function's outputs and,
        after an exception, its ``traceback``.
    """
    function = CaseFunction(function) if isinstance(function, str) else function
    start = time.perf_counter()
    record: dict[str, Any] = case.to_dict()
    try:
        scene = replace(base, **case.overrides) if case.overrides else base
        outputs = _outputs(function, function(scene, case.engine))
        status, reason = str(outputs.pop("status", Status.OK)), str(outputs.pop("reason", "") or "")
        error_type = error = tb = None
    except Exception as exc:  # the worker's boundary: any failure of the case becomes its record
        outputs, status = {}, ERROR
        error_type, error = type(exc).__name__, str(exc)
        reason = f"{error_type}: {error}"
        tb = "".join(traceback.format_exception(exc)[-12:])
    record.update(status=status, reason=reason, error_type=error_type, error=error,
                  case_wall_s=time.perf_counter() - start, **outputs)
    if tb is not None:
        record["traceback"] = tb
    return record


def _outputs(function: CaseFunction, outputs: Any) -> dict[str, Any]:
    """A case function's return value checked and flattened into JSON-able record fields."""
    if not isinstance(outputs, Mapping):
        raise TypeError(f"case function {function.name} returned {type(outputs).__name__}, not a dict")
    clash = sorted(RESERVED_OUTPUTS & set(outputs))
    if clash:
        raise ValueError(f"case function {function.name} returned reserved key(s) {clash}")
    return to_jsonable(flatten_paths(outputs))


def run_in_process(cases: Sequence[Case], base: Scene, function: CaseFunction, emit: Emit) -> None:
    """Run the cases one after the other in this process."""
    for case in cases:
        emit(run_case(case, base, function))


def run_pool(cases: Sequence[Case], base: Scene, function: CaseFunction, workers: int,
             emit: Emit) -> None:
    """Run cases in spawned processes, at most ``2 workers`` submitted at a time.

    A worker that dies (crash, ``os._exit``, out of memory) breaks the pool and every case in
    flight; those are rerun one at a time in a fresh process, where a case that kills the
    process is the one running, and is recorded as ``WorkerCrash``.
    """
    # spawn, not fork: a worker inherits nothing from the driver (threads, locks, open files)
    context = multiprocessing.get_context("spawn")
    queue = deque(cases)
    while queue:
        victims = _pool_round(queue, base, function, workers, context, emit)
        _run_one_at_a_time(deque(victims), base, function, context, emit)


def ignore_interrupts() -> None:
    """Pool worker initializer: Ctrl-C reaches the whole process group, and the driver alone
    decides what an interruption stops (it terminates the workers)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _pool(workers: int, context) -> Iterator[ProcessPoolExecutor]:
    """A process pool; on any exception its workers are terminated instead of awaited (a running
    case would otherwise hold the driver until it ends)."""
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=ignore_interrupts)
    try:
        yield pool
    except BaseException:
        # no public way to stop running tasks before Python 3.14's terminate_workers()
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            with contextlib.suppress(OSError, ValueError, AttributeError):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def _emit_finished(running: dict[Any, Case], emit: Emit) -> None:
    """Emit the records of the futures in ``running`` that finished with one (at an interruption:
    cases done meanwhile are kept)."""
    for future in list(running):
        if future.done() and not future.cancelled() and future.exception() is None:
            emit(future.result())
            running.pop(future)


def _pool_round(queue: deque, base: Scene, function: CaseFunction, workers: int, context,
                emit: Emit) -> list[Case]:
    """Run from ``queue`` until it is empty or the pool breaks; returns the cases in flight then."""
    running: dict[Any, Case] = {}
    with _pool(workers, context) as pool:
        try:
            while queue or running:
                while queue and len(running) < 2 * workers:
                    case = queue.popleft()
                    running[pool.submit(run_case, case, base, function)] = case
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                broken = False
                for future in done:
                    if isinstance(future.exception(), BrokenProcessPool):
                        broken = True
                        continue
                    with deferred_signals():  # emitted and crossed off together
                        emit(future.result())
                        running.pop(future)
                if broken:
                    return list(running.values())
        except KeyboardInterrupt:
            _emit_finished(running, emit)
            raise
    return []


def _run_one_at_a_time(queue: deque, base: Scene, function: CaseFunction, context, emit: Emit) -> None:
    while queue:
        with _pool(1, context) as pool:
            while queue:
                case = queue.popleft()
                future = pool.submit(run_case, case, base, function)
                try:
                    record = future.result()
                except BrokenProcessPool:
                    emit(error_record(case, "WorkerCrash", "the worker process died while running "
                                      "this case alone (a crash, os._exit, or killed, e.g. out of memory)"))
                    break
                except KeyboardInterrupt:
                    _emit_finished({future: case}, emit)
                    raise
                emit(record)


def connect(scheduler: Any):
    """A :class:`distributed.Client` for an address (``tcp://host:port``) or the client given.

    Raises
    ------
    SweepError
        ``distributed`` is not installed, or the scheduler does not answer within 10 s.
    """
    try:
        from distributed import Client  # an optional dependency, needed only for a cluster
    except ImportError as exc:
        raise SweepError(f"--scheduler needs the `distributed` package: {exc}") from None
    if isinstance(scheduler, Client):
        return scheduler
    try:
        return Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepError(f"cannot connect to the Dask scheduler at {scheduler!r}: {exc}") from None


def run_dask(cases: Sequence[Case], base: Scene, function: CaseFunction, client, emit: Emit) -> None:
    """Submit every case to the cluster and record them as they complete.

    A case whose worker dies repeatedly (Dask's ``KilledWorker``) is recorded as failed; any
    other failure of the cluster stops the sweep, recording nothing for the cases in flight.

    Raises
    ------
    SweepIncomplete
        The cluster failed other than by killing a worker; the records so far are kept.
    """
    from distributed import KilledWorker, as_completed  # optional, as in connect

    if not cases:
        return
    token = uuid.uuid4().hex[:8]
    base_future = client.scatter(base, broadcast=True)
    futures = client.map(run_case, cases, base=base_future, function=function, pure=False,
                         key=[f"cardan-sweep-{token}-{case.id}" for case in cases])
    case_of = dict(zip(futures, cases, strict=True))
    try:
        for future, result in as_completed(futures, with_results=True, raise_errors=False):
            with deferred_signals():  # emitted and crossed off together
                _emit_dask(future, result, case_of.pop(future), emit, KilledWorker)
    except KeyboardInterrupt:  # keep the cases finished meanwhile
        for future in [f for f in case_of if f.status == "finished"]:
            emit(future.result())
        raise
    finally:
        client.cancel(futures)


def _emit_dask(future, result, case: Case, emit: Emit, killed: type) -> None:
    if future.status == "finished":
        emit(result)
        return
    error = future.exception() if future.status == "error" else future.status
    if not isinstance(error, killed):
        raise SweepIncomplete(f"the Dask cluster failed on case {case.id}: "
                              f"{type(error).__name__}: {error}; rerun to resume")
    emit(error_record(case, "KilledWorker", str(error)))
