"""Where a sweep's cases run: in the driver, in a local process pool, or on a Dask cluster.

Each executor hands every finished task's records to ``emit`` in the driver (only the driver
writes). A dead worker is a record (``WorkerCrash``, ``KilledWorker``); a Ctrl-C never is: the
finished tasks are emitted, the rest cancelled, the local workers stopped, and it is re-raised.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import uuid
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.sweep.checks import SweepError
from cardan_exudyn.sweep.functions import CaseFunction
from cardan_exudyn.sweep.records import error_record
from cardan_exudyn.sweep.tasks import Batch, Task, run_case, run_task, task_cases, task_key
from reference.scene.scene import Scene

__all__ = ["SweepIncomplete", "SweepInterrupted", "Emit", "default_workers", "run_case", "run_in_process",
           "run_pool", "ignore_interrupts", "connect", "run_dask"]

Emit = Callable[[list[dict[str, Any]]], None]
"""The driver's callback receiving the records of a task (one per case) as the task finishes."""


class SweepIncomplete(RuntimeError):
    """The sweep stopped before every case had a record (e.g. the Dask cluster went away)."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C or SIGTERM stopped the sweep (``done`` of ``total`` cases recorded in folder ``out``,
    signal ``signum``); the same command resumes.
    """

    def __init__(self, done: int, total: int, out: os.PathLike | str, signum: int = signal.SIGINT) -> None:
        super().__init__(f"{done} of {total} cases done (records in {out}); rerun the same command "
                         "to resume")
        self.done = done
        self.total = total
        self.out = out
        self.signum = signum


def default_workers() -> int:
    """Cores available to this process."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def run_in_process(tasks: Sequence[Task], base: Scene, function: CaseFunction, emit: Emit) -> None:
    """Run ``tasks`` on scene ``base`` with ``function`` one after the other in this process, calling
    ``emit(records)`` as each finishes.
    """
    for task in tasks:
        emit(run_task(task, base, function))


def run_pool(tasks: Sequence[Task], base: Scene, function: CaseFunction, workers: int,
             emit: Emit) -> None:
    """Run tasks in ``workers`` spawned processes, at most ``2 workers`` submitted at a time.

    A dying worker breaks the pool; the tasks in flight are rerun one case at a time in a fresh
    process, so the case that kills it is recorded as ``WorkerCrash``.
    """
    # spawn, not fork: a worker inherits nothing from the driver (threads, locks, open files)
    context = multiprocessing.get_context("spawn")
    queue = deque(tasks)
    while queue:
        victims = _pool_round(queue, base, function, workers, context, emit)
        _run_one_at_a_time(deque(c for task in victims for c in task_cases(task)), base, function,
                           context, emit)


def ignore_interrupts() -> None:
    """Pool worker initializer: the driver alone decides what an interruption stops."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _pool(workers: int, context) -> Iterator[ProcessPoolExecutor]:
    """A process pool whose workers are terminated, not awaited, on any exception."""
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


def _emit_finished(running: dict[Any, Task], emit: Emit) -> None:
    """Emit the records of the futures in ``running`` that finished with one."""
    for future in list(running):
        if future.done() and not future.cancelled() and future.exception() is None:
            emit(future.result())
            running.pop(future)


def _pool_round(queue: deque, base: Scene, function: CaseFunction, workers: int, context,
                emit: Emit) -> list[Task]:
    """Run from ``queue`` until it is empty or the pool breaks; returns the tasks in flight then."""
    running: dict[Any, Task] = {}
    with _pool(workers, context) as pool:
        try:
            while queue or running:
                while queue and len(running) < 2 * workers:
                    task = queue.popleft()
                    try:
                        running[pool.submit(run_task, task, base, function)] = task
                    except BrokenProcessPool:  # a worker died since the last wait: the round ends
                        queue.appendleft(task)  # never started: the next round runs it
                        _emit_finished(running, emit)
                        return list(running.values())
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
    """Run the cases of ``queue`` one at a time, each in a fresh pool of one process (a case that kills
    it is recorded as ``WorkerCrash``).
    """
    while queue:
        with _pool(1, context) as pool:
            while queue:
                case = queue.popleft()
                future = pool.submit(run_task, case, base, function)
                try:
                    records = future.result()
                except BrokenProcessPool:
                    emit([error_record(case, "WorkerCrash", "the worker process died while running "
                                       "this case alone (a crash, os._exit, or killed, e.g. out of memory)")])
                    break
                except KeyboardInterrupt:
                    _emit_finished({future: case}, emit)
                    raise
                emit(records)


def connect(scheduler: Any):
    """A :class:`distributed.Client` for ``scheduler`` (``tcp://host:port``) or the client given;
    SweepError without ``distributed`` or without an answer in 10 s.
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


def run_dask(tasks: Sequence[Task], base: Scene, function: CaseFunction, client, emit: Emit) -> None:
    """Submit every task to ``client``'s cluster and emit them as they complete.

    A case Dask gave up on (``KilledWorker``) is recorded as failed; a batch's cases are submitted
    again one by one. Any other cluster failure raises :class:`SweepIncomplete`.
    """
    from distributed import KilledWorker, as_completed  # optional, as in connect

    if not tasks:
        return
    token = uuid.uuid4().hex[:8]
    base_future = client.scatter(base, broadcast=True)

    def submit(items: Sequence[Task]) -> list:
        return client.map(run_task, items, base=base_future, function=function, pure=False,
                          key=[f"cardan-sweep-{token}-{task_key(task)}" for task in items])

    futures = submit(tasks)
    task_of = dict(zip(futures, tasks, strict=True))
    completed = as_completed(futures, with_results=True, raise_errors=False)
    try:
        for future, result in completed:
            task = task_of.pop(future)
            if _killed_batch(future, task, KilledWorker):
                again = submit(task_cases(task))
                task_of.update(zip(again, task_cases(task), strict=True))
                completed.update(again)
                continue
            with deferred_signals():  # emitted and crossed off together
                _emit_dask(future, result, task, emit, KilledWorker)
    except KeyboardInterrupt:  # keep the tasks finished meanwhile
        for future in [f for f in task_of if f.status == "finished"]:
            emit(future.result())
        raise
    finally:
        client.cancel(list(task_of))


def _killed_batch(future, task: Task, killed: type) -> bool:
    """Whether ``future`` is a batch whose worker Dask gave up on (``killed``: ``KilledWorker``)."""
    return isinstance(task, Batch) and future.status == "error" and isinstance(future.exception(), killed)


def _emit_dask(future, result, task: Task, emit: Emit, killed: type) -> None:
    """Emit a finished task's records, or a failed case's ``KilledWorker`` record; any other failure
    raises :class:`SweepIncomplete`.
    """
    if future.status == "finished":
        emit(result)
        return
    error = future.exception() if future.status == "error" else future.status
    if not isinstance(error, killed):
        where = task_key(task) if isinstance(task, Batch) else f"case {task.id}"
        raise SweepIncomplete(f"the Dask cluster failed on {where}: "
                              f"{type(error).__name__}: {error}; rerun to resume")
    emit([error_record(task, "KilledWorker", str(error))])
