"""The work-precision runs of ``cardan bench``: every configuration of every scene, its errors
against the reference engine at its tightest defaults, and its median wall time per simulated
second. The repeats run in rounds over all configurations, so a change in the machine's load hits
every configuration alike.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn import engines
from cardan_exudyn.studies.bench.configs import (
    ENGINE_NAMES,
    BenchError,
    Config,
    Progress,
    configurations,
    quiet,
    simulated_time,
)
from reference.engine.motion import InputMotion, input_motion
from reference.engine.options import ReferenceOptions
from reference.engine.table import columns_at
from reference.physics.kinematics import speed_ratio
from reference.results.result import Result
from reference.results.summary import Summary
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["ERROR_KEYS", "Yardstick", "yardstick", "run_errors", "cost_counters", "Job",
           "bench_jobs", "timed_run", "work_precision"]

ERROR_KEYS = ("speed_ratio_error", "torque_in_error", "torque_in_error_steady",
              "mean_efficiency_error", "mean_torque_in_error")


@dataclass
class Yardstick:
    """The reference engine's exact answer for one scene: its input motion and summary."""

    scene: Scene
    motion: InputMotion
    summary: Summary


def yardstick(scene: Scene) -> Yardstick:
    """Reference run of ``scene`` (summary only) at its tightest defaults; BenchError when it fails."""
    options = ReferenceOptions()
    result = engines.run(replace(scene, **{"record.timeseries": False}), "reference", options)
    if not result.success:
        raise BenchError(f"the reference engine cannot solve {scene.name!r}: {result.message}")
    return Yardstick(scene, input_motion(scene, options), result.summary)


def run_errors(scene: Scene, result: Result, yard: Yardstick) -> dict[str, float]:
    """Errors [-] of run ``result`` of ``scene`` against ``yard`` (NaN without table or means).

    ``speed_ratio_error``: max ``|omega_out/omega_in - exact ratio|``; ``torque_in_error`` (all rows)
    and ``torque_in_error_steady`` (after the first revolution): max ``|torque_in - reference|`` over
    the reference's largest ``|torque_in|``; ``mean_efficiency_error`` (friction scenes);
    ``mean_torque_in_error`` (relative).
    """
    out = dict.fromkeys(ERROR_KEYS, float("nan"))
    if not result.success or result.table is None:
        return out
    out.update(_table_errors(scene, result.table, yard))
    summary = result.summary
    exact = yard.summary
    if scene.has_friction:
        out["mean_efficiency_error"] = abs(summary.mean_efficiency - exact.mean_efficiency)
    out["mean_torque_in_error"] = abs(summary.mean_torque_in - exact.mean_torque_in) / abs(
        exact.mean_torque_in)
    return out


def _table_errors(scene: Scene, table: pd.DataFrame, yard: Yardstick) -> dict[str, float]:
    """The speed-ratio and drive-torque errors of time ``table`` of ``scene`` against ``yard``."""
    t = table["t"].to_numpy()
    theta = table["theta_in"].to_numpy()
    ratio = table["omega_out"].to_numpy() / table["omega_in"].to_numpy()
    exact = columns_at(scene, yard.motion, t)
    if scene.joint.errors.any:  # Hooke's law is the ideal joint's: the reference's RCCC ratio
        hooke = exact["omega_out"] / exact["omega_in"]
    else:
        hooke = speed_ratio(theta, scene.joint.geometry.shaft_angle)
    out = {"speed_ratio_error": float(np.max(np.abs(ratio - hooke)))}
    ref = exact["torque_in"]
    diff = np.abs(table["torque_in"].to_numpy() - ref) / float(np.max(np.abs(ref)))
    out["torque_in_error"] = float(np.max(diff))
    steady = np.abs(theta - theta[0]) >= 2.0 * math.pi - 1e-9
    if np.any(steady):
        out["torque_in_error_steady"] = float(np.max(diff[steady]))
    return out


