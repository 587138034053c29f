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
    """First and second time derivatives of the joint variables, shape (..., 4) each.

    Attributes
    ----------
    theta_t, theta_tt : ndarray
        Joint angular speeds [rad/s] and accelerations [rad/s^2].
    s_t, s_tt : ndarray
        Joint sliding speeds [m/s] and accelerations [m/s^2] (zero for joint 1).
    """

    theta_t: np.ndarray
    s_t: np.ndarray
    theta_tt: np.ndarray
    s_tt: np.ndarray


@dataclass(frozen=True)
class BodyMotion:
    """Pose and motion of one link, global components.

    Attributes
    ----------
    rotation, origin : ndarray
        As :class:`BodyPose` [-], [m].
    omega, alpha : ndarray, shape (..., 3)
        Angular velocity [rad/s] and acceleration [rad/s^2].
    velocity, acceleration : ndarray, shape (..., 3)
        Velocity [m/s] and acceleration [m/s^2] of the body point at ``origin``.
    """

    rotation: np.ndarray
    origin: np.ndarray
    omega: np.ndarray
    velocity: np.ndarray
    alpha: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class PairMotion:
    """Motion of body ``b`` relative to body ``a`` along and about one pair's axis.

    Attributes
    ----------
    angle, speed, acceleration : ndarray
        Rotation since ``theta_1 = 0`` [rad], its speed [rad/s] and acceleration [rad/s^2].
    slide, slide_speed, slide_acceleration : ndarray
        Joint slide ``s_k`` [m] and its rates [m/s], [m/s^2] (constant for the revolute pair).
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
    """Joint speeds and accelerations for a given input motion (analytic, no differencing).

    The relative velocity screws close the loop, ``sum_k (theta_k_t + eps s_k_t) S_k = 0``, six
    linear equations for the rates of joints 2..4; differentiated once more with
    ``dS_k/dt = V_k x S_k`` they give the accelerations with the same matrix.

    Parameters
    ----------
    params : DHParameters
        The loop.
    positions : LoopPositions
        From :func:`solve_positions` for the same ``params``.
    theta1_t, theta1_tt : array_like
        Input speed [rad/s] and acceleration [rad/s^2], broadcastable to the input angles' shape.

    Returns
    -------
    LoopRates
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
    """:func:`solve_positions` and :func:`solve_rates` in one call.

    Parameters
    ----------
    params : DHParameters
        The loop.
    theta1, theta1_t, theta1_tt : array_like
        Input angle [rad], speed [rad/s] and acceleration [rad/s^2].
    branch : {"hooke", "flipped"}
        Assembly branch.

    Returns
    -------
    LoopPositions, LoopRates
    """
    positions = solve_positions(params, theta1, branch)
    return positions, solve_rates(params, positions, theta1_t, theta1_tt)


def body_motions(params: DHParameters, positions: LoopPositions,
                 rates: LoopRates) -> dict[str, BodyMotion]:
    """Pose, velocity and acceleration of ``ground``, ``input``, ``spider`` and ``output``.

    Link k's velocity screw is ``V_k = sum_{j<=k} (theta_j_t + eps s_j_t) S_j``; its real part is
    the angular velocity, its dual part the velocity of the body point at the global origin.

    Parameters
    ----------
    params : DHParameters
        The loop.
    positions : LoopPositions
        Its solved positions.
    rates : LoopRates
        Its solved rates.

    Returns
    -------
    dict of str to BodyMotion
        Global components, arrays of the samples' shape.
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
    """Relative rotation (b relative to a, about the pair axis, from ``theta_1 = 0``) and slide.

    Parameters
    ----------
    positions : LoopPositions
        The loop's solved positions.
    rates : LoopRates
        Its solved rates.

    Returns
    -------
    dict of str to PairMotion
        Angle [rad], speed [rad/s], acceleration [rad/s^2], slide [m] and its rates, per pair.
    """
    angle = positions.theta - positions.reference
    return {p: PairMotion(angle[..., k], rates.theta_t[..., k], rates.theta_tt[..., k],
                          positions.s[..., k], rates.s_t[..., k], rates.s_tt[..., k])
            for k, p in enumerate(PAIR_NAMES)}


def output_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Output shaft angle [rad], speed [rad/s], acceleration [rad/s^2] about its own axis.

    Measured like :func:`reference.physics.kinematics.output_angle`: from the output's position at
    ``theta_1 = 0``; it is minus the ``output_frame`` pair's rotation (ground relative to output).

    Parameters
    ----------
    positions : LoopPositions
        The loop's solved positions.
    rates : LoopRates
        Its solved rates.

    Returns
    -------
    angle, speed, acceleration : ndarray
        [rad], [rad/s], [rad/s^2].
    """
    pair = pair_motions(positions, rates)["output_frame"]
    return -pair.angle, -pair.speed, -pair.acceleration


def spider_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spider angle ``gamma`` relative to the input about the input yoke [rad] and its rates.

    The ``input_spider`` pair's rotation, as :func:`reference.physics.kinematics.spider_motion`.

    Parameters
    ----------
    positions : LoopPositions
        The loop's solved positions.
    rates : LoopRates
        Its solved rates.

    Returns
    -------
    gamma, gamma_t, gamma_tt : ndarray
        [rad], [rad/s], [rad/s^2].
    """
    pair = pair_motions(positions, rates)["input_spider"]
    return pair.angle, pair.speed, pair.acceleration
