"""The batched reference engine measured.

- per-sample cost against batch size: the rig scene (matched set) with Section 4.2 tolerances
  drawn as ``cardan tolerance montecarlo`` draws them (:func:`tolerance_scenes`), batches of 1,
  10, 100, 1000 through :func:`cardan_exudyn.engines.run_batch` (:func:`cost_by_batch_size`);
  the sweep's chunk size (:data:`cardan_exudyn.sweep.BATCH_SIZE`) is read from this table;
- the paper's eleven scenes in one batch, wall time and agreement with single runs
  (:func:`paper_batch`);
- peak memory per 1000 scenes (:func:`batch_memory`, Python's ``tracemalloc``, which numpy
  reports its arrays to);
- the Monte Carlo target, ``cardan tolerance montecarlo`` with the reference engine, with some
  samples compared to single runs (:func:`monte_carlo_target`);
- a Dask ``LocalCluster`` run of the same study against the in-process one (:func:`dask_equal`);
- a torque-driven paper scene with friction at ``rtol`` 1e-8, wall time per simulated revolution
  (:func:`torque_drive`; the reference engine's forward dynamics, :mod:`reference.engine.forward`).

All of them in one call: :func:`run_batch_bench`; the targets: :mod:`.targets`.
"""

from __future__ import annotations

import gc
import json
import math
import tempfile
import time
import tracemalloc
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from benchmarks.batch.targets import MONTE_CARLO_SAMPLES, batch_targets
from benchmarks.targets.paper import paper_scenes
from cardan_exudyn import engines
from cardan_exudyn.report.environment import environment
from cardan_exudyn.studies.bench.configs import Progress, quiet
from cardan_exudyn.studies.tolerance.command import monte_carlo
from cardan_exudyn.studies.tolerance.montecarlo import default_distributions
from cardan_exudyn.sweep import BATCH_SIZE, Distribution, RandomSpec, run_sweep
from reference.engine import ReferenceOptions
from reference.paper import named_scene, rig_scene
from reference.results.summary import Status
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["SIZES", "QUICK_SIZES", "TORQUE_DRIVE", "DASK_SAMPLES", "QUICK",
           "FULL", "SEED", "study_scene", "tolerance_scenes", "cost_by_batch_size", "paper_batch",
           "torque_drive", "batch_memory", "monte_carlo_target", "dask_equal", "run_batch_bench"]


SIZES = (1, 10, 100, 1000)
"""Batch sizes of the cost table."""
QUICK_SIZES = (1, 10)
TORQUE_DRIVE = {"scene": "paper-physical-10deg", "torque": 2.05, "initial_speed": 209.44, "rtol": 1e-8}
"""The torque-drive target's scene: 10 deg, started at 2000 rpm under about the drive torque the
prescribed-speed scene needs at its 2 N m mean input torque reading."""
DASK_SAMPLES = 1000
"""Samples of the Dask comparison (``--dask-samples``; docs/benchmarks.md has a 100,000 run)."""
QUICK = {"samples": 40, "dask_samples": 16, "memory_sizes": [2, 10], "checked": 4}
FULL = {"samples": MONTE_CARLO_SAMPLES, "dask_samples": DASK_SAMPLES, "memory_sizes": [100, 1000],
        "checked": 20}
SEED = 1
"""The tolerance study's default seed (``cardan tolerance montecarlo --seed``)."""


def study_scene() -> Scene:
    """The base scene of ``cardan tolerance montecarlo`` (``rig-matched``), time table off as the
    study sets it."""
    return replace(named_scene("rig-matched"), **{"record.timeseries": False})


def tolerance_scenes(samples: int, seed: int = SEED) -> list[Scene]:
    """``samples`` rig scenes (matched set) with the six mounting errors drawn as the tolerance
    study draws them: :func:`cardan_exudyn.studies.tolerance.montecarlo.default_distributions` (Section 4.2's
    tolerances, uniform with both signs), Latin hypercube, ``seed``."""
    base = replace(rig_scene(parameters="matched", errors=True), **{"record.timeseries": False})
    distributions = {p: Distribution(**d) for p, d in default_distributions().items()}
    spec = RandomSpec(samples, seed, distributions, "lhs")
    return [replace(base, **point) for point in spec.points()]


def _timed_batch(scenes: Sequence[Scene]) -> tuple[float, list]:
    start = time.perf_counter()
    results = engines.run_batch(scenes, "reference")
    return time.perf_counter() - start, results


def cost_by_batch_size(sizes: Sequence[int] = SIZES, seed: int = SEED,
                       progress: Progress = quiet) -> pd.DataFrame:
    """Wall time of one :func:`cardan_exudyn.engines.run_batch` per batch size, scenes built
    before the clock starts.

    Returns
    -------
    pandas.DataFrame
        ``batch_size``, ``wall_s`` [s], ``per_sample_ms`` [ms], ``ok`` (runs with status ok),
        ``speedup`` (per-sample cost of a batch of 1 over this one [-]).
    """
    rows = []
    _timed_batch(tolerance_scenes(1, seed + 1))  # warm-up: imports and first-call costs
    for size in sizes:
        scenes = tolerance_scenes(size, seed)
        wall, results = _timed_batch(scenes)
        rows.append({"batch_size": size, "wall_s": wall, "per_sample_ms": 1e3 * wall / size,
                     "ok": sum(r.success for r in results)})
        progress(f"batch of {size}: {wall:.3g} s, {rows[-1]['per_sample_ms']:.3g} ms per sample")
    table = pd.DataFrame(rows)
    single = table.loc[table["batch_size"] == 1, "per_sample_ms"]
    table["speedup"] = float(single.iloc[0]) / table["per_sample_ms"] if len(single) else float("nan")
    return table


