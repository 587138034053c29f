"""The MuJoCo engine (optional: ``pip install mujoco``) for the frictionless Cardan joint.

MuJoCo's friction loss is a constant-magnitude joint friction; it cannot express the paper's
friction forces proportional to the pair reactions (eqs. (1)-(5)), so this engine refuses scenes
with friction. Importing this module needs MuJoCo; :mod:`cardan_exudyn.engines` imports it on
first use, so a missing MuJoCo makes only this engine unavailable.

The engine in four steps: the time step (:mod:`~cardan_exudyn.mujoco.timestep`), the MJCF model
(:mod:`~cardan_exudyn.mujoco.mjcf`), the time loop (:mod:`~cardan_exudyn.mujoco.simulate`) and
the result columns (:mod:`~cardan_exudyn.mujoco.table`). Defaults: the settings study of
``docs/mujoco.md`` (``python tests/benchmarks mujoco-settings``).

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3 (RCCC model, pair frames) and eq. (18).
MuJoCo documentation, "Computation" (soft constraints: impedance ``d``, reference acceleration
``a_ref = -b J v - k r``) and "Modeling / Solver parameters" (``solref``, ``solimp``).
"""

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
    """Simulate the frictionless ``scene`` with MuJoCo and return its time table and summary.

    Parameters
    ----------
    scene : Scene
        A scene with every friction coefficient zero.
    options : MujocoOptions, optional
        Solver settings; the defaults are the recommended ones (``docs/mujoco.md``).

    Returns
    -------
    Result
        The columns of :func:`reference.results.columns.table_columns` (pair forces and frame-pair
        reactions NaN, see :mod:`~cardan_exudyn.mujoco.table`) and the summary with the mean
        values.

    Raises
    ------
    NotImplementedError
        For scenes with friction (MuJoCo has no friction proportional to the reactions), with
        ``numerics.richardson``, or with a load history.    SceneError
        ``numerics.accuracy`` needs more steps than allowed
        (:func:`~cardan_exudyn.mujoco.timestep.choose_timestep`).
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
