"""How the MuJoCo engine drives the input: the drive plan of a scene and the assembled initial
state of the three hinges."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reference.physics.kinematics import body_motions, rot_z
from reference.scene import AngleDrive, Scene, SpeedDrive, TorqueDrive

__all__ = ["DrivePlan", "drive_plan", "joint_state"]


def joint_state(scene: Scene, theta: float, theta_t: float) -> tuple[np.ndarray, np.ndarray]:
    """``(q, qd)``: assembled hinge angles [rad] and rates [rad/s] (input, spider, output) at input angle
    ``theta`` [rad] and speed ``theta_t`` [rad/s]; the output hinge angle ``phi`` from
    ``R_output = R_spider Rz(beta) Rz(phi)``."""
    beta = scene.joint.geometry.shaft_angle
    m = body_motions(np.array(theta), np.array(theta_t), np.array(0.0), beta)
    r_input, r_spider, r_output = (m[b].rotation for b in ("input", "spider", "output"))
    spider_relative = r_input.T @ r_spider
    output_relative = rot_z(np.array(-beta)) @ r_spider.T @ r_output
    gamma = math.atan2(spider_relative[0, 2], spider_relative[0, 0])
    phi = math.atan2(output_relative[1, 0], output_relative[0, 0])
    gamma_t = float((m["spider"].omega - m["input"].omega) @ r_input[:, 1])
    phi_t = float((m["output"].omega - m["spider"].omega) @ r_spider[:, 2])
    return np.array([theta, gamma, phi]), np.array([theta_t, gamma_t, phi_t])


@dataclass(frozen=True)
class DrivePlan:
    """How the input is driven: ``start`` and longest ``span`` [s]; ``motion(t) -> (angle [rad], speed
    [rad/s], acceleration [rad/s^2])`` of a prescribed input (None: torque drive); ``theta0`` [rad],
    ``omega0`` [rad/s] at the start; the ``turn`` [rad] after which the run stops."""

    start: float
    span: float
    motion: Callable[[float], tuple[float, float, float]] | None
    theta0: float
    omega0: float
    turn: float


def drive_plan(scene: Scene) -> DrivePlan:
    """The :class:`DrivePlan` of the scene's drive; ``NotImplementedError`` for an unknown kind."""
    drive = scene.drive
    turn = 2.0 * math.pi * scene.revolutions
    if isinstance(drive, SpeedDrive):
        w = drive.speed
        return DrivePlan(0.0, turn / abs(w), lambda t: (w * t, w, 0.0), 0.0, w, turn)
    if isinstance(drive, AngleDrive):
        spline = drive.spline()
        rates = (spline, spline.derivative(), spline.derivative(2))
        end = drive.time_to_turn(turn)
        start = drive.time[0]
        return DrivePlan(start, end - start, lambda s: tuple(float(f(s)) for f in rates),
                         float(spline(start)), float(rates[1](start)), turn)
    if isinstance(drive, TorqueDrive):
        # as the Exudyn engine: four times the time at the initial speed, stopped at `turn`
        return DrivePlan(0.0, drive.time_allowed(turn), None, 0.0, drive.initial_speed, turn)
    raise NotImplementedError(f"the MuJoCo engine cannot run a {type(drive).__name__}")
