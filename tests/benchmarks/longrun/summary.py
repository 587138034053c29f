"""The long runs' headline figures (:func:`summarise`): per node type, the largest value and the
first and last windows of every per-revolution measure and the efficiency's trend; per shaft
angle, the order of the energy loss in the step and its dependence on the spectral radius; and
plain sentences for what did not run through.

Measurements only: the tolerances these figures are held to, each with its reason, are the
tests of ``tests/benchmarks/test_longrun.py``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from benchmarks.longrun.measures import damping_coefficient, first_last, linear_trend, window_size
from benchmarks.longrun.plan import (
    DEFAULT_RHO,
    ENGINE,
    RHO_LADDER_STEPS,
    RHO_MODEL,
    STARTUP_REVOLUTIONS,
    LongRunPlan,
    settings,
)
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.report.format import number
from reference.results.summary import Status

__all__ = ["DRIFT_MEASURES", "NEWTON_TOLERANCE", "ROTVEC_FAILURE", "measure_figures",
           "efficiency_figures", "drift_summary", "step_ladder", "rho_ladder", "fit_dissipation",
           "findings", "summarise"]

DRIFT_MEASURES = ("position_violation_m", "angle_violation_rad", "velocity_violation_m_s",
                  "angular_velocity_violation_rad_s", "orthogonality_error", "ep_norm_error",
                  "rotvec_norm_max", "input_angle_error_rad", "time_grid_error_s",
                  "balance_residual_j")
NEWTON_TOLERANCE = ExudynOptions().newton_absolute_tolerance
ROTVEC_FAILURE = (
    "the spider's rotation vector passes the identity at every whole input revolution and the step "
    "grid lands there; Exudyn's CompositionRotationVector (w = pi - 2 atan2(x, sqrt(|1 - x^2|)), "
    "x = cos(w/2)) cannot resolve angles below about sqrt(eps) = 1e-8 rad and returns exactly zero, "
    "so at that step the input-spider pair is misaligned by the input angle's rounding drift "
    "(theta_in - 2 pi k, growing with the run); once that exceeds what Newton accepts, Newton cannot "
    "represent the sub-1e-8 rotation that would remove it and the step fails")


def measure_figures(rows: pd.DataFrame, steady: pd.DataFrame, window: int) -> dict[str, dict[str, float]]:
    """Per measure of :data:`DRIFT_MEASURES`: largest value, first revolution, largest over the
    first and last windows of the steady revolutions and their ratio, trend, final value."""
    out = {}
    for key in DRIFT_MEASURES:
        y = rows[key].to_numpy(dtype=float)
        if not np.isfinite(y).any():
            continue
        magnitude = np.abs(steady[key].to_numpy(dtype=float))
        first = float(np.nanmax(magnitude[:window]))
        last = float(np.nanmax(magnitude[-window:]))
        trend = linear_trend(steady["revolution"].to_numpy(), steady[key].to_numpy(dtype=float))
        out[key] = {
            "max_abs": float(np.nanmax(np.abs(y))),
            "first_revolution": float(y[0]),
            "first_window_max_abs": first,
            "last_window_max_abs": last,
            "growth_ratio": last / first if first > 0 else float("nan"),
            "trend_per_1000_revolutions": 1000.0 * trend["slope"],
            "final": float(y[-1]),
        }
    return out


def efficiency_figures(rows: pd.DataFrame, steady: pd.DataFrame, window: int) -> dict[str, float]:
    """The per-revolution efficiency: first revolution, mean, scatter and trend after the
    start-up, means of the first and last windows."""
    eta = steady["efficiency"].to_numpy(dtype=float)
    trend = linear_trend(steady["revolution"].to_numpy(), eta)
    span = float(steady["revolution"].iloc[-1] - steady["revolution"].iloc[0])
    return {
        "startup_revolutions": STARTUP_REVOLUTIONS,
        "first_revolution": float(rows["efficiency"].iloc[0]),
        "mean": float(np.mean(eta)),
        "scatter": trend["scatter"],
        "trend_per_1000_revolutions": 1000.0 * trend["slope"],
        "trend_stderr_per_1000_revolutions": 1000.0 * trend["slope_stderr"],
        "trend_over_run": trend["slope"] * span,
        **first_last(eta, window),
    }


def drift_summary(rows: pd.DataFrame, info: dict[str, Any]) -> dict[str, Any]:
    """A drift run's figures: its ``info`` with the measures, the efficiency, and the spacing of
    doubles at the largest input angle coordinate [rad] (the resolution of the Rxyz input angle)."""
    out: dict[str, Any] = dict(info)
    if len(rows) < STARTUP_REVOLUTIONS + 3:
        return out
    steady = rows.iloc[STARTUP_REVOLUTIONS:]
    window = window_size(len(steady))
    out.update(revolutions=len(rows), window=window, measures=measure_figures(rows, steady, window),
               efficiency=efficiency_figures(rows, steady, window))
    # the largest input angle coordinate the solver had (kept within pi by the post-step wrap)
    out["input_angle_spacing_rad"] = float(np.spacing(info.get("input_coordinate_max_abs_rad",
                                                               2.0 * math.pi * len(rows))))
    return out


def _ok_exudyn_cases(cases: list[dict[str, Any]], angle: float) -> list[dict[str, Any]]:
    return [c for c in cases if c["engine"] == ENGINE and c["shaft_angle_deg"] == angle
            and c["status"] == Status.OK and c.get("loss_per_revolution", 0) > 0]


def step_ladder(cases: list[dict[str, Any]], angle: float) -> list[dict[str, Any]]:
    """The angle's Exudyn cases that ran at the default spectral radius, by step count."""
    return sorted((c for c in _ok_exudyn_cases(cases, angle) if c["spectral_radius"] == DEFAULT_RHO),
                  key=lambda c: c["steps_per_revolution"])


