"""What a worker runs: one case, or a batch of cases through the engine's batched pass.

Either way a task returns one record per case, so executors, records and resume see cases only.
Only the default case function is batched: a custom one may do anything with its scene.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cardan_exudyn import engines
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.sweep.functions import DEFAULT_FUNCTION, CaseFunction, resolve_function
from cardan_exudyn.sweep.plan import Case
from cardan_exudyn.sweep.records import ERROR, RESERVED_OUTPUTS, scalar_summary
from cardan_exudyn.sweep.spec import flatten_paths
from reference.results.summary import Status
from reference.scene.mapping import replace
from reference.scene.scene import Scene

__all__ = ["BATCH_SIZE", "BATCHES_PER_WORKER", "Batch", "Task", "batched_function", "batch_size_for",
           "plan_tasks", "run_case", "run_batch_cases", "run_task", "task_cases", "task_key"]

BATCH_SIZE = 1000
"""Most cases in one batch: it bounds a batch's memory, which grows linearly with the batch (a
scene that records its time table holds 721 x 72 floats, 0.4 MB), while the cost per case stops
falling well before it. Measured (per-sample cost against batch size, peak memory per 1000
scenes): docs/benchmarks.md#the-batched-reference-engine."""
BATCHES_PER_WORKER = 4
"""Batches are cut so that each worker gets at least this many (smaller batches when the sweep is
small): the last batch to finish does not leave the other workers idle for long, records land and
the progress bar moves several times per worker, and Ctrl-C loses at most a quarter of a worker's
share (the batch in flight is not recorded; it runs again on resume)."""


@dataclass(frozen=True)
class Batch:
    """Cases of one engine run together by :func:`run_batch_cases`."""

    cases: tuple[Case, ...]

    @property
    def engine(self) -> str:
        """The engine of every case of the batch."""
        return self.cases[0].engine


Task = Case | Batch
"""What a worker runs: one case, or a batch."""


def task_cases(task: Task) -> list[Case]:
    """The cases of a task."""
    return list(task.cases) if isinstance(task, Batch) else [task]


def task_key(task: Task) -> str:
    """A name of the task unique within its sweep (Dask's task keys)."""
    if isinstance(task, Batch):
        return f"batch-{task.cases[0].id}-{len(task.cases)}"
    return task.id


def batched_function(function: CaseFunction) -> bool:
    """Whether the cases of ``function`` may run in batches: the default case function, no arguments."""
    if function.args:
        return False
    return function.name == DEFAULT_FUNCTION or resolve_function(function.name) is resolve_function(
        DEFAULT_FUNCTION)


def batch_size_for(cases: int, workers: int, batch_size: int = BATCH_SIZE) -> int:
    """Cases per batch (at least 1) for ``cases`` cases of one engine: at most ``batch_size``, and
    small enough that each of ``workers`` gets :data:`BATCHES_PER_WORKER` batches.
    """
    return max(1, min(batch_size, math.ceil(cases / (BATCHES_PER_WORKER * max(workers, 1)))))


def plan_tasks(cases: Sequence[Case], function: CaseFunction, workers: int,
               batch_size: int | None = None) -> list[Task]:
    """The tasks of ``cases``: each engine's cases with a batched pass cut into :class:`Batch` es in plan
    order (default case function only), every other case on its own.

    Parameters
    ----------
    cases : sequence of Case
        The plan's cases, in order.
    function : CaseFunction
    workers : int
        Processes or Dask threads that run tasks at once.
    batch_size : int, optional
        Most cases per batch (default :data:`BATCH_SIZE`); 1 runs every case on its own.

    Returns
    -------
    list of Task
    """
    by_engine: dict[str, list[Case]] = {}
    for case in cases:
        by_engine.setdefault(case.engine, []).append(case)
    limit = BATCH_SIZE if batch_size is None else batch_size
    tasks: list[Task] = []
    for engine, group in by_engine.items():
        if limit <= 1 or not batched_function(function) or not engines.has_batch(engine):
            tasks += group
            continue
        size = batch_size_for(len(group), workers, limit)
        chunks = [group[i:i + size] for i in range(0, len(group), size)]
        tasks += [Batch(tuple(c)) if len(c) > 1 else c[0] for c in chunks]
    return tasks


