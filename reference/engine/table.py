"""The reference engine's time table: its instants, its columns, and what it says about the run."""

from __future__ import annotations

import math

import numpy as np

from reference.engine.dynamics import dynamics_columns
from reference.engine.motion import InputMotion
from reference.engine.options import ReferenceOptions
from reference.engine.periodic import period_rows, repeat_period
from reference.results.summary import Status, Summary
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene
from reference.scene.validation import check_steps

__all__ = ["EXTRA_COLUMNS", "columns_at", "table_columns", "table_times", "table_verdict"]

EXTRA_COLUMNS = ("input_acceleration", "friction_loop_gain", "self_locking",
                 *(f"{p}_slide" for p in PAIR_NAMES),
                 *(f"power_loss_{p}_{part}" for p in PAIR_NAMES for part in ("rotation", "sliding")))


def columns_at(scene: Scene, motion: InputMotion, t: np.ndarray,
               load: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """``t`` and every :func:`reference.engine.dynamics.dynamics_columns` column of ``scene`` driven by
    ``motion`` at instants ``t`` [s], under output ``load`` [N m] (None: the scene's load at ``t``).
    """
    theta, theta_t, theta_tt = motion.state(t)
    theta = np.broadcast_to(np.asarray(theta, float), np.shape(t))
    theta_t = np.broadcast_to(np.asarray(theta_t, float), np.shape(t))
    if load is None:
        load = scene.load.at(np.asarray(t, float))
    cols, _ = dynamics_columns(scene, theta, theta_t, theta_tt=theta_tt, load_torque=load,  # one of the two
                               torque_in=motion.torque_in if theta_tt is None else None)
    return {"t": np.asarray(t, float), **cols}


def table_columns(scene: Scene, motion: InputMotion, t: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`columns_at` on the table's instants ``t`` [s]; summary only: a periodic motion's first
    period repeated (:mod:`reference.engine.periodic`); a recorded table row by row.
    """
    rows = period_rows(t, scene.drive.speed) if motion.periodic and not scene.record.timeseries else None
    if rows is None:
        return columns_at(scene, motion, t)
    return repeat_period(columns_at(scene, motion, t[:rows]), t, scene.drive.speed)


def table_times(scene: Scene, motion: InputMotion, options: ReferenceOptions) -> np.ndarray:
    """Equispaced instants [s] of the time table over ``motion``'s span: ``options.samples_per_revolution``
    (None: ``scene.numerics.dt``, lining up with a fixed-step engine's rows, else 360); SceneError
    beyond :data:`reference.scene.validation.MAX_STEPS`.
    """
    span = motion.t_end - motion.t0
    if options.samples_per_revolution is None and scene.numerics.dt is not None:
        check_steps(span / scene.numerics.dt,
                    f"{scene.revolutions:g} revolutions at dt = {scene.numerics.dt:.3g} s")
        steps = max(1, math.ceil(span / scene.numerics.dt - 1e-9))  # as the Exudyn engine
    else:
        spr = options.samples_per_revolution or 360
        theta_a = motion.angle(motion.t0)
        theta_b = motion.angle(motion.t_end)
        check_steps(abs(theta_b - theta_a) / (2.0 * math.pi) * spr,
                    f"{scene.revolutions:g} revolutions at {spr} samples per revolution")
        steps = max(1, round(abs(theta_b - theta_a) / (2.0 * math.pi) * spr))
    return np.linspace(motion.t0, motion.t_end, steps + 1)


def table_verdict(t: np.ndarray, columns: dict[str, np.ndarray], summary: Summary,
                  origin: float = 0.0) -> None:
    """The table's step, sample count, self-locking samples and loop gain into ``summary`` (failed as
    ``self_locking`` when a sample locks), times shifted by ``origin`` [s].
    """
    locked = columns["self_locking"]
    summary.dt = float(t[1] - t[0])
    summary.steps = int(t.size - 1)
    summary.extras["self_locking_samples"] = int(np.count_nonzero(locked))
    summary.max_friction_loop_gain = float(np.max(columns["friction_loop_gain"]))
    if np.any(locked) and summary.success:
        first = int(np.argmax(locked))
        summary.fail(Status.SELF_LOCKING, (
            f"friction self-locks at {int(np.count_nonzero(locked))} of {locked.size} samples, "
            f"first at t = {t[first] + origin:.6g} s, input angle "
            f"{math.degrees(columns['theta_in'][first]):.6g} deg (loop gain "
            f"{columns['friction_loop_gain'][first]:.3g}): no consistent friction"))
