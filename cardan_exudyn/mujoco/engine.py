"""The MuJoCo engine (optional: ``pip install mujoco``) for the frictionless Cardan joint: MuJoCo's
constant joint friction cannot express friction proportional to the reactions (eqs. (1)-(5)).
Defaults: ``docs/mujoco.md``."""

from __future__ import annotations

import time
from dataclasses import asdict

import mujoco

from cardan_exudyn.mujoco.options import MujocoOptions
from cardan_exudyn.mujoco.simulate import simulate
from cardan_exudyn.mujoco.table import columns, constraint_violation
from cardan_exudyn.mujoco.timestep import choose_timestep
from reference.results.result import Result, result_table
from reference.results.summary import Status, Summary
from reference.scene import Scene, scene_to_dict

__all__ = ["ENGINE_NAME", "VIOLATION_LIMIT_RAD", "engine_version", "run"]

ENGINE_NAME = "mujoco"
VIOLATION_LIMIT_RAD = 1e-2
"""A loop that opens by more than this is no Cardan joint any more: the run is flagged [rad]."""


def engine_version() -> str:
    """MuJoCo's version."""
    return mujoco.__version__


def _refuse(scene: Scene) -> None:
    """``NotImplementedError`` for a scene this engine cannot express, saying which engine can."""
    if scene.has_friction:
        raise NotImplementedError(
            "MuJoCo cannot model the paper's friction (eqs. (1)-(5): friction forces "
            "proportional to the pair reactions); its frictionloss is a constant joint friction. "
            "Use the exudyn engine or a '-frictionless' scene")
    if scene.numerics.richardson:
        raise NotImplementedError("`numerics.richardson` is not implemented for MuJoCo (its RK4 with "
                                  "soft constraints has no O(h^2) error to extrapolate)")
    if not scene.load.constant:
        raise NotImplementedError("the MuJoCo engine takes a constant load torque only; a load "
                                  "history (measured brake torque) runs on exudyn or reference")


def _check_closure(summary: Summary) -> None:
    """Fail a run whose loop opened by more than :data:`VIOLATION_LIMIT_RAD`."""
    if summary.success and summary.max_constraint_violation_rad > VIOLATION_LIMIT_RAD:
        summary.fail(Status.CONSTRAINT_VIOLATED, (
            f"the output axis left its bearing by up to "
            f"{summary.max_constraint_violation_rad:.3g} rad (limit {VIOLATION_LIMIT_RAD:g}):"
            " the loop closure is too soft for this time step and these settings"))


def run(scene: Scene, options: MujocoOptions | None = None) -> Result:
    """Simulate the frictionless ``scene`` with MuJoCo.

    Parameters
    ----------
    scene : Scene
        Every friction coefficient zero, a constant load.
    options : MujocoOptions, optional
        Defaults: the recommended ones (``docs/mujoco.md``).

    Returns
    -------
    Result
        The table (pair forces and frame-pair reactions NaN) and the summary with the means.

    Raises
    ------
    NotImplementedError
        A scene with friction, ``numerics.richardson`` or a load history.
    SceneError
        ``numerics.accuracy`` needs more steps than allowed.
    """
    _refuse(scene)
    options = options or MujocoOptions()
    start = time.perf_counter()
    dt, why = choose_timestep(scene, options)
    record, status, reason = simulate(scene, options, dt)
    cols = columns(scene, record)
    summary = Summary(status, reason, engine=ENGINE_NAME, engine_version=engine_version(),
                      scene=scene_to_dict(scene), dt=dt, dt_choice=why, steps=int(record.t.size - 1),
                      options={**asdict(options), "solref": list(options.solref_for(dt))})
    violation = constraint_violation(scene, record)
    summary.max_constraint_violation_m = violation["max_constraint_violation_m"]
    summary.max_constraint_violation_rad = violation["max_constraint_violation_rad"]
    summary.extras["max_drive_error_rad"] = violation["max_drive_error_rad"]
    _check_closure(summary)  # before the means: a loop that does not hold explains whatever they say
    if summary.success:
        means = summary.whole_revolution_means(cols, scene.record.skip_revolutions)
        if means is not None:
            summary.set_means(means)
    table = result_table(cols, scene.record.every) if scene.record.timeseries else None
    summary.wall_time_s = time.perf_counter() - start
    return Result(table, summary)