def _largest_difference(a: Sequence, b: Sequence) -> float:
    """Largest ``|mean efficiency|`` difference of two result lists where both ran ok (NaN: none),
    infinite where their statuses differ."""
    diffs = []
    for x, y in zip(a, b, strict=True):
        if x.status != y.status:
            return math.inf
        if x.success:
            diffs.append(abs(x.summary.mean_efficiency - y.summary.mean_efficiency))
    return max(diffs) if diffs else float("nan")


def paper_batch(repeats: int = 3) -> dict[str, Any]:
    """The paper's eleven scenes (literal set, summary only) in one batch: median wall time [s]
    and the largest mean-efficiency difference [-] from single runs."""
    scenes = paper_scenes()
    walls = []
    results = []
    for _ in range(repeats):
        wall, results = _timed_batch(scenes)
        walls.append(wall)
    single = [engines.run(s, "reference") for s in scenes]
    return {"scenes": len(scenes), "wall_s": float(np.median(walls)), "walls_s": walls,
            "failed": sum(not r.success for r in results),
            "max_difference": _largest_difference(results, single)}


def torque_drive(repeats: int = 3) -> dict[str, Any]:
    """The reference engine on :data:`TORQUE_DRIVE` (friction, ``rtol`` = ``atol``): median wall
    time per simulated revolution [s] after one untimed run (imports), right-hand-side
    evaluations, status, mean efficiency."""
    t = TORQUE_DRIVE
    scene = replace(named_scene(t["scene"]), drive={"kind": "torque", "torque": t["torque"],
                                                    "initial_speed": t["initial_speed"]},
                    **{"record.timeseries": False})
    options = ReferenceOptions(ode_rtol=t["rtol"], ode_atol=t["rtol"])
    walls = []
    result = engines.run(scene, "reference", options)  # untimed: imports and first-call costs
    for _ in range(repeats):
        start = time.perf_counter()
        result = engines.run(scene, "reference", options)
        walls.append(time.perf_counter() - start)
    s = result.summary
    per_revolution = float(np.median(walls)) / scene.revolutions
    return {**t, "revolutions": scene.revolutions, "per_revolution_s": per_revolution, "walls_s": walls,
            "status": str(s.status), "mean_efficiency": s.mean_efficiency,
            "ode_evaluations": s.ode_evaluations}


def batch_memory(sizes: Sequence[int] = (100, 1000), seed: int = SEED) -> dict[str, Any]:
    """Peak memory allocated during one batch of tolerance scenes (results kept until the batch
    returns) at two sizes, and what 1000 scenes take: the peak at the smaller size plus the
    growth per scene between the two [MB] (one size alone would mix the per-run working memory,
    which does not grow with the batch, into the per-scene cost)."""
    peaks = []
    kept = []
    for size in sizes:
        batch = tolerance_scenes(size, seed)
        gc.collect()
        tracemalloc.start()
        try:
            results = _timed_batch(batch)[1]
            peaks.append(tracemalloc.get_traced_memory()[1] / 1e6)
            gc.collect()  # what the results hold, without garbage awaiting the cycle collector
            kept.append(tracemalloc.get_traced_memory()[0] / 1e6)
            del results
        finally:
            tracemalloc.stop()
    n0, n1 = sizes
    p0, p1 = peaks
    per_scene = (p1 - p0) / (n1 - n0)
    return {"sizes": list(sizes), "peak_mb": peaks, "retained_mb": kept, "per_scene_mb": per_scene,
            "per_1000_mb": p0 + per_scene * (1000 - n0)}


def monte_carlo_target(samples: int, out: Path, workers: int | None = None,
                       checked: int = 20) -> dict[str, Any]:
    """``cardan tolerance montecarlo`` (reference engine, seed 1, ``samples``) timed, and
    ``checked`` of its samples run again one by one through :func:`cardan_exudyn.engines.run`.

    Returns
    -------
    dict
        ``samples``, ``wall_s`` [s], ``per_sample_ms`` [ms], ``status_counts``, ``batching`` (of
        the sweep), ``checked`` and ``max_difference`` (mean efficiency, batched against single
        [-]; infinite when a status differs).
    """
    scene = study_scene()
    start = time.perf_counter()
    summary = monte_carlo(scene, "reference", samples, SEED, out=out, workers=workers, progress=False)
    wall = time.perf_counter() - start
    table = pd.read_csv(out / "cases" / "results.csv")
    pick = np.random.default_rng(SEED).choice(len(table), size=min(checked, len(table)), replace=False)
    diffs = []
    for i in sorted(pick):
        row = table.iloc[i]
        single = engines.run(replace(scene, **{p: float(row[p]) for p in default_distributions()}),
                             "reference").summary
        if single.status.value != row["status"]:
            diffs.append(math.inf)
        elif single.success:
            diffs.append(abs(single.mean_efficiency - float(row["mean_efficiency"])))
    sweep = json.loads((out / "cases" / "sweep.json").read_text(encoding="utf-8"))
    return {"samples": samples, "wall_s": wall, "per_sample_ms": 1e3 * wall / samples,
            "status_counts": summary["status_counts"], "batching": dict(sweep.get("batching") or {}),
            "checked": len(pick), "max_difference": max(diffs, default=float("nan"))}


