"""Running a sweep: :func:`run_sweep` plans, resumes, runs the missing cases, and writes the tables.

Each case runs ``function(replace(base, **overrides), engine, **function_args)`` and becomes one
record. Files in ``OUT`` (``plan.json``, ``cases.jsonl``, ``results.csv``, ``sweep.json``):
``docs/sweep.md``.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.outputs import OutputError, check_output_folder
from cardan_exudyn.report.environment import environment
from cardan_exudyn.sweep.checks import SweepError
from cardan_exudyn.sweep.executors import (
    Emit,
    SweepInterrupted,
    connect,
    default_workers,
    run_dask,
    run_in_process,
    run_pool,
)
from cardan_exudyn.sweep.plan import Case, Plan, make_plan
from cardan_exudyn.sweep.records import (
    CASES_FILE,
    PLAN_FILE,
    RESULTS_FILE,
    SUMMARY_FILE,
    SWEEP_FILES,
    RecordWriter,
    existing_records,
    interrupted_record,
    locked,
    read_records,
    results_table,
    statistics,
    write_text,
)
from cardan_exudyn.sweep.spec import SweepSpec
from cardan_exudyn.sweep.tasks import Batch, plan_tasks
from reference.results.summary import Status

__all__ = ["run_sweep", "Progress"]


def run_sweep(spec: SweepSpec | Mapping[str, Any], out: str | os.PathLike, *,
              workers: int | None = None, scheduler: Any = None, restart: bool = False,
              retry_failed: bool = False, progress: bool | None = None,
              batch_size: int | None = None) -> dict[str, Any]:
    """Run (or resume) a sweep into the folder ``out`` and return its summary (``sweep.json``).

    Parameters
    ----------
    spec : SweepSpec or dict
        A dict is read by :func:`cardan_exudyn.sweep.spec_from_mapping`.
    out : path
        Output folder; with records of the same plan, only the missing cases run.
    workers : int, optional
        Local processes (default: every available core); 1 runs in this process.
    scheduler : str or distributed.Client, optional
        Dask scheduler address (``tcp://host:port``) or client.
    restart : bool
        Discard the sweep files in ``out`` and start over.
    retry_failed : bool
        Also rerun cases recorded with a status other than ``ok``.
    progress : bool, optional
        Progress bar on stderr; default when stderr is a terminal.
    batch_size : int, optional
        Most cases per batch of the batched engines (default
        :data:`cardan_exudyn.sweep.tasks.BATCH_SIZE`); 1 runs every case on its own.

    Returns
    -------
    dict
        Spec, counts, wall time [s], statistics per output.

    Raises
    ------
    SweepError, SceneError, EngineUnavailable
        Before anything is written.
    SweepIncomplete
        The Dask cluster failed; rerun to resume.
    SweepInterrupted
        Ctrl-C or SIGTERM; finished cases are recorded; rerun to resume.
    """
    start = time.perf_counter()
    for name, value in (("workers", workers), ("batch_size", batch_size)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
            raise SweepError(f"`{name}` must be an integer >= 1, got {value!r}")
    plan = make_plan(spec)
    out = Path(out)
    try:
        check_output_folder(out, replace=False)
    except OutputError as exc:
        raise SweepError(f"--out {exc}") from None
    if not restart:
        existing_records(out, plan)
    client = connect(scheduler) if scheduler is not None else None
    try:
        out.mkdir(parents=True, exist_ok=True)
        with locked(out):
            records = _prepare(out, plan, restart)
            todo = [c for c in plan.cases if c.id not in records or interrupted_record(records[c.id])
                    or (retry_failed and records[c.id].get("status") != Status.OK)]
            how = _execute(plan, todo, records, out, (workers, batch_size), client, progress)
            return _finish(plan, records, out, len(todo), time.perf_counter() - start, how)
    finally:
        if client is not None and client is not scheduler:
            client.close()


def _prepare(out: Path, plan: Plan, restart: bool) -> dict[str, dict[str, Any]]:
    """Under the lock: reset or check the folder, write the plan, cut a torn last record."""
    if restart:
        for name in SWEEP_FILES:
            (out / name).unlink(missing_ok=True)
    records = existing_records(out, plan)
    if not (out / PLAN_FILE).exists():
        write_text(out / PLAN_FILE, json.dumps(plan.to_dict(), indent=1, allow_nan=False) + "\n")
    read_records(out / CASES_FILE, truncate=True)
    (out / RESULTS_FILE).unlink(missing_ok=True)
    (out / SUMMARY_FILE).unlink(missing_ok=True)
    return records


def _execute(plan: Plan, todo: list[Case], records: dict, out: Path, sizes: tuple[int | None, int | None],
             client, progress: bool | None) -> dict[str, Any]:
    """Run ``todo``, appending each task's records as they arrive (also into ``records``); returns
    :func:`_dispatch`'s answer. ``sizes``: ``workers`` and ``batch_size``.
    """
    rerun = {c.id for c in todo}
    failed = sum(r.get("status") != Status.OK for i, r in records.items() if i not in rerun)
    show = sys.stderr.isatty() if progress is None else progress
    bar = Progress(len(plan.cases), len(plan.cases) - len(todo), failed, show and bool(todo))
    writer = RecordWriter(out / CASES_FILE)

    def emit(new: list[dict[str, Any]]) -> None:
        with deferred_signals():  # an interruption now counts these records as done
            # one fsync per task (a few ms each: per case, they would cost more than a batched case)
            if len(new) == 1:
                writer.write(new[0])
            else:
                writer.write_many(new)
            records.update((r["id"], r) for r in new)
        for record in new:
            bar.update(record.get("status") == Status.OK)

    workers, batch_size = sizes
    try:
        return _dispatch(plan, todo, min(workers or default_workers(), max(len(todo), 1)), client, emit,
                         batch_size)
    except KeyboardInterrupt as exc:
        done = sum(c.id in records and not interrupted_record(records[c.id]) for c in plan.cases)
        raise SweepInterrupted(done, len(plan.cases), out / CASES_FILE,
                               getattr(exc, "signum", signal.SIGINT)) from None
    finally:
        writer.close()
        bar.close()


def _dispatch(plan: Plan, todo: list[Case], workers: int, client, emit: Emit,
              batch_size: int | None = None) -> dict[str, Any]:
    """Hand ``todo`` as tasks to the cluster, this process or a local pool; returns the executor and
    the number of cases run in batches.
    """
    function = plan.spec.case_function()
    if client is not None:
        executor = {"kind": "dask", "scheduler": client.scheduler.address,
                    "threads": sum(client.nthreads().values())}
    elif workers == 1:
        executor = {"kind": "in-process", "workers": 1}
    else:
        executor = {"kind": "processes", "workers": workers}
    tasks = plan_tasks(todo, function, executor.get("threads", workers), batch_size)
    batches = [len(t.cases) for t in tasks if isinstance(t, Batch)]
    batching = {"batches": len(batches), "batched_cases": sum(batches),
                "largest_batch": max(batches, default=0)}
    if client is not None:
        run_dask(tasks, plan.base, function, client, emit)
    elif workers == 1:
        run_in_process(tasks, plan.base, function, emit)
    else:
        run_pool(tasks, plan.base, function, workers, emit)
    return {"executor": executor, "batching": batching}


def _finish(plan: Plan, records: dict, out: Path, run_now: int, wall: float,
            how: dict[str, Any]) -> dict[str, Any]:
    """Write ``results.csv`` and ``sweep.json``; returns the latter's content."""
    table = results_table(plan, records)
    ok = table["status"] == Status.OK
    summary = {
        "spec": plan.spec.to_dict(),
        "base_scene": plan.base.name,
        "base_scene_sha256": plan.base_hash,
        "cases": len(plan.cases),
        "done": int(len(table)),
        "ok": int(ok.sum()),
        "failed": int((~ok).sum()),
        "status_counts": {str(k): int(v) for k, v in table["status"].value_counts().items()},
        "failed_ids": table.loc[~ok, "id"].tolist(),
        "run_now": run_now,
        "executor": how["executor"],
        "batching": how["batching"],
        "wall_time_s": wall,
        "case_time_s": float(np.nansum(table["case_wall_s"].to_numpy(dtype=float))),
        "statistics": statistics(table, plan.parameters),
        "files": {"plan": PLAN_FILE, "records": CASES_FILE, "table": RESULTS_FILE},
        "environment": environment(),
    }
    write_text(out / RESULTS_FILE, table.to_csv(index=False))
    write_text(out / SUMMARY_FILE, json.dumps(to_jsonable(summary), indent=2, allow_nan=False) + "\n")
    return to_jsonable(summary)


class Progress:
    """Cases done / total, failures, elapsed and ETA on stderr (tqdm), or nothing."""

    def __init__(self, total: int, done: int, failed: int, show: bool) -> None:
        self.failed = failed
        self._bar = None
        if show:
            from tqdm import tqdm  # only when a bar is shown: workers and quiet runs skip it

            self._bar = tqdm(total=total, initial=done, unit="case", file=sys.stderr,
                             dynamic_ncols=True, desc="sweep", smoothing=0.1)
            self._bar.set_postfix(failed=failed)

    def update(self, ok: bool) -> None:
        """One more case done; ``ok``: its status is ``ok``."""
        self.failed += not ok
        if self._bar is not None:
            self._bar.set_postfix(failed=self.failed, refresh=False)
            self._bar.update(1)

    def close(self) -> None:
        """Close the bar (nothing without one)."""
        if self._bar is not None:
            self._bar.close()
