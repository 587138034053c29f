"""The batched reference engine's targets (:func:`batch_targets`), from the measurements of
:func:`benchmarks.batch.measure.run_batch_bench`. Measured: ``docs/benchmarks.md`` (*The batched
reference engine*)."""

from __future__ import annotations

from typing import Any

from cardan_exudyn.report.format import number
from reference.engine import ReferenceOptions
from reference.results.summary import Status

__all__ = ["MONTE_CARLO_TARGET_S", "PAPER_BATCH_TARGET_S", "TORQUE_TARGET_S", "MONTE_CARLO_SAMPLES",
           "AGREEMENT", "batch_targets"]


MONTE_CARLO_TARGET_S = 30.0
"""The Monte Carlo study of :data:`MONTE_CARLO_SAMPLES` samples on a 2-core machine [s]."""
PAPER_BATCH_TARGET_S = 0.1
"""The eleven paper scenes in one batch [s]."""
TORQUE_TARGET_S = 0.2
"""A torque-driven paper scene with friction, per simulated revolution [s]."""
MONTE_CARLO_SAMPLES = 10_000
"""Samples of the Monte Carlo target's tolerance study."""
AGREEMENT = 2.0 * ReferenceOptions().quadrature_rtol
"""Batched and single (or Dask and in-process) mean efficiencies agree when within this [-]: the
quadrature accepts each work integral to ``quadrature_rtol`` of the input work, and the efficiency
``1 - W_loss / W_in`` takes the error of both (where the batched pass adapts differently)."""


def batch_targets(result: dict[str, Any]) -> list[dict[str, Any]]:
    """The targets measured here: ``target``, ``measured``, ``limit``, ``met`` (None
    when the run was smaller than the target's), ``detail``."""
    paper = result["paper"]
    rows = [{"target": "paper_batch", "measured": paper["wall_s"], "limit": PAPER_BATCH_TARGET_S,
             "met": paper["wall_s"] <= PAPER_BATCH_TARGET_S and paper["failed"] == 0,
             "detail": f"{paper['scenes']} scenes, median of {len(paper['walls_s'])}; largest difference "
                       f"from single runs {number(paper['max_difference'], '.2g')}"}]
    torque = result.get("torque")
    if torque:
        rows.append({"target": "torque_drive", "measured": torque["per_revolution_s"],
                     "limit": TORQUE_TARGET_S,
                     "met": torque["per_revolution_s"] <= TORQUE_TARGET_S and torque["status"] == Status.OK,
                     "detail": f"{torque['scene']}, {torque['torque']:g} N m from "
                               f"{torque['initial_speed']:g} rad/s, rtol {torque['rtol']:g}: "
                               f"{torque['status']}, mean efficiency "
                               f"{number(torque['mean_efficiency'], '.6g')}, {torque['ode_evaluations']} "
                               f"right-hand sides, median of {len(torque['walls_s'])}"})
    if result.get("monte_carlo"):
        rows.append(_monte_carlo_row(result["monte_carlo"]))
    dask = result.get("dask")
    if dask:
        detail = dask.get("skipped") or (f"{dask['samples']} samples: Dask {dask['dask_s']:.3g} s, "
                                         f"in-process {dask['in_process_s']:.3g} s")
        met = None if "skipped" in dask else bool(dask["same_statuses"]
                                                  and dask["max_difference"] <= AGREEMENT)
        rows.append({"target": "dask_equal", "measured": dask.get("max_difference"), "limit": AGREEMENT,
                     "met": met, "detail": detail + f"; every column identical: {dask.get('equal')}"})
    return rows


def _monte_carlo_row(mc: dict[str, Any]) -> dict[str, Any]:
    """The Monte Carlo target: met only when measured at its full size."""
    projected = mc["wall_s"] * MONTE_CARLO_SAMPLES / mc["samples"]
    full = mc["samples"] >= MONTE_CARLO_SAMPLES
    return {"target": "montecarlo", "measured": mc["wall_s"], "limit": MONTE_CARLO_TARGET_S,
            "met": (mc["wall_s"] <= MONTE_CARLO_TARGET_S and mc["max_difference"] <= AGREEMENT)
            if full else None,
            "detail": f"{mc['samples']} samples ({number(mc['per_sample_ms'], '.3g')} ms each; "
                      f"{MONTE_CARLO_SAMPLES} at this rate: {projected:.3g} s); statuses "
                      f"{mc['status_counts']}; batches {mc['batching']}; {mc['checked']} samples "
                      f"against single runs: largest difference "
                      f"{number(mc['max_difference'], '.2g')}"}
