"""Closed-form kinematics of the ideal Cardan (Hooke's) joint, vectorised over time.

Input axis global x, output axis ``a2 = (cos b, sin b, 0)``; at input angle 0 the input yoke's
trunnions lie along y, the output's along z. Canonical body frames: input ``Rx(theta)``; spider
``Rx(theta) Ry(gamma)``, ``gamma = atan2(sin b sin theta, cos b)``; output ``Rz(b) Rx(theta_out)``,
``tan(theta_out) = tan(theta) / cos b``. Angles [rad], times [s], arrays of any common shape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.scene.joint import PAIR_BODIES, PAIR_NAMES

__all__ = ["rot_x", "rot_y", "rot_z", "output_angle", "speed_ratio", "speed_ratio_slope",
           "output_motion", "spider_motion", "BodyMotion", "body_motions", "pair_frames_in_body_a",
           "pair_frames", "relative_speeds"]


def rot_x(angle: np.ndarray) -> np.ndarray:
    """Rotation matrices about x [-], shape ``angle.shape + (3, 3)``."""
    c = np.cos(angle)
    s = np.sin(angle)
    one = np.ones_like(c)
    zero = np.zeros_like(c)
    return np.stack([np.stack([one, zero, zero], -1),
                     np.stack([zero, c, -s], -1),
                     np.stack([zero, s, c], -1)], -2)


def rot_y(angle: np.ndarray) -> np.ndarray:
    """Rotation matrices about y [-], shape ``angle.shape + (3, 3)``."""
    c = np.cos(angle)
    s = np.sin(angle)
    one = np.ones_like(c)
    zero = np.zeros_like(c)
    return np.stack([np.stack([c, zero, s], -1),
                     np.stack([zero, one, zero], -1),
                     np.stack([-s, zero, c], -1)], -2)


def rot_z(angle: np.ndarray) -> np.ndarray:
    """Rotation matrices about z [-], shape ``angle.shape + (3, 3)``."""
    c = np.cos(angle)
    s = np.sin(angle)
    one = np.ones_like(c)
    zero = np.zeros_like(c)
    return np.stack([np.stack([c, -s, zero], -1),
                     np.stack([s, c, zero], -1),
                     np.stack([zero, zero, one], -1)], -2)


def output_angle(theta: np.ndarray, beta: float) -> np.ndarray:
    """Output shaft angle [rad] at input angles ``theta`` [rad] and shaft angle ``beta`` in [0, pi/2):
    ``theta`` plus the lag ``atan2((1 - cos b) sin theta cos theta, cos b cos^2 theta + sin^2 theta)``,
    continuous (the second argument is positive).
    """
    c = np.cos(theta)
    s = np.sin(theta)
    cb = np.cos(beta)
    return theta + np.arctan2((1.0 - cb) * s * c, cb * c**2 + s**2)


def speed_ratio(theta: np.ndarray, beta: float) -> np.ndarray:
    """Speed ratio ``omega_out / omega_in = cos b / (1 - sin^2 b cos^2 theta)`` [-] at ``theta``, ``beta``
    [rad].
    """
    return np.cos(beta) / (1.0 - np.sin(beta) ** 2 * np.cos(theta) ** 2)


def speed_ratio_slope(theta: np.ndarray, beta: float) -> np.ndarray:
    """``d ratio / d theta`` [1/rad] of :func:`speed_ratio` at ``theta``, ``beta`` [rad]."""
    d = 1.0 - np.sin(beta) ** 2 * np.cos(theta) ** 2
    return -np.cos(beta) * np.sin(beta) ** 2 * np.sin(2.0 * theta) / d**2


def output_motion(theta: np.ndarray, theta_t: np.ndarray, theta_tt: np.ndarray,
                  beta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Output angle [rad], speed [rad/s] and acceleration [rad/s^2] for the input motion ``theta``,
    ``theta_t``, ``theta_tt`` and shaft angle ``beta`` [rad].
    """
    ratio = speed_ratio(theta, beta)
    return (output_angle(theta, beta), ratio * theta_t,
            speed_ratio_slope(theta, beta) * theta_t**2 + ratio * theta_tt)


