"""Dynamics of the Cardan joint with the paper's friction: reactions, friction and the drive unknown.

Newton-Euler gives ``K x = r - W phi`` with friction values ``phi = G(x)``, so ``x = x0 - S phi``
(``x0 = K^-1 r``, ``S = K^-1 W``) and ``phi = G(x0 - S phi)`` has at most seven unknowns. A sample
without a converged fixed point, or with loop gain (spectral radius of ``dG/dphi``) >= 1, is
*self-locking*: the Coulomb problem has no unique finite solution.
"""

from __future__ import annotations

from typing import NamedTuple

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


class _System(NamedTuple):
    """Newton-Euler at n samples, the friction's unit wrenches and the pairs' relative speeds."""

    matrix: np.ndarray
    """(n, 18, 18)."""
    rhs: np.ndarray
    """(n, 18)."""
    wrenches: np.ndarray
    """(n, 18, K)."""
    omega_rel: dict[str, np.ndarray]
    slide_rel: dict[str, np.ndarray]


def solve_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                   theta_tt: np.ndarray | None = None,
                   torque_in: float | np.ndarray | None = None,
                   method: str = "auto",
                   load_torque: float | np.ndarray | None = None,
                   bands: np.ndarray | None = None) -> tuple[JointMotion, FixedPoint]:
    """``(motion, fixed_point)``: reactions, friction and the drive unknown ``x[..., -1]`` per sample.

    Exactly one of ``theta_tt`` [rad/s^2] (inverse dynamics: the drive torque [N m] is the unknown) and
    ``torque_in`` [N m] (forward: the input acceleration is) is given, with ``theta`` [rad], ``theta_t``
    [rad/s], the kinematics ``method``, ``load_torque`` [N m] (None: the scene's constant load) and
    ``bands`` (K,) [m/s] (None: :func:`slot_bands`; passing them saves the scene's hash).
    """
    if (theta_tt is None) == (torque_in is None):
        raise ValueError("give exactly one of `theta_tt` (inverse) and `torque_in` (forward)")
    theta = np.atleast_1d(np.asarray(theta, float))
    theta_t = np.atleast_1d(np.asarray(theta_t, float))
    if theta_tt is not None:
        motion = joint_motion(scene.joint, theta, theta_t, np.broadcast_to(theta_tt, theta.shape), method)
        matrix, rhs = reaction_system(scene, motion, load_torque)
        system = _System(matrix, rhs, friction_matrix(motion, friction_slots(scene)), motion.omega_rel,
                         motion.slide_rel)
    else:
        system = _forward_system(scene, theta, theta_t, torque_in, method, load_torque)
    fixed = _fixed_point(scene, system, bands, theta.size)
    if torque_in is not None:
        motion = joint_motion(scene.joint, theta, theta_t, fixed.x[..., -1], method)
    return motion, fixed


def _forward_system(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                    torque_in: float | np.ndarray, method: str,
                    load_torque: float | np.ndarray | None) -> _System:
    """The system with the input acceleration as last unknown (:func:`solve_dynamics`' arguments): one
    batch at accelerations 0 and 1, the right-hand side being affine in it.
    """
    n = theta.size
    pair = joint_motion(scene.joint, np.tile(theta, 2), np.tile(theta_t, 2), np.repeat([0.0, 1.0], n),
                        method)
    load = None if load_torque is None else np.tile(np.broadcast_to(load_torque, theta.shape), 2)
    matrix, rhs = reaction_system(scene, pair, load)
    matrix = matrix[:n]
    rhs_one = rhs[n:]
    rhs = rhs[:n]
    matrix[..., :, -1] = -(rhs_one - rhs)  # the acceleration's share moves to the left
    rhs[..., DRIVE_ROW] -= torque_in
    # velocity-level quantities and the pair geometry do not depend on the acceleration
    return _System(matrix, rhs, friction_matrix(pair, friction_slots(scene))[:n],
                   {p: v[:n] for p, v in pair.omega_rel.items()},
                   {p: v[:n] for p, v in pair.slide_rel.items()})