def rho_ladder(cases: list[dict[str, Any]], angle: float) -> list[dict[str, Any]]:
    """The angle's Exudyn cases at :data:`RHO_LADDER_STEPS` steps per revolution, by spectral radius."""
    return sorted((c for c in _ok_exudyn_cases(cases, angle)
                   if c["nominal_steps_per_revolution"] == RHO_LADDER_STEPS),
                  key=lambda c: c["spectral_radius"])


def fit_dissipation(cases: list[dict[str, Any]], angle: float) -> dict[str, Any]:
    """Order in h of the loss at the default spectral radius, K of ``loss = K c(rho) h^3``, and
    the loss against the spectral radius relative to the default's, measured and in theory."""
    out: dict[str, Any] = {"shaft_angle_deg": angle}
    ladder = step_ladder(cases, angle)
    if len(ladder) >= 2:
        h = np.array([2 * math.pi / c["steps_per_revolution"] for c in ladder])
        loss = np.array([c["loss_per_revolution"] for c in ladder])
        out["order"] = float(np.polyfit(np.log(h), np.log(loss), 1)[0])
        out["order_between_neighbours"] = [float(math.log(loss[i + 1] / loss[i]) / math.log(h[i + 1] / h[i]))
                                           for i in range(len(h) - 1)]
    fit = [c for c in _ok_exudyn_cases(cases, angle) if RHO_MODEL[0] <= c["spectral_radius"] <= RHO_MODEL[1]]
    if fit:
        logs = [math.log(c["loss_per_revolution"] / (damping_coefficient(c["spectral_radius"])
                                                      * (2 * math.pi / c["steps_per_revolution"]) ** 3))
                for c in fit]
        out["K_fitted"] = float(math.exp(np.mean(logs)))
        out["K_fit_max_deviation"] = float(math.exp(np.max(np.abs(np.array(logs) - np.mean(logs)))) - 1)
    at_200 = {c["spectral_radius"]: c["loss_per_revolution"] for c in rho_ladder(cases, angle)}
    if DEFAULT_RHO in at_200:
        c0 = damping_coefficient(DEFAULT_RHO)
        out["rho_dependence"] = [{"spectral_radius": r, "measured_ratio": v / at_200[DEFAULT_RHO],
                                  "theory_ratio": damping_coefficient(r) / c0}
                                 for r, v in sorted(at_200.items())]
    return out


def findings(drift_out: dict[str, Any], cases: list[dict[str, Any]]) -> list[str]:
    """Plain sentences for what did not run through, and why where it is known."""
    out = []
    for node_type, info in drift_out.items():
        if info["status"] == Status.OK:
            continue
        text = (f"{node_type}: {info['status']} at revolution "
                f"{number(info.get('ended_at_revolution'), '.2f')} of {info.get('requested_revolutions')} "
                f"({info['reason']})")
        misalignment = info.get("measures", {}).get("angle_violation_rad", {})
        if node_type == "RotVecLG" and misalignment.get("last_window_max_abs", 0.0) > NEWTON_TOLERANCE:
            text += (f"; before it the axis misalignment grew to "
                     f"{misalignment['last_window_max_abs']:.2g} rad: " + ROTVEC_FAILURE)
        out.append(text)
    for c in cases:
        if c["status"] != Status.OK:
            text = (f"{c['case']}: {c['status']} after {c.get('completed_revolutions', 0)} "
                    f"revolutions ({c['reason']})")
            if c["engine"] == ENGINE and c["spectral_radius"] >= 0.99:
                text += ("; almost without numerical damping Exudyn's index-3 Newton iteration "
                         "fails (not investigated further: at 400 steps per revolution the 35 deg "
                         "case ran 100 revolutions in a side test; ExudynOptions refuses a spectral "
                         "radius of 1)")
            out.append(text)
    return out


def summarise(drift: pd.DataFrame, runs: list[dict[str, Any]], cases: list[dict[str, Any]],
              plan: LongRunPlan, walls: dict[str, float]) -> dict[str, Any]:
    """Settings, drift figures per node type, energy cases and fits per angle, findings, wall
    times [s]: the content of ``longrun_summary.json``."""
    drift_out = {}
    for info in runs:
        rows = drift[drift["node_type"] == info["node_type"]] if not drift.empty else drift
        drift_out[info["node_type"]] = drift_summary(rows.reset_index(drop=True), info)
    angles = sorted({c["shaft_angle_deg"] for c in cases})
    return {
        "settings": settings(plan),
        "drift": drift_out,
        "energy": {"cases": cases, "fits": {f"{a:g}": fit_dissipation(cases, a) for a in angles}},
        "findings": findings(drift_out, cases),
        "wall_time_s": walls,
    }
