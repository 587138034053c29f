"""Campaigns on synthetic recordings from a stated truth (friction 0.12 in every pair), each returning
the numbers its verdict rests on."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import tomllib

from rigdata.campaign import campaign, campaign_from_mapping
from rigdata.campaign.report import write_report
from rigdata.synthetic import write_campaign

__all__ = ["TRUTH", "truth_campaign", "coverage", "tied_groups", "QUASI_STATIC_POINTS"]

TRUTH = 0.12
"""The true friction coefficient of every pair [-]."""
SPIDER = ("input_spider", "spider_output")
FRAME = ("frame_input", "output_frame")


def _spec(toml: Path, **changes: Any):
    """The campaign of ``toml`` with top-level keys changed (engines, monte_carlo, parameters)."""
    data = tomllib.loads(toml.read_text(encoding="utf-8"))
    data.update(changes)
    return campaign_from_mapping(data, toml.parent, path=toml)


def _rows(result) -> list[dict[str, Any]]:
    """Per recording: label, use, E, k u_val, resolvable, dominant, each engine's S."""
    rows = []
    for r in result.recordings:
        first = r.first
        rows.append({"label": r.label, "use": r.use, "status": r.status, "E": first.comparison_error,
                     "k_u_val": r.k * first.u_val if first.u_val is not None else None,
                     "u_D": r.u_D, "u_input": r.budget.u_input if r.budget else None, "u_num": first.u_num,
                     "resolvable": r.resolvable, "dominant": r.dominant,
                     "S": {e: c.simulated for e, c in r.engines.items()}})
    return rows


def truth_campaign(folder: Path, drag: float, seconds: float = 12.0, workers: int | None = None,
                   seed: int = 0) -> dict[str, Any]:
    """The default eight recordings (four formats) with ``drag`` [N m] the model lacks, both engines, the
    report written to ``folder/report``: wall time by stage, estimate, test, verdicts."""
    write_start = time.perf_counter()
    toml = write_campaign(folder, friction=TRUTH, drag_torque=drag, seed=seed, seconds=seconds)
    written = time.perf_counter() - write_start
    start = time.perf_counter()
    result = campaign(toml, folder / "report", workers=workers)
    wall = time.perf_counter() - start
    write_report(result, folder / "report")
    (estimate,) = result.calibration.estimates
    cal = result.calibration
    return {"drag": drag, "seconds": seconds, "write_s": written, "wall_s": wall, "timing": result.timing,
            "estimate": estimate.value, "u": estimate.standard_uncertainty,
            "truth_within_k_u": abs(estimate.value - TRUTH) <= result.k * estimate.standard_uncertainty,
            "chi_square": cal.chi_square, "dof": cal.dof, "p_value": cal.p_value, "rejected": cal.rejected,
            "recordings": _rows(result)}


def coverage(folder: Path, seeds: int, seconds: float = 4.0, workers: int | None = None,
             progress=print) -> dict[str, Any]:
    """The consistent campaign over ``seeds`` noise seeds (reference engine, GUM only): how often the
    validation intervals hold the zero model error, the friction interval the truth, and the
    calibration test rejects a right model."""
    held = 0
    total = 0
    friction_held = 0
    rejected = 0
    for seed in range(seeds):
        toml = write_campaign(folder / f"seed{seed}", friction=TRUTH, seed=seed, seconds=seconds)
        result = campaign(_spec(toml, engines=["reference"], monte_carlo=0), None, workers=workers)
        for r in result.validation:
            total += 1
            held += int(not r.resolvable)
        (estimate,) = result.calibration.estimates
        friction_held += int(abs(estimate.value - TRUTH) <= result.k * estimate.standard_uncertainty)
        rejected += int(bool(result.calibration.rejected))
        progress(f"seed {seed}: {held}/{total} intervals hold 0, friction {friction_held}/{seed + 1}, "
                 f"rejected {rejected}/{seed + 1}")
    return {"seeds": seeds, "seconds": seconds, "intervals": total, "held": held,
            "rate": held / total, "binomial_sd": math.sqrt(0.95 * 0.05 / total),
            "friction_held": friction_held, "friction_rate": friction_held / seeds,
            "rejected": rejected, "rejected_rate": rejected / seeds}


QUASI_STATIC_POINTS = tuple(
    {"shaft_angle_deg": angle, "speed": 1.0, "input_torque": torque, "use": use, "format": "csv"}
    for angle, torque, use in ((10, 2.0, "calibration"), (20, 2.0, "calibration"), (30, 2.0, "calibration"),
                               (15, 3.0, "calibration"), (25, 1.5, "calibration"), (30, 3.0, "calibration"),
                               (20, 3.0, "validation"), (25, 2.5, "validation")))
"""Slow (1 rad/s) recordings, where the joint's inertia hardly acts: friction alone sets the loss."""


def tied_groups(folder: Path, seconds: float = 30.0, workers: int | None = None) -> dict[str, Any]:
    """Spider pairs and frame pairs as two parameters on quasi-static recordings: identifiable or not, and
    the combinations the data determine against the truth's value of each."""
    toml = write_campaign(folder, friction=TRUTH, seed=0, seconds=seconds, points=QUASI_STATIC_POINTS)
    groups = {"spider": SPIDER, "frame": FRAME}
    parameters = {name: {"keys": [f"joint.pairs.{p}.friction_coefficient" for p in pairs], "initial": 0.2,
                         "bounds": [0.0, 0.6]} for name, pairs in groups.items()}
    result = campaign(_spec(toml, engines=["reference"], parameters=parameters), folder / "report",
                      workers=workers)
    write_report(result, folder / "report")
    cal = result.calibration
    combos = [{"coefficients": c.coefficients, "value": c.value, "u": c.standard_uncertainty,
               "truth": sum(c.coefficients.values()) * TRUTH} for c in cal.combinations]
    return {"estimates": [{"name": e.name, "value": e.value, "u": e.standard_uncertainty,
                           "identifiable": e.identifiable, "at_bound": e.at_bound} for e in cal.estimates],
            "correlation": cal.correlation.tolist(), "combinations": combos,
            "chi_square": cal.chi_square, "dof": cal.dof, "p_value": cal.p_value,
            "recordings": _rows(result)}


def sampling_check(folder: Path, samples: int = 100, seconds: float = 4.0,
                   workers: int | None = None) -> dict[str, Any]:
    """The consistent campaign with a stated arm-radius uncertainty: ``u_input``'s parameter and input
    parts by sensitivity coefficients against the spread of ``samples`` sampled model runs."""
    toml = write_campaign(folder, friction=TRUTH, seed=0, seconds=seconds)
    inputs = {"joint.geometry.arm_radius": {"distribution": "normal", "std": 0.0005}}
    spec = _spec(toml, engines=["reference"], monte_carlo=0, inputs=inputs, input_samples=samples)
    result = campaign(spec, None, workers=workers)
    rows = []
    for r in result.recordings:
        b = r.budget
        by_sensitivity = math.sqrt(b.u_parameters**2 + b.u_inputs**2)
        rows.append({"label": r.label, "u_parameters": b.u_parameters, "u_inputs": b.u_inputs,
                     "sensitivity": by_sensitivity, "sampled": b.u_input_sampled,
                     "ratio": b.u_input_sampled / by_sensitivity})
    return {"samples": samples, "relative_sd_of_sampled_std": 1.0 / math.sqrt(2 * (samples - 1)),
            "recordings": rows}
