"""Dynamics of the Cardan joint with the paper's friction: reactions, friction and the drive unknown.

Newton-Euler (:mod:`reference.engine.newton_euler`) gives ``K x = r - W phi`` with ``phi`` the
friction values (:mod:`reference.engine.slots`: a torque per pair with friction, an axial force
per cylindrical pair with friction), and friction depends on the reactions, ``phi = G(x)``. Linear
in ``x``, so ``x = x0 - S phi`` with ``x0 = K^-1 r`` and ``S = K^-1 W``, and the fixed point reduces
to at most seven unknowns, ``phi = G(x0 - S phi)``. It is solved by Newton's method with the
analytic Jacobian of ``G``, every sample at once (:mod:`reference.engine.fixed_point`). A sample
whose fixed point does not converge, or converges to a point where the loop gain (spectral
radius of ``dG/dphi``) is 1 or more, is *self-locking*: friction grows faster than the reactions
that cause it, the Coulomb problem has no unique finite solution.

Pair origins and frames come with the joint motion: in the ideal joint the origins are fixed in
space (``frame_input`` at ``-input_bearing e_x``, the spider pairs at O, ``output_frame`` at
``output_bearing a2``) and no pair slides, so the regularised sign of the zero sliding speed is 0
and the axial friction of eq. (5) vanishes. With mounting errors the cylindrical pairs slide and
their axial friction does work (``power_loss_<pair>_sliding``).

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3, eqs. (3), (5) (friction from the reactions) and eq. (18)
(instantaneous efficiency).
"""

from __future__ import annotations

import numpy as np

from reference.engine.fixed_point import FixedPoint, solve_friction
from reference.engine.newton_euler import (
    DRIVE_ROW,
    constant_load,
    mechanical_energy,
    reaction_system,
    unknowns,
)
from reference.engine.slots import (
    FrictionLaw,
    friction_matrix,
    friction_slots,
    slot_bands,
    slot_signs,
    slot_speeds,
)
from reference.physics.friction import pair_power_loss
from reference.physics.joint_motion import JointMotion, joint_motion
from reference.results.columns import PAIR_SUFFIXES, instantaneous_efficiency
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["dynamics_columns", "inverse_dynamics", "solution_columns", "solve_dynamics"]


def solve_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                   theta_tt: np.ndarray | None = None,
                   torque_in: float | np.ndarray | None = None,
                   method: str = "auto",
                   load_torque: float | np.ndarray | None = None,
                   bands: np.ndarray | None = None) -> tuple[JointMotion, FixedPoint]:
    """Reactions, friction and the drive unknown for every sample.

    Exactly one of ``theta_tt`` (inverse dynamics: the drive torque is the unknown) and
    ``torque_in`` (forward dynamics: the input acceleration is the unknown) is given.
    ``method`` chooses the kinematics (:func:`reference.physics.joint_motion.joint_motion`);
    ``load_torque`` [N m] the output load per sample (None: the scene's constant load);
    ``bands`` the sign ramps' widths (None: :func:`slot_bands`, looked up by the scene, whose
    hash a caller solving one sample at a time may save by passing them).

    Returns
    -------
    motion : JointMotion
        The joint's motion (with the solved acceleration in forward dynamics).
    fixed_point : FixedPoint
        ``x[..., -1]`` is the drive torque [N m] or the input acceleration [rad/s^2].
    """
    if (theta_tt is None) == (torque_in is None):
        raise ValueError("give exactly one of `theta_tt` (inverse) and `torque_in` (forward)")
    joint = scene.joint
    theta = np.atleast_1d(np.asarray(theta, float))
    theta_t = np.atleast_1d(np.asarray(theta_t, float))
    n = theta.size
    if theta_tt is not None:
        motion = joint_motion(joint, theta, theta_t, np.broadcast_to(theta_tt, theta.shape), method)
        matrix, rhs = reaction_system(scene, motion, load_torque)
        omega_rel = motion.omega_rel
        slide_rel = motion.slide_rel
        wrenches = friction_matrix(motion, friction_slots(scene))
    else:  # one batch at accelerations 0 and 1: the right-hand side is affine in theta_tt
        pair = joint_motion(joint, np.tile(theta, 2), np.tile(theta_t, 2), np.repeat([0.0, 1.0], n),
                            method)
        load = None if load_torque is None else np.tile(np.broadcast_to(load_torque, theta.shape), 2)
        matrix, rhs = reaction_system(scene, pair, load)
        matrix = matrix[:n]
        rhs_one = rhs[n:]
        rhs = rhs[:n]
        matrix[..., :, -1] = -(rhs_one - rhs)  # the acceleration's share moves to the left
        rhs[..., DRIVE_ROW] -= torque_in
        # velocity-level quantities and the pair geometry do not depend on the acceleration
        omega_rel = {p: v[:n] for p, v in pair.omega_rel.items()}
        slide_rel = {p: v[:n] for p, v in pair.slide_rel.items()}
        wrenches = friction_matrix(pair, friction_slots(scene))[:n]
    slots = friction_slots(scene)
    both = np.linalg.solve(matrix, np.concatenate([rhs[..., None], wrenches], -1))
    if bands is None:
        bands = slot_bands(scene, slots)
    signs = (slot_signs(scene, slots, slot_speeds(scene, slots, omega_rel, slide_rel), bands)
             if slots else np.zeros(theta.shape + (0,)))
    law = FrictionLaw(scene, slots)
    if scene.friction.coupling == "uncoupled":  # evaluated on the frictionless reactions only
        fixed = FixedPoint(both[..., 0], law(both[..., 0], signs)[0], np.ones(n, bool), np.zeros(n), 0)
    else:
        fixed = solve_friction(law, both[..., 0], both[..., 1:], signs)
    if torque_in is not None:
        motion = joint_motion(joint, theta, theta_t, fixed.x[..., -1], method)
    return motion, fixed