def cost_counters(summary: Summary) -> dict[str, Any]:
    """The engine's cost counters, flattened: steps, Newton iterations, Jacobians, friction evaluations
    per step, quadrature panels.
    """
    friction = summary.friction
    quadrature = summary.extras.get("quadrature")
    return {"steps": summary.steps, "newton_iterations": summary.newton_iterations,
            "jacobian_evaluations": summary.jacobian_evaluations,
            "friction_evaluations_per_step": friction.mean_iterations_per_step if friction else None,
            "quadrature_panels": quadrature.get("panels") if isinstance(quadrature, dict) else None}


@dataclass
class Job:
    """One configuration on one scene: its first run's record and the timed runs' walls [s]."""

    key: str
    config: Config
    scene: Scene
    yard: Yardstick
    walls: list[float] = field(default_factory=list)
    record: dict[str, Any] | None = None


def bench_jobs(scenes: Mapping[str, Scene], quick: bool, engines: Iterable[str]) -> list[Job]:
    """Every configuration of each of ``scenes`` (key -> scene) for ``engines``, with its yardstick."""
    jobs = []
    for key, base in scenes.items():
        yard = yardstick(base)
        jobs += [Job(key, config, config.scene(base), yard)
                 for config in configurations(base, quick, engines)]
    return jobs


def timed_run(config: Config, scene: Scene) -> tuple[Result | None, str, float]:
    """``(result or None, error raised or "", wall time [s])`` of one run of ``config`` on ``scene``."""
    start = time.perf_counter()
    result = None
    error = ""
    try:
        result = config.run(scene)
    except Exception as exc:  # a configuration that cannot run is recorded as a row, not a crash
        error = f"{type(exc).__name__}: {exc}"
    return result, error, time.perf_counter() - start


def _first_record(job: Job, result: Result | None, error: str) -> dict[str, Any]:
    """The row of ``job`` from its first run (``result``, or None with ``error``): configuration,
    status, errors, cost counters, simulated time [s].
    """
    record = {"scene": job.key, **job.config.describe()}
    # the coupling that ran (the scene's own where the configuration does not set one)
    record["coupling"] = job.scene.friction.coupling if job.scene.has_friction else None
    if result is None:
        record.update(status="error", reason=error[:300])
    else:
        summary = result.summary
        record.update(status=summary.status.value, reason=str(summary.reason)[:300],
                      mean_efficiency=summary.mean_efficiency,
                      **run_errors(job.scene, result, job.yard), **cost_counters(summary))
    record["simulated_s"] = simulated_time(job.scene)
    return record


def _finished_row(job: Job) -> dict[str, Any]:
    """The record of ``job`` with its median wall time [s] and per simulated second [-]."""
    wall = float(np.median(job.walls)) if job.walls else float("nan")
    return {**job.record, "wall_s": wall, "wall_per_simulated_s": wall / job.record["simulated_s"],
            "runs_timed": len(job.walls)}


def work_precision(scenes: Mapping[str, Scene], quick: bool, repeats: int,
                   engines: Iterable[str] = ENGINE_NAMES,
                   progress: Progress | None = None) -> pd.DataFrame:
    """Run every configuration of every scene ``repeats`` times in rounds, the wall time their median;
    one row per configuration: description, status, :func:`run_errors`, cost counters,
    ``simulated_s``, ``wall_s`` [s], ``wall_per_simulated_s`` [-].
    """
    say = progress or quiet
    jobs = bench_jobs(scenes, quick, engines)
    start = time.perf_counter()
    for round_ in range(repeats):
        for i, job in enumerate(jobs):
            result, error, wall = timed_run(job.config, job.scene)
            if result is not None and result.success:
                job.walls.append(wall)
            if job.record is None:
                job.record = _first_record(job, result, error)
            say(f"[{round_ * len(jobs) + i + 1}/{len(jobs) * repeats} "
                f"{time.perf_counter() - start:6.1f} s] {job.key:20s} {job.config.label:28s} "
                f"n={job.config.steps:<5d} {wall:7.3f} s {job.record['status']}")
    return pd.DataFrame([_finished_row(job) for job in jobs])
