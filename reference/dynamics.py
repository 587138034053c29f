"""Inverse dynamics of the ideal, frictionless Cardan joint: Newton-Euler, one linear solve per sample.

For a prescribed input motion the closed-form kinematics (:mod:`reference.kinematics`) give every
body's motion. Newton-Euler for the three moving bodies (force balance and moment balance about
the joint centre O, a fixed point) is then linear in the 18 unknowns

- ``frame_input`` (revolute): fx, fy, fz, mx, my;
- ``input_spider``, ``spider_output``, ``output_frame`` (cylindrical): fx, fy, mx, my;
- the drive torque on the input about +x,

each reaction being the force and moment (about the pair origin) that body ``a`` exerts on body
``b``, in the pair frame attached to body ``a`` (:func:`reference.kinematics.pair_frames`). Body
``b`` receives the wrench, body ``a`` its opposite. The 18 x 18 systems of all samples are solved
as one batch.

The pair origins are fixed in space in the ideal joint: ``frame_input`` at ``-input_bearing e_x``,
the two spider pairs at O and ``output_frame`` at ``output_bearing a2``, all on the rotation
axes of their bodies.

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3 (RCCC model, reactions in the joint frames, eqs. (8)-(9))
and eq. (18) (instantaneous efficiency).
"""

from __future__ import annotations

import math
import time

import numpy as np

from reference.kinematics import (
    BodyMotion,
    body_motions,
    output_motion,
    pair_frames,
    relative_speeds,
)
from reference.scene import (
    BODY_NAMES,
    PAIR_BODIES,
    PAIR_KIND,
    PAIR_NAMES,
    Body,
    Geometry,
    Scene,
    SpeedDrive,
    scene_to_dict,
)
from reference.schema import (
    PAIR_SUFFIXES,
    STATUS_OK,
    Result,
    instantaneous_efficiency,
    mean_values,
    table_columns,
)

ENGINE_NAME = "reference"
ENGINE_VERSION = "reference-0.1"
DEFAULT_SAMPLES_PER_REVOLUTION = 360
_COMPONENTS = {"revolute": ("fx", "fy", "fz", "mx", "my"), "cylindrical": ("fx", "fy", "mx", "my")}


def unknowns() -> list[tuple[str, str]]:
    """The 18 unknowns in solution order: ``(pair, component)`` and ``("drive", "torque_in")``."""
    out = [(pair, c) for pair in PAIR_NAMES for c in _COMPONENTS[PAIR_KIND[pair]]]
    return out + [("drive", "torque_in")]


def pair_origins(geometry: Geometry) -> dict[str, np.ndarray]:
    """Pair origins in global coordinates [m] (fixed in the ideal joint)."""
    return {
        "frame_input": np.array([-geometry.input_bearing, 0.0, 0.0]),
        "input_spider": np.zeros(3),
        "spider_output": np.zeros(3),
        "output_frame": geometry.output_bearing * geometry.output_axis(),
    }


def body_kinematics(body: Body, motion: BodyMotion) -> dict[str, np.ndarray]:
    """Centre-of-mass position, velocity, acceleration and inertia of a body, global components.

    Parameters
    ----------
    body : Body
        Mass properties; :meth:`Body.canonical` places them in the canonical body frame, whose
        origin is the joint centre O.
    motion : BodyMotion
        Orientation and angular motion of the body.

    Returns
    -------
    dict
        ``mass`` [kg]; ``r``, ``v``, ``a``: centre of mass relative to O [m], its velocity [m/s]
        and acceleration [m/s^2], shape (..., 3); ``inertia`` about the centre of mass
        [kg m^2], shape (..., 3, 3).
    """
    mass, com, inertia = body.canonical()
    rot = motion.rotation
    r = rot @ com
    v = np.cross(motion.omega, r)
    a = np.cross(motion.alpha, r) + np.cross(motion.omega, v)
    return {"mass": mass, "r": r, "v": v, "a": a,
            "inertia": rot @ inertia @ np.swapaxes(rot, -1, -2)}


