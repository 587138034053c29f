"""Newton-Euler of the Cardan joint's three moving bodies, linear in 18 unknowns, batched over samples.

For a given input motion the kinematics (:func:`reference.physics.joint_motion.joint_motion`: closed
form for the ideal joint, the dual-number loop with mounting errors) give every body's motion.
Newton-Euler for the three moving bodies (force balance and moment balance about the global
origin O) is then linear in the 18 unknowns

- ``frame_input`` (revolute): fx, fy, fz, mx, my;
- ``input_spider``, ``spider_output``, ``output_frame`` (cylindrical): fx, fy, mx, my;
- the drive torque on the input about +x (inverse dynamics) or the input acceleration
  (forward dynamics, the drive torque given),

each reaction being the force and moment (about the pair origin) that body ``a`` exerts on body
``b``, in the pair frame attached to body ``a`` (:func:`reference.physics.kinematics.pair_frames`). Body
``b`` receives the wrench, body ``a`` its opposite.

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3 (RCCC model, reactions in the joint frames, eqs. (8)-(9)).
"""

from __future__ import annotations

import numpy as np

from reference.physics.joint_motion import JointMotion
from reference.physics.rccc.motion import BodyMotion
from reference.scene.joint import BODY_NAMES, PAIR_BODIES, PAIR_KIND, PAIR_NAMES, Body
from reference.scene.scene import Scene

__all__ = ["COMPONENTS", "DRIVE_ROW", "body_kinematics", "constant_load", "cross", "mass_kinematics",
           "mechanical_energy", "reaction_system", "required_wrench", "unknowns", "wrench_columns"]

DRIVE_ROW = 3  # the input's moment about x (rows: per body force x, y, z, moment x, y, z)
COMPONENTS = {"revolute": ("fx", "fy", "fz", "mx", "my"), "cylindrical": ("fx", "fy", "mx", "my")}


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis (``numpy.cross`` without its per-call overhead).

    Parameters
    ----------
    a, b : ndarray, shape (..., 3)
        Vectors, broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 3)
        ``a x b``.
    """
    a, b = np.broadcast_arrays(a, b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def unknowns() -> list[tuple[str, str]]:
    """The 18 unknowns in solution order: ``(pair, component)`` and ``("drive", "torque_in")``."""
    out = [(pair, c) for pair in PAIR_NAMES for c in COMPONENTS[PAIR_KIND[pair]]]
    return out + [("drive", "torque_in")]


def body_kinematics(body: Body, motion: BodyMotion) -> dict[str, np.ndarray]:
    """Centre-of-mass position, velocity, acceleration and inertia of a body, global components.

    Parameters
    ----------
    body : Body
        Mass properties; :meth:`Body.canonical` places them in the canonical body frame, whose
        origin is the body's frame origin (the joint centre O for the ideal joint).
    motion : reference.physics.rccc.motion.BodyMotion
        Pose and motion of the body.

    Returns
    -------
    dict
        ``mass`` [kg]; ``r``, ``v``, ``a``: centre of mass relative to O [m], its velocity [m/s]
        and acceleration [m/s^2], shape (..., 3); ``inertia`` about the centre of mass
        [kg m^2], shape (..., 3, 3).
    """
    return mass_kinematics(*body.canonical(), motion)


def mass_kinematics(mass: float | np.ndarray, com: np.ndarray, inertia: np.ndarray,
                    motion: BodyMotion) -> dict[str, np.ndarray]:
    """:func:`body_kinematics` from the canonical mass properties (:meth:`Body.canonical`).

    Parameters
    ----------
    mass : float or ndarray, shape (...,)
        Mass [kg].
    com : ndarray, shape (3,) or (..., 3)
        Centre of mass in the canonical body frame [m].
    inertia : ndarray, shape (3, 3) or (..., 3, 3)
        Inertia about the centre of mass, canonical body axes [kg m^2]; one per sample for many
        scenes in one pass (:mod:`reference.engine.batch.model`).
    motion : reference.physics.rccc.motion.BodyMotion
        Pose and motion of the body.

    Returns
    -------
    dict
        As :func:`body_kinematics`.
    """
    rot = motion.rotation
    c = rot @ com if np.ndim(com) == 1 else np.einsum("...ij,...j->...i", rot, com)
    w_c = cross(motion.omega, c)
    return {"mass": mass, "r": motion.origin + c, "v": motion.velocity + w_c,
            "a": motion.acceleration + cross(motion.alpha, c) + cross(motion.omega, w_c),
            "inertia": rot @ inertia @ np.swapaxes(rot, -1, -2)}


def required_wrench(body: Body, motion: BodyMotion,
                    gravity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force and moment about O the pairs, drive and load must apply to a body.

    Newton-Euler with gravity moved to the left: ``F = m (a_c - g)``,
    ``M_O = r_c x F + J alpha + omega x J omega`` (J about the centre of mass, global axes).

    Parameters
    ----------
    body : Body
        Mass properties.
    motion : reference.physics.rccc.motion.BodyMotion
        Pose and motion of the body.
    gravity : ndarray, shape (3,) or (..., 3)
        Gravitational acceleration [m/s^2].

    Returns
    -------
    force : ndarray, shape (..., 3)
        [N].
    moment : ndarray, shape (..., 3)
        About O [N m].
    """
    k = body_kinematics(body, motion)
    force = k["mass"] * (k["a"] - gravity)
    j_omega = np.einsum("...ij,...j->...i", k["inertia"], motion.omega)
    j_alpha = np.einsum("...ij,...j->...i", k["inertia"], motion.alpha)
    return force, cross(k["r"], force) + j_alpha + cross(motion.omega, j_omega)


