"""One cell of ``cardan stress``'s map measured: the reference's verdict, and Exudyn at the cell's
step ``h`` and (ok with friction) at ``h / 2``, as flat scalars for :mod:`.classify`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.engines import run
from cardan_exudyn.model.stepsize import error_coefficient
from cardan_exudyn.studies.stress.classify import RATIO_FLOOR, SAFETY
from cardan_exudyn.studies.stress.panels import ENGINE, REFERENCE
from reference.engine import ReferenceOptions
from reference.engine.motion import input_motion
from reference.engine.table import columns_at
from reference.physics.kinematics import speed_ratio
from reference.results.summary import Summary
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["REFERENCE_OPTIONS", "reference_measures", "exudyn_measures", "exact_ratio",
           "ratio_error", "measure_cell", "cell"]

REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=72, quadrature_rtol=1e-8)
"""The reference engine's settings in every cell."""


def reference_measures(scene: Scene) -> dict[str, Any]:
    """The reference engine's verdict on the cell: status, reason, efficiency, loop gain."""
    s = run(replace(scene, **{"record.timeseries": False}), REFERENCE, REFERENCE_OPTIONS).summary
    return {"ref_status": s.status.value, "ref_reason": str(s.reason or ""),
            "ref_efficiency": s.mean_efficiency, "ref_loop_gain_max": s.max_friction_loop_gain}


def exudyn_measures(s: Summary) -> dict[str, Any]:
    """Exudyn's status, efficiency, friction loop gain, cost and constraint violations."""
    return {"exu_status": s.status.value, "exu_reason": str(s.reason or "")[:300],
            "exu_efficiency": s.mean_efficiency, "exu_loop_gain_max": s.max_friction_loop_gain,
            "exu_steps": s.steps, "exu_newton_iterations": s.newton_iterations,
            "exu_wall_s": s.wall_time_s,
            "constraint_violation_m": s.max_constraint_violation_m,
            "constraint_violation_rad": s.max_constraint_violation_rad}


def exact_ratio(scene: Scene, t: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Exact ``omega_out / omega_in`` [-] of ``scene`` at instants ``t`` [s] and input angles ``theta``
    [rad]: Hooke's closed form for the ideal joint, the reference's RCCC kinematics with mounting errors.
    """
    if not scene.joint.errors.any:
        return speed_ratio(theta, scene.joint.geometry.shaft_angle)
    exact = columns_at(scene, input_motion(scene, REFERENCE_OPTIONS), t)
    return exact["omega_out"] / exact["omega_in"]


def ratio_error(table: pd.DataFrame, scene: Scene) -> float | None:
    """Largest error [-] of ``omega_out / omega_in`` of time ``table`` against :func:`exact_ratio` of
    ``scene``; None when not finite.
    """
    ratio = table["omega_out"].to_numpy() / table["omega_in"].to_numpy()
    err = np.abs(ratio - exact_ratio(scene, table["t"].to_numpy(), table["theta_in"].to_numpy()))
    return float(np.max(err)) if np.all(np.isfinite(err)) else None


def measure_cell(scene: Scene, node_type: str) -> dict[str, Any]:
    """Run the reference and Exudyn (``node_type``; at ``h`` and, ok with friction, ``h / 2``) on a
    cell's ``scene``: statuses, reasons, efficiencies and loop gains [-], Exudyn's cost, wall time
    [s] and constraint violations [m], [rad], ``ratio_error`` and ``ratio_promise`` [-], as flat scalars.
    """
    out = reference_measures(scene)
    result = run(scene, ENGINE, node_type=node_type)
    out.update(exudyn_measures(result.summary))
    h = scene.drive.speed * scene.numerics.dt  # [rad] of input angle per step
    out["ratio_promise"] = (SAFETY * error_coefficient(scene.joint.geometry.shaft_angle, node_type)
                            * h * h + RATIO_FLOOR)
    if result.table is not None and len(result.table):
        out["ratio_error"] = ratio_error(result.table, scene)
    if result.success and scene.has_friction:
        half = run(replace(scene, **{"numerics.dt": scene.numerics.dt / 2, "record.timeseries": False}),
                   ENGINE, node_type=node_type).summary
        out.update(half_status=half.status.value, exu_efficiency_half=half.mean_efficiency)
    return out


def cell(scene: Scene, engine: str, node_type: str) -> dict[str, Any]:
    """Sweep case function: :func:`measure_cell` of ``scene`` (``engine``: Exudyn) at ``node_type``."""
    if engine != ENGINE:
        raise ValueError(f"stress cells compare {ENGINE} with the {REFERENCE}; engine {engine!r}")
    return measure_cell(scene, node_type)