def required_wrench(body: Body, motion: BodyMotion,
                    gravity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force [N] and moment about O [N m] the pairs, drive and load must apply to a body.

    Newton-Euler with gravity moved to the left: ``F = m (a_c - g)``,
    ``M_O = r_c x F + J alpha + omega x J omega`` (J about the centre of mass, global axes).
    """
    k = body_kinematics(body, motion)
    force = k["mass"] * (k["a"] - gravity)
    j_omega = np.einsum("...ij,...j->...i", k["inertia"], motion.omega)
    j_alpha = np.einsum("...ij,...j->...i", k["inertia"], motion.alpha)
    return force, np.cross(k["r"], force) + j_alpha + np.cross(motion.omega, j_omega)


def mechanical_energy(scene: Scene,
                      motions: dict[str, BodyMotion]) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy of the three bodies [J] (potential zero at O)."""
    gravity = np.asarray(scene.gravity)
    kinetic, potential = 0.0, 0.0
    for name, body in scene.joint.bodies():
        k = body_kinematics(body, motions[name])
        w = motions[name].omega
        j_omega = np.einsum("...ij,...j->...i", k["inertia"], w)
        kinetic = kinetic + 0.5 * k["mass"] * np.sum(k["v"] ** 2, -1) + 0.5 * np.sum(w * j_omega, -1)
        potential = potential - k["mass"] * (k["r"] @ gravity)
    return kinetic, potential


def _unit_wrench(frame: np.ndarray, origin: np.ndarray, component: str) -> np.ndarray:
    """Wrench (force, moment about O), shape (..., 6), of one unit reaction component on body b."""
    d = frame[..., :, "xyz".index(component[1])]
    if component[0] == "f":
        return np.concatenate([d, np.cross(origin, d)], -1)
    return np.concatenate([np.zeros_like(d), d], -1)


def reaction_system(scene: Scene,
                    motions: dict[str, BodyMotion]) -> tuple[np.ndarray, np.ndarray]:
    """Newton-Euler equations of the three bodies as ``matrix @ unknowns = rhs``.

    Returns
    -------
    matrix : ndarray, shape (..., 18, 18)
        Rows: per body (input, spider, output) force x, y, z [N] and moment about O x, y, z
        [N m]; columns: :func:`unknowns`.
    rhs : ndarray, shape (..., 18)
        Required wrench minus the known applied wrench (the load torque on the output).
    """
    shape = motions["input"].omega.shape[:-1]
    rows = {name: 6 * i for i, name in enumerate(BODY_NAMES)}
    matrix = np.zeros(shape + (18, 18))
    frames = pair_frames(motions)
    origins = pair_origins(scene.joint.geometry)
    for j, (pair, component) in enumerate(unknowns()[:-1]):
        unit = _unit_wrench(frames[pair], origins[pair], component)
        a, b = PAIR_BODIES[pair]
        if b in rows:
            matrix[..., rows[b]:rows[b] + 6, j] += unit
        if a in rows:
            matrix[..., rows[a]:rows[a] + 6, j] -= unit
    matrix[..., rows["input"] + 3, -1] = 1.0  # drive torque about +x (the fixed input axis)
    rhs = np.concatenate([np.concatenate(required_wrench(body, motions[name],
                                                         np.asarray(scene.gravity)), -1)
                          for name, body in scene.joint.bodies()], -1)
    # the load's moment -T a2 on the output, moved to the right-hand side
    rhs[..., rows["output"] + 3:rows["output"] + 6] += (scene.load.torque
                                                       * scene.joint.geometry.output_axis())
    return matrix, rhs


def inverse_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray) -> dict[str, np.ndarray]:
    """Result-schema columns (without ``t``) for a prescribed input motion, no friction.

    Parameters
    ----------
    scene : Scene
        Joint, load and gravity (the drive is replaced by the given motion).
    theta, theta_t, theta_tt : ndarray, shape (n,)
        Input angle [rad], speed [rad/s] and acceleration [rad/s^2].

    Returns
    -------
    dict of str to ndarray, shape (n,)
        Every column of :func:`reference.schema.table_columns` but ``t``; friction and loss
        columns are zero.
    """
    beta = scene.joint.geometry.shaft_angle
    motions = body_motions(theta, theta_t, theta_tt, beta)
    matrix, rhs = reaction_system(scene, motions)
    solution = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    theta_out, omega_out, _ = output_motion(theta, theta_t, theta_tt, beta)
    zero = np.zeros_like(theta_out)
    cols = {"theta_in": theta + zero, "theta_out": theta_out, "omega_in": theta_t + zero,
            "omega_out": omega_out, "torque_in": solution[..., -1],
            "torque_out": zero + scene.load.torque}
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * omega_out
    cols["power_loss"] = zero
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], zero)
    cols["energy_kinetic"], cols["energy_potential"] = mechanical_energy(scene, motions)
    omega_rel = relative_speeds(motions)
    for pair in PAIR_NAMES:
        cols[f"power_loss_{pair}"] = zero
        cols.update({f"{pair}_{suffix}": zero for suffix in PAIR_SUFFIXES})
        cols[f"{pair}_omega_rel"] = omega_rel[pair]
    for j, (pair, component) in enumerate(unknowns()[:-1]):
        cols[f"{pair}_{component}"] = solution[..., j]
    return cols


