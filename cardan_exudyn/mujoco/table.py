"""The MuJoCo engine's result columns and constraint measures from its per-step records. Its supports
are not the RCCC pairs: pair forces and frame-pair reactions are NaN, the spider pairs' moments
filled (``docs/mujoco.md#reactions``); friction columns zero."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from cardan_exudyn.mujoco.mjcf import BODY_IDS
from reference.physics.kinematics import pair_frames_in_body_a
from reference.results.columns import instantaneous_efficiency
from reference.scene.joint import PAIR_BODIES, PAIR_NAMES
from reference.scene.scene import Scene

if TYPE_CHECKING:
    from cardan_exudyn.mujoco.simulate import Record

__all__ = ["FILLED_REACTIONS", "mechanical_energy", "pair_columns", "columns", "constraint_violation"]

FILLED_REACTIONS = ("input_spider", "spider_output")
"""Pairs whose moments (mx, my, mz) are filled; the other reaction columns are NaN."""


def _point_velocity(cvel: np.ndarray, centre: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Velocity [m/s] of a body point from MuJoCo's com-based velocity ``[omega, v(centre)]``."""
    return cvel[:, 3:] + np.cross(cvel[:, :3], point - centre)


def _body_motion(record: Record) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Rotation matrices (columns: canonical axes) and angular velocities [rad/s], ground included."""
    n = record.t.size
    rot = {"ground": np.broadcast_to(np.eye(3), (n, 3, 3))}
    omega = {"ground": np.zeros((n, 3))}
    for name, i in BODY_IDS.items():
        rot[name] = record.xmat[:, i - 1]
        omega[name] = record.cvel[:, i - 1, :3]
    return rot, omega


def mechanical_energy(scene: Scene, record: Record) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy [J] of the three bodies per record row."""
    rot, omega = _body_motion(record)
    kinetic = np.zeros(record.t.size)
    potential = np.zeros(record.t.size)
    for name, i in BODY_IDS.items():
        mass, com, inertia = getattr(scene.joint, name).canonical()
        r = rot[name] @ com
        v = _point_velocity(record.cvel[:, i - 1], record.centre, r)
        j_omega = np.einsum("nij,jk,nlk,nl->ni", rot[name], inertia, rot[name], omega[name])
        kinetic += 0.5 * mass * np.sum(v * v, 1) + 0.5 * np.sum(omega[name] * j_omega, 1)
        potential -= mass * (r @ np.asarray(scene.gravity))
    return kinetic, potential


def _pair_points(scene: Scene, record: Record) -> dict[str, np.ndarray]:
    """Origin of each pair in the world [m], shape (n, 3): frame pairs at their bearings, spider pairs
    at O."""
    n = record.t.size
    geo = scene.joint.geometry
    return {"frame_input": np.broadcast_to([-geo.input_bearing, 0.0, 0.0], (n, 3)),
            "input_spider": np.zeros((n, 3)), "spider_output": np.zeros((n, 3)),
            "output_frame": record.sites[:, 1]}


def pair_columns(scene: Scene, record: Record) -> dict[str, np.ndarray]:
    """Per pair ``_omega_rel`` [rad/s], ``_slide_rel`` [m/s], zero friction and loss columns, and the
    reactions ``fx, fy, fz`` [N], ``mx, my, mz`` [N m] in the pair frame (NaN where not filled)."""
    n = record.t.size
    rot, omega = _body_motion(record)
    points = _pair_points(scene, record)
    local = pair_frames_in_body_a()
    cols = {}
    for pair in PAIR_NAMES:
        a, b = PAIR_BODIES[pair]
        frame = rot[a] @ local[pair]
        velocity = {body: np.zeros((n, 3)) if body == "ground" else
                    _point_velocity(record.cvel[:, BODY_IDS[body] - 1], record.centre, points[pair])
                    for body in (a, b)}
        cols[f"{pair}_omega_rel"] = np.sum((omega[b] - omega[a]) * frame[:, :, 2], 1)
        cols[f"{pair}_slide_rel"] = np.sum((velocity[b] - velocity[a]) * frame[:, :, 2], 1)
        cols.update({key: np.zeros(n) for key in (f"power_loss_{pair}", f"{pair}_friction_torque",
                                                  f"{pair}_friction_force")})
        cols.update({f"{pair}_{c}": np.full(n, np.nan) for c in ("fx", "fy", "fz", "mx", "my", "mz")})
        if pair in FILLED_REACTIONS:  # the wrench a exerts on b, moved to the pair origin
            wrench = record.cfrc_int[:, BODY_IDS[b] - 1]
            moment = wrench[:, :3] + np.cross(record.centre - points[pair], wrench[:, 3:])
            local_moment = np.einsum("nji,nj->ni", frame, moment)
            cols.update({f"{pair}_{c}": local_moment[:, i] for i, c in enumerate(("mx", "my", "mz"))})
    return cols


def columns(scene: Scene, record: Record) -> dict[str, np.ndarray]:
    """The result schema's columns, one row per record row."""
    n = record.t.size
    geo = scene.joint.geometry
    y_out = record.xmat[:, BODY_IDS["output"] - 1, :, 1]
    y_ref = np.array([-math.sin(geo.shaft_angle), math.cos(geo.shaft_angle), 0.0])
    cols = {"t": record.t, "theta_in": record.q[:, 0], "omega_in": record.qd[:, 0],
            "theta_out": np.unwrap(np.arctan2(y_out[:, 2], y_out @ y_ref)),
            "omega_out": record.cvel[:, BODY_IDS["output"] - 1, :3] @ geo.output_axis(),
            "torque_in": record.torque_in, "torque_out": np.full(n, scene.load.torque)}
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * cols["omega_out"]
    cols["power_loss"] = np.zeros(n)
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], cols["power_loss"])
    kinetic, potential = mechanical_energy(scene, record)
    cols["energy_kinetic"] = kinetic
    cols["energy_potential"] = potential
    cols.update(pair_columns(scene, record))
    return cols


def constraint_violation(scene: Scene, record: Record) -> dict[str, float]:
    """Largest ``max_constraint_violation_m`` (output bearing from its ground place [m]),
    ``max_constraint_violation_rad`` (output axis from ``a2``) and ``max_drive_error_rad`` (NaN for
    a torque drive)."""
    drift = np.linalg.norm(record.sites[:, 1] - record.sites[:, 0], axis=1)
    axis = record.xmat[:, BODY_IDS["output"] - 1, :, 0]
    tilt = np.linalg.norm(np.cross(axis, scene.joint.geometry.output_axis()), axis=1)
    lag = np.abs(record.q[:, 0] - record.reference)
    return {"max_constraint_violation_m": float(np.max(drift)),
            "max_constraint_violation_rad": float(np.max(tilt)),
            "max_drive_error_rad": float(np.max(lag)) if np.all(np.isfinite(lag)) else float("nan")}