def dask_equal(samples: int, out: Path, workers: int = 2) -> dict[str, Any]:
    """The Monte Carlo sweep of ``samples`` on a Dask ``LocalCluster`` (``workers`` processes of
    one thread) and in this process: whether every record agrees (timings aside).

    Returns
    -------
    dict
        ``samples``, ``dask_s`` and ``in_process_s`` [s], ``equal`` (every column but the wall
        times identical), ``max_difference`` (mean efficiency [-]); ``skipped`` when
        ``distributed`` is not installed.
    """
    try:
        import distributed  # optional: the bench part is skipped without it
    except ImportError as exc:
        return {"samples": samples, "skipped": f"distributed is not installed: {exc}"}
    spec = {"scene": study_scene(), "engine": "reference",
            "random": {"samples": samples, "seed": SEED, "method": "lhs",
                       "parameters": default_distributions()}}
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        start = time.perf_counter()
        run_sweep(spec, out / "dask", scheduler=cluster.scheduler_address, progress=False)
        dask_s = time.perf_counter() - start
    start = time.perf_counter()
    run_sweep(spec, out / "in-process", workers=1, progress=False)
    local_s = time.perf_counter() - start
    a = pd.read_csv(out / "dask" / "results.csv")
    b = pd.read_csv(out / "in-process" / "results.csv")
    timing = ["case_wall_s", "wall_time_s"]
    equal = a.drop(columns=timing).equals(b.drop(columns=timing))
    ok = (a["status"] == Status.OK) & (b["status"] == Status.OK)
    diff = np.abs(a.loc[ok, "mean_efficiency"].to_numpy(float) - b.loc[ok, "mean_efficiency"].to_numpy(float))
    diff = float(diff.max(initial=0.0))
    return {"samples": samples, "dask_s": dask_s, "in_process_s": local_s, "equal": bool(equal),
            "same_statuses": bool((a["status"] == b["status"]).all()), "max_difference": diff}


def run_batch_bench(quick: bool = False, sizes: Sequence[int] | None = None, samples: int | None = None,
                    dask_samples: int | None = None, workers: int | None = None,
                    progress: Progress = quiet) -> dict[str, Any]:
    """Every measurement of this module (quick: a smaller study, batches of 1 and 10).

    Parameters
    ----------
    quick : bool
        Defaults of a run of about a minute: ``QUICK`` instead of ``FULL``.
    sizes : sequence of int, optional
        Batch sizes of the cost table (default :data:`SIZES`, quick :data:`QUICK_SIZES`).
    samples, dask_samples : int, optional
        Monte Carlo samples of the timed study and of the Dask comparison (0: leave it out).
    workers : int, optional
        Local processes of the timed study (default: every core).
    """
    settings = {**(QUICK if quick else FULL), "quick": quick,
                "sizes": list(sizes or (QUICK_SIZES if quick else SIZES))}
    for key, value in (("samples", samples), ("dask_samples", dask_samples)):
        if value is not None:
            settings[key] = value
    start = time.perf_counter()
    result: dict[str, Any] = {"environment": environment(), "settings": settings,
                              "batch_size_constant": BATCH_SIZE}
    result["cost"] = cost_by_batch_size(settings["sizes"], progress=progress).to_dict(orient="records")
    result["paper"] = paper_batch()
    progress(f"paper scenes in one batch: {result['paper']['wall_s']:.3g} s")
    result["torque"] = torque_drive()
    progress(f"torque drive: {result['torque']['per_revolution_s']:.3g} s per revolution")
    result["memory"] = batch_memory(settings["memory_sizes"])
    progress(f"peak memory: {result['memory']['per_1000_mb']:.3g} MB per 1000 scenes")
    with tempfile.TemporaryDirectory(prefix="cardan-bench-batch-") as tmp:
        if settings["samples"]:
            result["monte_carlo"] = monte_carlo_target(settings["samples"], Path(tmp, "mc"), workers,
                                                       settings["checked"])
            progress(f"montecarlo {settings['samples']}: {result['monte_carlo']['wall_s']:.3g} s")
        if settings["dask_samples"]:
            result["dask"] = dask_equal(settings["dask_samples"], Path(tmp, "dask"))
            progress(f"dask {settings['dask_samples']}: equal {result['dask'].get('equal')}")
    result["wall_s"] = time.perf_counter() - start
    result["targets"] = batch_targets(result)
    return result