def run_task(task: Task, base: Scene,
             function: CaseFunction | str = DEFAULT_FUNCTION) -> list[dict[str, Any]]:
    """The records of ``task``'s cases, in order, on the sweep's ``base`` scene with ``function``
    (a batch always runs the default one).
    """
    if isinstance(task, Batch):
        return run_batch_cases(task, base)
    return [run_case(task, base, function)]


def run_case(case: Case, base: Scene, function: CaseFunction | str = DEFAULT_FUNCTION) -> dict[str, Any]:
    """Run one case and return its record; an exception becomes a record with status ``error``.

    Parameters
    ----------
    case : Case
    base : Scene
        The sweep's base scene.
    function : CaseFunction or str
        The case function (a name alone: no arguments).

    Returns
    -------
    dict
        :data:`cardan_exudyn.sweep.records.RECORD_KEYS`, the function's outputs and, after an
        exception, its ``traceback``.
    """
    function = CaseFunction(function) if isinstance(function, str) else function
    start = time.perf_counter()
    try:
        scene = replace(base, **case.overrides) if case.overrides else base
        record = _record(case, _outputs(function.name, function(scene, case.engine)))
    except Exception as exc:  # the worker's boundary: any failure of the case becomes its record
        record = _failure(case, exc)
    record["case_wall_s"] = time.perf_counter() - start
    return record


def run_batch_cases(batch: Batch, base: Scene) -> list[dict[str, Any]]:
    """Records of ``batch``'s cases on ``base``, from one :func:`cardan_exudyn.engines.run_batch`, equal
    to :func:`run_case`'s.

    If the batched run raises, every case runs again on its own so a failure is recorded for its
    own case only. ``case_wall_s`` is the batch's wall time over its cases.
    """
    start = time.perf_counter()
    records: dict[int, dict[str, Any]] = {}
    scenes: dict[int, Scene] = {}
    for i, case in enumerate(batch.cases):
        try:
            scenes[i] = replace(base, **case.overrides) if case.overrides else base
        except Exception as exc:  # as in run_case: a case's failure is its record
            records[i] = _failure(case, exc)
    try:
        results = engines.run_batch(list(scenes.values()), batch.engine) if scenes else []
    except Exception:  # one case's exception must not fail its batch-mates: each runs alone
        return [run_case(case, base) for case in batch.cases]
    for i, result in zip(scenes, results, strict=True):
        case = batch.cases[i]
        try:
            records[i] = _record(case, _outputs(DEFAULT_FUNCTION, scalar_summary(result.summary)))
        except Exception as exc:  # as in run_case
            records[i] = _failure(case, exc)
    share = (time.perf_counter() - start) / len(batch.cases)
    return [{**records[i], "case_wall_s": share} for i in range(len(batch.cases))]


def _record(case: Case, outputs: dict[str, Any]) -> dict[str, Any]:
    """The record of a case whose function returned ``outputs`` (``case_wall_s`` set by the caller)."""
    status = str(outputs.pop("status", Status.OK))
    reason = str(outputs.pop("reason", "") or "")
    return {**case.to_dict(), "status": status, "reason": reason, "error_type": None, "error": None,
            "case_wall_s": None, **outputs}


def _failure(case: Case, exc: Exception) -> dict[str, Any]:
    """The record of a case whose function raised ``exc``."""
    error_type = type(exc).__name__
    error = str(exc)
    return {**case.to_dict(), "status": ERROR, "reason": f"{error_type}: {error}",
            "error_type": error_type, "error": error, "case_wall_s": None,
            "traceback": "".join(traceback.format_exception(exc)[-12:])}


def _outputs(name: str, outputs: Any) -> dict[str, Any]:
    """A case function's return value checked and flattened into JSON-able record fields."""
    if not isinstance(outputs, Mapping):
        raise TypeError(f"case function {name} returned {type(outputs).__name__}, not a dict")
    clash = sorted(RESERVED_OUTPUTS & set(outputs))
    if clash:
        raise ValueError(f"case function {name} returned reserved key(s) {clash}")
    return to_jsonable(flatten_paths(outputs))
