"""Rates of the solved RCCC loop: joint speeds and accelerations, the bodies' and pairs' motions.

The relative velocity screws close the loop, ``sum_k (theta_k_t + eps s_k_t) S_k = 0``; link k's
velocity screw is ``V_k = sum_{j<=k} (theta_j_t + eps s_j_t) S_j`` and ``dS_k/dt = V_k x S_k``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from reference.physics import dual
from reference.physics.dual import Dual
from reference.physics.rccc.frames import body_poses, joint_screws
from reference.physics.rccc.parameters import LINK_NAMES, DHParameters
from reference.physics.rccc.positions import LoopPositions, sample_array, solve_positions
from reference.scene.joint import PAIR_NAMES

__all__ = ["BodyMotion", "LoopRates", "PairMotion", "body_motions", "output_motion", "pair_motions",
           "solve_motion", "solve_rates", "spider_motion"]


@dataclass(frozen=True)
class LoopRates:
    """Joint rates (..., 4): angular ``theta_t`` [rad/s], ``theta_tt`` [rad/s^2]; sliding ``s_t`` [m/s],
    ``s_tt`` [m/s^2] (zero for joint 1).
    """

    theta_t: np.ndarray
    s_t: np.ndarray
    theta_tt: np.ndarray
    s_tt: np.ndarray


@dataclass(frozen=True)
class BodyMotion:
    """Pose (``rotation``, ``origin`` as :class:`BodyPose`) and motion of one link, global components:
    ``omega`` [rad/s], ``alpha`` [rad/s^2], ``velocity`` [m/s] and ``acceleration`` [m/s^2] of the body
    point at ``origin``.
    """

    rotation: np.ndarray
    origin: np.ndarray
    omega: np.ndarray
    velocity: np.ndarray
    alpha: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class PairMotion:
    """Motion of body ``b`` relative to ``a`` about and along one pair's axis: ``angle`` since
    ``theta_1 = 0`` [rad], ``speed``, ``acceleration``; ``slide`` ``s_k`` [m], ``slide_speed``,
    ``slide_acceleration``.
    """

    angle: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    slide: np.ndarray
    slide_speed: np.ndarray
    slide_acceleration: np.ndarray


def _with_input(first: np.ndarray, rest: Dual) -> Dual:
    """Prepend the (slide-free) joint 1 value to dual values of joints 2..4, shape (..., 4)."""
    return Dual(np.concatenate([first[..., None], rest.re], -1),
                np.concatenate([np.zeros_like(first)[..., None], rest.du], -1))


def _screw_rates(screws: Dual, joint_rates: Dual) -> Dual:
    """``dS_k/dt = V_k x S_k``, ``V_k`` the velocity screw of link k (``V_k x S_k = V_{k-1} x S_k``)."""
    return dual.cross((joint_rates[..., None] * screws).cumsum(-2), screws)


def solve_rates(params: DHParameters, positions: LoopPositions, theta1_t: ArrayLike,
                theta1_tt: ArrayLike) -> LoopRates:
    """:class:`LoopRates` of ``params`` at its ``positions`` for input speed ``theta1_t`` [rad/s] and
    acceleration ``theta1_tt`` [rad/s^2]: six linear equations for joints 2..4, differentiated once
    more with the same matrix for the accelerations (no differencing).
    """
    shape = positions.theta.shape[:-1]
    theta1_t = sample_array("theta1_t", theta1_t, shape)
    theta1_tt = sample_array("theta1_tt", theta1_tt, shape)
    screws = joint_screws(params, positions)
    matrix = screws[..., 1:, :].T
    rates = _with_input(theta1_t, dual.solve(matrix, -(theta1_t[..., None] * screws[..., 0, :])))
    drift = (rates[..., None] * _screw_rates(screws, rates)).sum(-2)
    accels = _with_input(theta1_tt,
                         dual.solve(matrix, -(theta1_tt[..., None] * screws[..., 0, :] + drift)))
    return LoopRates(theta_t=rates.re, s_t=rates.du, theta_tt=accels.re, s_tt=accels.du)


def solve_motion(params: DHParameters, theta1: ArrayLike, theta1_t: ArrayLike, theta1_tt: ArrayLike,
                 branch: str = "hooke") -> tuple[LoopPositions, LoopRates]:
    """:func:`solve_positions` and :func:`solve_rates` in one call: ``(LoopPositions, LoopRates)``."""
    positions = solve_positions(params, theta1, branch)
    return positions, solve_rates(params, positions, theta1_t, theta1_tt)


def body_motions(params: DHParameters, positions: LoopPositions,
                 rates: LoopRates) -> dict[str, BodyMotion]:
    """:class:`BodyMotion` of ``ground``, ``input``, ``spider`` and ``output`` from the loop's
    ``positions`` and ``rates``: link k's screw ``V_k`` gives the angular velocity (real part) and the
    velocity of the body point at the origin (dual part).
    """
    screws = joint_screws(params, positions)
    joint_rates = Dual(rates.theta_t, rates.s_t)
    joint_accels = Dual(rates.theta_tt, rates.s_tt)
    twist = (joint_rates[..., None] * screws).cumsum(-2)
    twist_t = (joint_accels[..., None] * screws
               + joint_rates[..., None] * _screw_rates(screws, joint_rates)).cumsum(-2)
    poses = body_poses(params, positions)
    zero = np.zeros(positions.theta.shape[:-1] + (3,))
    out = {"ground": BodyMotion(poses["ground"].rotation, zero, zero, zero, zero, zero)}
    for k, name in enumerate(LINK_NAMES[:3]):
        p = poses[name].origin
        omega = twist.re[..., k, :]
        alpha = twist_t.re[..., k, :]
        velocity = twist.du[..., k, :] + np.cross(omega, p)
        acceleration = twist_t.du[..., k, :] + np.cross(alpha, p) + np.cross(omega, velocity)
        out[name] = BodyMotion(poses[name].rotation, p, omega, velocity, alpha, acceleration)
    return out


def pair_motions(positions: LoopPositions, rates: LoopRates) -> dict[str, PairMotion]:
    """Per pair, :class:`PairMotion` of b relative to a from the loop's ``positions`` and ``rates``."""
    angle = positions.theta - positions.reference
    return {p: PairMotion(angle[..., k], rates.theta_t[..., k], rates.theta_tt[..., k],
                          positions.s[..., k], rates.s_t[..., k], rates.s_tt[..., k])
            for k, p in enumerate(PAIR_NAMES)}


def output_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Output shaft angle [rad] since ``theta_1 = 0``, speed [rad/s] and acceleration [rad/s^2] about its
    own axis: minus the ``output_frame`` pair's rotation.
    """
    pair = pair_motions(positions, rates)["output_frame"]
    return -pair.angle, -pair.speed, -pair.acceleration


def spider_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spider angle ``gamma`` about the input yoke relative to the input [rad] and its rates: the
    ``input_spider`` pair's rotation, as :func:`reference.physics.kinematics.spider_motion`.
    """
    pair = pair_motions(positions, rates)["input_spider"]
    return pair.angle, pair.speed, pair.acceleration