def drive_samples(scene: Scene, samples_per_revolution: int) -> tuple[np.ndarray, ...]:
    """Sample times [s] and input angle [rad], speed [rad/s], acceleration [rad/s^2].

    The span of ``scene.revolutions`` input revolutions from t = 0 is cut into
    ``round(revolutions * samples_per_revolution)`` equal steps, both ends included.
    """
    drive = scene.drive
    if not isinstance(drive, SpeedDrive):
        raise NotImplementedError(
            f"the reference engine handles only constant-speed drives so far, got a "
            f"{drive.kind!r} drive"
        )
    spr = samples_per_revolution
    if isinstance(spr, bool) or not isinstance(spr, (int, np.integer)) or spr < 1:
        raise ValueError(f"`samples_per_revolution` must be a positive integer, got {spr!r}")
    steps = max(1, round(scene.revolutions * spr))
    t = np.linspace(0.0, 2.0 * math.pi * scene.revolutions / abs(drive.speed), steps + 1)
    return t, drive.speed * t, np.full_like(t, drive.speed), np.zeros_like(t)


def run(scene: Scene, samples_per_revolution: int = DEFAULT_SAMPLES_PER_REVOLUTION) -> Result:
    """Inverse dynamics of ``scene`` (constant-speed drive, no friction) in the result schema.

    Parameters
    ----------
    scene : Scene
        The scene (constant-speed drive, every friction coefficient zero).
    samples_per_revolution : int
        Samples per input revolution [-].

    Returns
    -------
    Result
        Time table (every ``scene.record.every``-th sample, or None) and summary with the mean
        values of :func:`reference.schema.mean_values` over all samples.

    Raises
    ------
    NotImplementedError
        For angle and torque drives, and for scenes with friction (not implemented yet: a
        friction-free answer to a friction scene would be a silent wrong result).
    """
    if scene.has_friction:
        raise NotImplementedError(
            "friction in the reference engine is not implemented yet (issue 4); use a "
            "'-frictionless' scene or --friction-spider 0 --friction-frame 0")
    start = time.perf_counter()
    t, theta, theta_t, theta_tt = drive_samples(scene, samples_per_revolution)
    columns = {"t": t, **inverse_dynamics(scene, theta, theta_t, theta_tt)}
    summary = {"status": STATUS_OK, "reason": "", "engine": ENGINE_NAME,
               "engine_version": ENGINE_VERSION, "scene": scene_to_dict(scene),
               "samples_per_revolution": int(samples_per_revolution), "dt": float(t[1] - t[0]),
               "steps": int(t.size - 1)}
    means = mean_values(columns, scene.record.skip_revolutions)
    if means.get("revolutions", 0) < 1:
        summary.update(status="no_whole_revolution", reason=means.get("mean_status", ""))
    summary.update({k: v for k, v in means.items() if k != "mean_status"})
    table = None
    if scene.record.timeseries:
        import pandas as pd

        every = scene.record.every
        table = pd.DataFrame({c: columns[c][::every] for c in table_columns()})
    summary["wall_time_s"] = time.perf_counter() - start
    return Result(table, summary)