def _fixed_point(scene: Scene, system: _System, bands: np.ndarray | None, n: int) -> FixedPoint:
    """The friction fixed point of the ``n`` samples of ``system`` (``bands`` as for
    :func:`solve_dynamics`)."""
    slots = friction_slots(scene)
    both = np.linalg.solve(system.matrix, np.concatenate([system.rhs[..., None], system.wrenches], -1))
    if bands is None:
        bands = slot_bands(scene, slots)
    signs = (slot_signs(scene, slots, slot_speeds(scene, slots, system.omega_rel, system.slide_rel), bands)
             if slots else np.zeros((n, 0)))
    law = FrictionLaw(scene, slots)
    if scene.friction.coupling == "uncoupled":  # evaluated on the frictionless reactions only
        return FixedPoint(both[..., 0], law(both[..., 0], signs)[0], np.ones(n, bool), np.zeros(n), 0)
    return solve_friction(law, both[..., 0], both[..., 1:], signs)


def dynamics_columns(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray | None = None,
                     torque_in: float | None = None,
                     method: str = "auto",
                     load_torque: float | np.ndarray | None = None,
                     ) -> tuple[dict[str, np.ndarray], FixedPoint]:
    """``(columns, fixed_point)``: the result-schema columns but ``t``, plus ``input_acceleration``,
    ``friction_loop_gain``, ``self_locking``, ``<pair>_slide`` [m] and ``power_loss_<pair>_rotation`` /
    ``_sliding`` [W], for :func:`solve_dynamics`' arguments; NaN reactions, friction and powers where a
    sample self-locks.
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
    """:func:`dynamics_columns`' columns from the ``motion``, the ``fixed`` point, the ``slots``, the
    ``inputs`` (angle, speed, acceleration), ``drive`` and ``load`` torques [N m] and ``energy`` [J].
    """
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
        own = _pair_columns(motion, pair, applied, zero)
        loss_total = loss_total + own[f"power_loss_{pair}_rotation"] + own[f"power_loss_{pair}_sliding"]
        cols.update(own)
    for j, (pair, component) in enumerate(unknowns()[:-1]):
        cols[f"{pair}_{component}"] = x[:, j]
    cols["power_loss"] = loss_total
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], loss_total)
    cols["input_acceleration"] = accel
    cols["friction_loop_gain"] = fixed.loop_gain
    cols["self_locking"] = locked
    return cols


def _pair_columns(motion: JointMotion, pair: str, applied: dict[tuple[str, str], np.ndarray],
                  zero: np.ndarray) -> dict[str, np.ndarray]:
    """One pair's friction, speeds, slide and losses (its reactions zero, filled by the caller),
    from the ``applied`` friction values per ``(pair, kind)``; ``zero`` (n,)."""
    torque = applied.get((pair, "torque"), zero)
    force = applied.get((pair, "force"), zero)
    omega_rel = motion.omega_rel[pair] + zero
    slide_rel = motion.slide_rel[pair] + zero
    rotation = pair_power_loss(torque, zero, omega_rel, zero)
    sliding = pair_power_loss(zero, force, zero, slide_rel)
    cols = {f"power_loss_{pair}": rotation + sliding, f"power_loss_{pair}_rotation": rotation,
            f"power_loss_{pair}_sliding": sliding}
    cols.update({f"{pair}_{suffix}": zero for suffix in PAIR_SUFFIXES})
    cols[f"{pair}_friction_torque"] = torque + zero
    cols[f"{pair}_friction_force"] = force + zero
    cols[f"{pair}_omega_rel"] = omega_rel
    cols[f"{pair}_slide_rel"] = slide_rel
    cols[f"{pair}_slide"] = motion.slide[pair] + zero
    return cols


def inverse_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray) -> dict[str, np.ndarray]:
    """Result-schema columns (without ``t``) of ``scene`` with friction for the prescribed input motion
    ``theta`` [rad], ``theta_t`` [rad/s], ``theta_tt`` [rad/s^2] (the drive is replaced by it).
    """
    return dynamics_columns(scene, theta, theta_t, theta_tt=theta_tt)[0]