def mechanical_energy(scene: Scene,
                      motions: dict[str, BodyMotion]) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy of the three bodies.

    Parameters
    ----------
    scene : Scene
        Mass properties and gravity.
    motions : dict of str to BodyMotion
        Each body's motion (:attr:`reference.physics.joint_motion.JointMotion.bodies`).

    Returns
    -------
    kinetic, potential : ndarray, shape (...)
        [J]; the potential is zero at O.
    """
    gravity = np.asarray(scene.gravity)
    kinetic = 0.0
    potential = 0.0
    for name, body in scene.joint.bodies():
        k = body_kinematics(body, motions[name])
        w = motions[name].omega
        j_omega = np.einsum("...ij,...j->...i", k["inertia"], w)
        kinetic = kinetic + 0.5 * k["mass"] * np.sum(k["v"] ** 2, -1) + 0.5 * np.sum(w * j_omega, -1)
        potential = potential - k["mass"] * (k["r"] @ gravity)
    return kinetic, potential


def wrench_columns(motion: JointMotion, components: list[tuple[str, str]]) -> np.ndarray:
    """Body wrenches of unit pair loads.

    Each component ``(pair, "fx" | "fy" | "fz" | "mx" | "my" | "mz")`` is a unit force along
    (at the pair origin) or moment about that axis of the pair frame, acting on body b; body a
    receives the opposite. All components are built in one vectorised pass.

    Parameters
    ----------
    motion : JointMotion
        Pair frames and origins, per sample.
    components : list of (pair, component)
        The m unit loads.

    Returns
    -------
    ndarray, shape (..., 18, m)
        Rows as :func:`reaction_system`'s [N, N m per unit load].
    """
    shape = motion.bodies["input"].omega.shape[:-1]
    if not components:
        return np.zeros(shape + (6 * len(BODY_NAMES), 0))
    d = np.stack([motion.frames[p][..., :, "xyz".index(c[1])] for p, c in components], -2)
    is_force = np.array([c[0] == "f" for _, c in components])[:, None]
    lever = np.stack([motion.origins[p] for p, _ in components], -2)
    unit = np.concatenate([np.where(is_force, d, 0.0),
                           np.where(is_force, cross(lever, d), d)], -1)  # (..., m, 6)
    incidence = np.zeros((len(BODY_NAMES), len(components)))
    for j, (pair, _) in enumerate(components):
        a, b = PAIR_BODIES[pair]
        for body, sign in ((b, 1.0), (a, -1.0)):
            if body in BODY_NAMES:
                incidence[BODY_NAMES.index(body), j] = sign
    out = np.einsum("bm,...mk->...bkm", incidence, unit)
    return out.reshape(shape + (6 * len(BODY_NAMES), len(components)))


def reaction_system(scene: Scene, motion: JointMotion,
                    load_torque: float | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Newton-Euler equations of the three bodies as ``matrix @ unknowns = rhs``.

    Parameters
    ----------
    scene : Scene
        Bodies and gravity (and the constant load).
    motion : JointMotion
        The joint's motion, per sample.
    load_torque : float or ndarray, shape (...), or None
        The output load at these samples [N m]; None: the scene's constant load (a history
        needs it given: the motion has no time).

    Returns
    -------
    matrix : ndarray, shape (..., 18, 18)
        Rows: per body (input, spider, output) force x, y, z [N] and moment about O x, y, z
        [N m]; columns: :func:`unknowns`.
    rhs : ndarray, shape (..., 18)
        Required wrench minus the known applied wrench (the load torque on the output).
    """
    shape = motion.bodies["input"].omega.shape[:-1]
    rows = {name: 6 * i for i, name in enumerate(BODY_NAMES)}
    matrix = np.zeros(shape + (18, 18))
    matrix[..., :-1] = wrench_columns(motion, unknowns()[:-1])
    matrix[..., rows["input"] + DRIVE_ROW, -1] = 1.0  # drive torque about +x (the fixed input axis)
    rhs = np.concatenate([np.concatenate(required_wrench(body, motion.bodies[name],
                                                         np.asarray(scene.gravity)), -1)
                          for name, body in scene.joint.bodies()], -1)
    # the load's moment -T u on the output (u its axis, the output_frame pair's z), to the right
    load = np.asarray(constant_load(scene) if load_torque is None else load_torque, float)
    rhs[..., rows["output"] + 3:rows["output"] + 6] += (load[..., None]
                                                       * motion.frames["output_frame"][..., :, 2])
    return matrix, rhs


def constant_load(scene: Scene) -> float:
    """The scene's load torque [N m]; a history needs the instants, so it is refused here."""
    if not scene.load.constant:
        raise ValueError("the scene's load is a torque history: pass `load_torque` for the samples")
    return float(scene.load.torque)