def spider_motion(theta: np.ndarray, theta_t: np.ndarray, theta_tt: np.ndarray,
                  beta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spider angle ``gamma = atan2(sin b sin theta, cos b)`` [rad] relative to the input and its rates
    [rad/s], [rad/s^2], the rate being ``h theta_t``, ``h = sin b cos b cos theta / (1 - sin^2 b cos^2
    theta)``.
    """
    sb = np.sin(beta)
    cb = np.cos(beta)
    c = np.cos(theta)
    s = np.sin(theta)
    d = 1.0 - sb**2 * c**2
    h = sb * cb * c / d
    h_theta = -sb * cb * s * (1.0 + sb**2 * c**2) / d**2
    return np.arctan2(sb * s, cb), h * theta_t, h_theta * theta_t**2 + h * theta_tt


@dataclass(frozen=True)
class BodyMotion:
    """One body's ``rotation`` (..., 3, 3) (columns: canonical axes, global), ``omega`` [rad/s] and
    ``alpha`` [rad/s^2] (..., 3).
    """

    rotation: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray


def body_motions(theta: np.ndarray, theta_t: np.ndarray, theta_tt: np.ndarray,
                 beta: float) -> dict[str, BodyMotion]:
    """:class:`BodyMotion` of ``ground``, ``input``, ``spider``, ``output`` for the input motion and shaft
    angle ``beta`` [rad] (an array: one per sample). Spider: ``omega = theta_t e_x + gamma_t u1``, its
    acceleration with the transport term ``gamma_t (theta_t e_x x u1)``.
    """
    theta, theta_t, theta_tt = np.broadcast_arrays(*(np.asarray(v, float)
                                                     for v in (theta, theta_t, theta_tt)))
    e_x = np.array([1.0, 0.0, 0.0])
    if np.ndim(beta) == 0:
        a2 = np.array([np.cos(beta), np.sin(beta), 0.0])
    else:
        a2 = np.stack(np.broadcast_arrays(np.cos(beta), np.sin(beta), 0.0), -1)
    gamma, gamma_t, gamma_tt = spider_motion(theta, theta_t, theta_tt, beta)
    theta_out, omega_out, alpha_out = output_motion(theta, theta_t, theta_tt, beta)
    a_in = rot_x(theta)
    u1 = a_in[..., :, 1]
    w_in = theta_t[..., None] * e_x
    dw_in = theta_tt[..., None] * e_x
    w_spider = w_in + gamma_t[..., None] * u1
    dw_spider = (dw_in + gamma_tt[..., None] * u1
                 + gamma_t[..., None] * np.cross(w_in, u1))
    zero = np.zeros(theta.shape + (3,))
    return {
        "ground": BodyMotion(np.broadcast_to(np.eye(3), zero.shape + (3,)), zero, zero),
        "input": BodyMotion(a_in, w_in, dw_in),
        "spider": BodyMotion(a_in @ rot_y(gamma), w_spider, dw_spider),
        "output": BodyMotion(rot_z(np.full_like(theta, beta)) @ rot_x(theta_out),
                             omega_out[..., None] * a2, alpha_out[..., None] * a2),
    }


def pair_frames_in_body_a() -> dict[str, np.ndarray]:
    """Each pair's frame (columns x, y, z; z the pair axis) in body a's canonical axes [-]; in global
    axes at rest: ``frame_input`` (e_y, e_z, e_x), ``input_spider`` (e_z, e_x, e_y), ``spider_output``
    (e_x, e_y, e_z), ``output_frame`` ((-sin b, cos b, 0), e_z, a2).
    """
    e_x, e_y, e_z = np.eye(3)
    return {
        "frame_input": np.column_stack([e_y, e_z, e_x]),
        "input_spider": np.column_stack([e_z, e_x, e_y]),
        "spider_output": np.eye(3),
        "output_frame": np.column_stack([e_y, e_z, e_x]),
    }


def pair_frames(motions: dict[str, BodyMotion]) -> dict[str, np.ndarray]:
    """Pair frames moving with body a, global components, shape (..., 3, 3) [-]."""
    local = pair_frames_in_body_a()
    return {p: motions[PAIR_BODIES[p][0]].rotation @ local[p] for p in PAIR_NAMES}


def relative_speeds(motions: dict[str, BodyMotion]) -> dict[str, np.ndarray]:
    """Angular speed [rad/s] of body b relative to body a about each pair's axis (the ideal joint does not
    slide).
    """
    frames = pair_frames(motions)
    out = {}
    for pair in PAIR_NAMES:
        a, b = PAIR_BODIES[pair]
        relative = motions[b].omega - motions[a].omega
        out[pair] = np.einsum("...i,...i->...", relative, frames[pair][..., :, 2])
    return out
