"""Newton-Euler of the Cardan joint's three moving bodies, linear in 18 unknowns, batched over samples.

Force and moment balance about the global origin O, given every body's motion, is linear in

- ``frame_input`` (revolute): fx, fy, fz, mx, my;
- ``input_spider``, ``spider_output``, ``output_frame`` (cylindrical): fx, fy, mx, my;
- the drive torque on the input about +x (inverse dynamics) or the input acceleration (forward),

each reaction the force and moment (about the pair origin) body ``a`` exerts on body ``b``, in the
pair frame attached to ``a``; body ``a`` receives the opposite (the paper's Section 3, eqs. (8)-(9)).
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
    """``a x b`` over the last axis, broadcast (``numpy.cross`` without its per-call overhead)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def unknowns() -> list[tuple[str, str]]:
    """The 18 unknowns in solution order: ``(pair, component)`` and ``("drive", "torque_in")``."""
    out = [(pair, c) for pair in PAIR_NAMES for c in COMPONENTS[PAIR_KIND[pair]]]
    return out + [("drive", "torque_in")]


def body_kinematics(body: Body, motion: BodyMotion) -> dict[str, np.ndarray]:
    """Centre of mass relative to O ``r`` [m], ``v`` [m/s], ``a`` [m/s^2] (..., 3), ``mass`` [kg] and
    ``inertia`` about it [kg m^2] (..., 3, 3) of ``body`` moving with ``motion``, global components.
    """
    return mass_kinematics(*body.canonical(), motion)


def mass_kinematics(mass: float | np.ndarray, com: np.ndarray, inertia: np.ndarray,
                    motion: BodyMotion) -> dict[str, np.ndarray]:
    """:func:`body_kinematics` from the canonical ``mass`` [kg], ``com`` [m] and ``inertia`` [kg m^2]
    (:meth:`Body.canonical`; one per sample for many scenes in one pass).
    """
    rot = motion.rotation
    c = rot @ com if np.ndim(com) == 1 else np.einsum("...ij,...j->...i", rot, com)
    w_c = cross(motion.omega, c)
    return {"mass": mass, "r": motion.origin + c, "v": motion.velocity + w_c,
            "a": motion.acceleration + cross(motion.alpha, c) + cross(motion.omega, w_c),
            "inertia": rot @ inertia @ np.swapaxes(rot, -1, -2)}


def required_wrench(body: Body, motion: BodyMotion,
                    gravity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force [N] and moment about O [N m] the pairs, drive and load must apply to ``body`` moving with
    ``motion`` under ``gravity`` [m/s^2]: ``F = m (a_c - g)``, ``M_O = r_c x F + J alpha + omega x J omega``.
    """
    k = body_kinematics(body, motion)
    force = k["mass"] * (k["a"] - gravity)
    j_omega = np.einsum("...ij,...j->...i", k["inertia"], motion.omega)
    j_alpha = np.einsum("...ij,...j->...i", k["inertia"], motion.alpha)
    return force, cross(k["r"], force) + j_alpha + cross(motion.omega, j_omega)


def mechanical_energy(scene: Scene,
                      motions: dict[str, BodyMotion]) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy [J] (zero potential at O) of the three bodies' ``motions``."""
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
    """Body wrenches (..., 18, m), rows as :func:`reaction_system`'s, of the unit loads
    ``components`` ``(pair, "fx" | ... | "mz")`` in the pair frames of ``motion``: on body b, the opposite
    on body a.
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
    """Newton-Euler of the three bodies as ``matrix @ unknowns = rhs`` at the samples of ``motion``.

    ``matrix`` (..., 18, 18): rows per body (input, spider, output) force x, y, z [N] and moment about
    O [N m], columns :func:`unknowns`; ``rhs`` (..., 18): required wrench minus the load torque on the
    output. ``load_torque`` [N m]: None for the scene's constant load (a history needs it given).
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