def dynamics_columns(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray | None = None,
                     torque_in: float | None = None,
                     method: str = "auto",
                     load_torque: float | np.ndarray | None = None,
                     ) -> tuple[dict[str, np.ndarray], FixedPoint]:
    """Result-schema columns (without ``t``) for the given motion, with friction.

    Inverse dynamics when ``theta_tt`` is given, forward dynamics when ``torque_in`` is (see
    :func:`solve_dynamics`). Samples that self-lock carry NaN reactions, friction and powers.

    Returns
    -------
    columns : dict of str to ndarray, shape (n,)
        Every column of :func:`reference.results.columns.table_columns` but ``t``, plus
        ``input_acceleration`` [rad/s^2], ``friction_loop_gain`` [-], ``self_locking`` and, per
        pair, ``<pair>_slide`` [m] (the D-H slide; zero in the ideal joint) and the two parts of
        its loss, ``power_loss_<pair>_rotation`` and ``power_loss_<pair>_sliding`` [W].
    fixed_point : FixedPoint
    """
    motion, fixed = solve_dynamics(scene, theta, theta_t, theta_tt, torque_in, method, load_torque)
    theta = np.atleast_1d(np.asarray(theta, float))
    theta_t = np.atleast_1d(np.asarray(theta_t, float))
    unknown = np.where(fixed.self_locking, np.nan, fixed.x[:, -1])  # drive torque or acceleration
    if torque_in is None:
        accel = np.broadcast_to(np.asarray(theta_tt, float), theta.shape) + 0.0
        drive = unknown
    else:
        accel = unknown
        drive = np.where(fixed.self_locking, np.nan, np.broadcast_to(torque_in, theta.shape))
    load = constant_load(scene) if load_torque is None else load_torque
    return solution_columns(motion, fixed, friction_slots(scene), (theta, theta_t, accel), drive, load,
                            mechanical_energy(scene, motion.bodies)), fixed


def solution_columns(motion: JointMotion, fixed: FixedPoint, slots: list[tuple[str, str]],
                     inputs: tuple[np.ndarray, np.ndarray, np.ndarray], drive: np.ndarray,
                     load: float | np.ndarray,
                     energy: tuple[np.ndarray, np.ndarray]) -> dict[str, np.ndarray]:
    """:func:`dynamics_columns`' columns from the solution: ``inputs`` the input angle [rad],
    speed [rad/s] and acceleration [rad/s^2], ``drive`` the drive torque [N m], ``load`` the
    output load [N m], ``energy`` the kinetic and potential energy [J], all per sample (n,)."""
    (theta, theta_t, accel) = inputs
    locked = fixed.self_locking
    x = np.where(locked[:, None], np.nan, fixed.x)
    phi = np.where(locked[:, None], np.nan, fixed.friction)
    theta_out, omega_out, _ = motion.output
    zero = np.zeros_like(theta_out)
    cols = {"theta_in": theta + zero, "theta_out": theta_out, "omega_in": theta_t + zero,
            "omega_out": omega_out, "torque_in": drive + zero, "torque_out": zero + load}
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * omega_out
    cols["energy_kinetic"], cols["energy_potential"] = energy
    applied = {(pair, kind): phi[:, j] for j, (pair, kind) in enumerate(slots)}
    loss_total = zero.copy()
    for pair in PAIR_NAMES:
        torque = applied.get((pair, "torque"), zero)
        force = applied.get((pair, "force"), zero)
        omega_rel = motion.omega_rel[pair] + zero
        slide_rel = motion.slide_rel[pair] + zero
        rotation = pair_power_loss(torque, zero, omega_rel, zero)
        sliding = pair_power_loss(zero, force, zero, slide_rel)
        loss_total = loss_total + rotation + sliding
        cols[f"power_loss_{pair}"] = rotation + sliding
        cols[f"power_loss_{pair}_rotation"] = rotation
        cols[f"power_loss_{pair}_sliding"] = sliding
        cols.update({f"{pair}_{suffix}": zero for suffix in PAIR_SUFFIXES})
        cols[f"{pair}_friction_torque"] = torque + zero
        cols[f"{pair}_friction_force"] = force + zero
        cols[f"{pair}_omega_rel"] = omega_rel
        cols[f"{pair}_slide_rel"] = slide_rel
        cols[f"{pair}_slide"] = motion.slide[pair] + zero
    for j, (pair, component) in enumerate(unknowns()[:-1]):
        cols[f"{pair}_{component}"] = x[:, j]
    cols["power_loss"] = loss_total
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], loss_total)
    cols["input_acceleration"] = accel
    cols["friction_loop_gain"] = fixed.loop_gain
    cols["self_locking"] = locked
    return cols


def inverse_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray) -> dict[str, np.ndarray]:
    """Result-schema columns (without ``t``) for a prescribed input motion, with friction.

    Parameters
    ----------
    scene : Scene
        Joint, load, gravity and friction (the drive is replaced by the given motion).
    theta, theta_t, theta_tt : ndarray, shape (n,)
        Input angle [rad], speed [rad/s] and acceleration [rad/s^2].
    """
    return dynamics_columns(scene, theta, theta_t, theta_tt=theta_tt)[0]
