"""The MuJoCo engine's time loop. Each step runs ``mj_forward`` and ``mj_rnePostConstraint``, records,
then integrates, so every record (state, drive torque, reactions) belongs to one instant."""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from cardan_exudyn.mujoco.drive import DrivePlan, drive_plan, joint_state
from cardan_exudyn.mujoco.mjcf import BODY_IDS, mjcf
from cardan_exudyn.mujoco.options import MujocoOptions
from reference.results.summary import Status
from reference.scene import Scene, TorqueDrive

__all__ = ["RECORD_SHAPES", "Record", "simulate"]

RECORD_SHAPES = {"t": (), "q": (3,), "qd": (3,), "reference": (), "xmat": (3, 3, 3), "cvel": (3, 6),
                 "centre": (3,), "sites": (2, 3), "cfrc_int": (3, 6), "torque_in": ()}
"""Per-step shape of each field of :class:`Record`."""
LAG_ALLOWANCE = 0.01
"""Extra steps, as a fraction of the span's, for a prescribed input (it lags its reference) to reach
the scene's revolutions. Measured: docs/mujoco.md#a-what-mujocos-defaults-give."""


class Record:
    """Per-step copies of the mjData fields the table is computed from (shapes :data:`RECORD_SHAPES`,
    bodies input, spider, output): ``t`` [s]; hinge ``q`` [rad], ``qd`` [rad/s]; drive ``reference``
    angle [rad] (NaN: torque drive); body ``xmat``; ``cvel`` ``[omega, v(centre)]`` and ``cfrc_int``
    ``[moment about centre, force]`` from the parent, ``centre`` the input subtree's CoM [m]; bearing
    ``sites`` [m]; ``torque_in`` [N m]; ``size`` rows recorded."""

    def __init__(self, n: int) -> None:
        for name, shape in RECORD_SHAPES.items():
            setattr(self, name, np.zeros((n, *shape)))
        self.size = 0

    def take(self, d: Any, drive_row: int | None, torque: float) -> None:
        """Append ``d``'s state (after ``mj_forward``, ``mj_rnePostConstraint``); the drive torque is the
        force of constraint row ``drive_row``, or ``torque`` [N m] when that is None (torque drive)."""
        k = self.size
        bodies = slice(1, 4)
        self.t[k] = d.time
        self.q[k] = d.qpos[:3]
        self.qd[k] = d.qvel[:3]
        self.reference[k] = d.qpos[3] if drive_row is not None else np.nan
        self.xmat[k] = d.xmat[bodies].reshape(3, 3, 3)
        self.cvel[k] = d.cvel[bodies]
        self.centre[k] = d.subtree_com[BODY_IDS["input"]]
        self.sites[k] = d.site_xpos[:2]
        self.cfrc_int[k] = d.cfrc_int[bodies]
        self.torque_in[k] = d.efc_force[drive_row] if drive_row is not None else torque
        self.size += 1

    def trimmed(self) -> Record:
        """The record cut to the rows taken (in place)."""
        for name, value in vars(self).items():
            if isinstance(value, np.ndarray):
                setattr(self, name, value[:self.size])
        return self


def _integrate(m: Any, d: Any) -> None:
    """Advance one step from an mjData on which ``mj_forward`` has just run."""
    integrator = m.opt.integrator
    if integrator == mujoco.mjtIntegrator.mjINT_RK4:
        mujoco.mj_RungeKutta(m, d, 4)
    elif integrator == mujoco.mjtIntegrator.mjINT_EULER:
        mujoco.mj_Euler(m, d)
    elif integrator in (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST):
        mujoco.mj_implicit(m, d)
    else:  # "discrete" has no separate integration call: mj_step repeats the forward pass
        mujoco.mj_step(m, d)


def _initial_state(scene: Scene, plan: DrivePlan, d: Any) -> float:
    """Put the assembled joint, the load and the drive torque into ``d``; that torque [N m] (0 for a
    prescribed input)."""
    q0, qd0 = joint_state(scene, plan.theta0, plan.omega0)
    d.qpos[:3] = q0
    d.qvel[:3] = qd0
    a2 = scene.joint.geometry.output_axis()
    d.xfrc_applied[BODY_IDS["output"], 3:] = -scene.load.torque * a2
    torque = scene.drive.torque if isinstance(scene.drive, TorqueDrive) else 0.0
    d.qfrc_applied[0] = torque
    return torque


def _step_count(plan: DrivePlan, dt: float) -> int:
    """Most steps of the run: the span's, plus :data:`LAG_ALLOWANCE` of them for a prescribed input."""
    steps = max(1, math.ceil(plan.span / dt - 1e-9))
    if plan.motion is not None:
        steps += math.ceil(LAG_ALLOWANCE * steps)
    return steps


def _drive_row(d: Any, drive_id: int) -> int:
    """The constraint row of the drive equality (equality rows keep their place)."""
    return int(np.flatnonzero((d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
                              & (d.efc_id == drive_id))[0])


def _shortfall(scene: Scene, plan: DrivePlan, d: Any) -> str:
    """Why the run is incomplete when the input turned less than the scene's revolutions, else ""."""
    turned = abs(d.qpos[0] - plan.theta0)
    if turned < plan.turn - 1e-9:
        return (f"the input turned {turned / (2 * math.pi):.6g} of {scene.revolutions:g} "
                "revolutions in the time allowed")
    return ""


def simulate(scene: Scene, options: MujocoOptions, dt: float) -> tuple[Record, Status, str]:
    """``(record, status, reason)`` of running the MuJoCo model of ``scene`` at step ``dt`` [s]: one row
    per step; ``ok``, ``diverged`` or ``incomplete`` with its reason ("" when ok)."""
    plan = drive_plan(scene)
    m = mujoco.MjModel.from_xml_string(mjcf(scene, options, dt))
    d = mujoco.MjData(m)
    torque = _initial_state(scene, plan, d)
    steps = _step_count(plan, dt)
    record = Record(steps + 1)
    drive_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, "drive")
    drive_row = None
    for k in range(steps + 1):
        d.time = plan.start + k * dt
        if plan.motion is not None:
            angle, speed, acceleration = plan.motion(d.time)
            d.qpos[3] = angle
            d.qvel[3] = speed
            d.qfrc_applied[3] = options.reference_inertia * acceleration
        mujoco.mj_forward(m, d)
        mujoco.mj_rnePostConstraint(m, d)
        if plan.motion is not None and drive_row is None:
            drive_row = _drive_row(d, drive_id)
        record.take(d, drive_row, torque)
        if not math.isfinite(d.qvel @ d.qvel + d.qacc @ d.qacc):
            return record.trimmed(), Status.DIVERGED, f"non-finite state at t = {d.time:.6g} s (step {k})"
        if abs(d.qpos[0] - plan.theta0) >= plan.turn - 1e-12 or k == steps:
            break
        _integrate(m, d)
    reason = _shortfall(scene, plan, d)
    return record.trimmed(), Status.INCOMPLETE if reason else Status.OK, reason
