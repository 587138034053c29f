"""Closed-form Cardan kinematics (reference.physics.kinematics) against independent constructions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.physics.kinematics import (
    body_motions,
    output_angle,
    output_motion,
    pair_frames_in_body_a,
    relative_speeds,
)
from reference.scene.joint import PAIR_BODIES, PAIR_NAMES

EPS = np.finfo(float).eps
ANGLES_DEG = [0.0, 5.0, 37.0, 60.0, 85.0]
ANGLE_IDS = [f"{a:g}deg" for a in ANGLES_DEG]
H = 1e-4  # finite-difference step [s]: truncation ~1e-9 even at 85 deg, rounding ~1e-11
TIMES = np.linspace(0.0, 4.0, 801)


def input_motion(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A non-uniform input motion (angle, speed, acceleration) so the theta_tt terms count."""
    return 0.3 + 2.0 * t + 0.5 * np.sin(3.0 * t), 2.0 + 1.5 * np.cos(3.0 * t), -4.5 * np.sin(3.0 * t)


def derivative(f, t: np.ndarray, h: float = H) -> tuple[np.ndarray, float]:
    """Fourth-order central difference of ``f`` at ``t`` and a bound on its error.

    The bound is twice the Richardson estimate of the O(h^4) truncation error,
    max |D(2h) - D(h)| / 15, plus the rounding of the difference quotient: weights summing to
    18/12 over h, applied to values accurate to about 4 ulp of max |f|.
    """
    def quotient(step):
        return (f(t - 2 * step) - 8 * f(t - step) + 8 * f(t + step) - f(t + 2 * step)) / (12 * step)

    d_h, d_2h = quotient(h), quotient(2 * h)
    rounding = 1.5 * 4 * EPS * np.max(np.abs(f(t))) / h
    return d_h, 2 * np.max(np.abs(d_2h - d_h)) / 15 + rounding


def motions_at(t: np.ndarray, beta: float):
    return body_motions(*input_motion(t), beta)


def vee(w: np.ndarray) -> np.ndarray:
    """Axial vector of the (nearly) skew matrices w, shape (..., 3)."""
    return 0.5 * np.stack([w[..., 2, 1] - w[..., 1, 2], w[..., 0, 2] - w[..., 2, 0],
                           w[..., 1, 0] - w[..., 0, 1]], -1)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_output_angle_matches_yoke_cross_product(beta_deg):
    """Hooke's closed form equals the angle of the output yoke built as a2 x (input yoke)."""
    beta = math.radians(beta_deg)
    theta = np.linspace(-2 * np.pi, 4 * np.pi, 1201)
    a2 = np.array([math.cos(beta), math.sin(beta), 0.0])
    y_out_0 = np.array([-math.sin(beta), math.cos(beta), 0.0])  # output canonical y at angle 0
    u1 = np.stack([np.zeros_like(theta), np.cos(theta), np.sin(theta)], -1)
    u2 = np.cross(a2, u1)
    u2 /= np.linalg.norm(u2, axis=-1, keepdims=True)
    # the yoke is the output's z axis, turned by theta_out about a2 from e_z towards -y_out_0
    wrapped = np.arctan2(-u2 @ y_out_0, u2[:, 2])
    got = output_angle(theta, beta)
    # angles up to 4 pi: 50 ulp of 4 pi (1.4e-13 rad) covers the few operations on each side
    tol = 50 * EPS * 4 * np.pi
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - wrapped))), 0.0, rtol=0, atol=tol)
    assert np.all(np.diff(got) > 0), "theta_out must be continuous and increasing"
    quarter = np.arange(-4, 9) * 0.5 * np.pi  # the shafts are in step at every quarter turn
    np.testing.assert_allclose(output_angle(quarter, beta), quarter, rtol=0, atol=tol)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_output_rates_match_finite_differences(beta_deg):
    """omega_out and alpha_out equal time derivatives of theta_out and omega_out (chain rule)."""
    beta = math.radians(beta_deg)
    _, omega, alpha = output_motion(*input_motion(TIMES), beta)
    fd_omega, tol_omega = derivative(lambda t: output_motion(*input_motion(t), beta)[0], TIMES)
    fd_alpha, tol_alpha = derivative(lambda t: output_motion(*input_motion(t), beta)[1], TIMES)
    np.testing.assert_allclose(omega, fd_omega, rtol=0, atol=tol_omega)
    np.testing.assert_allclose(alpha, fd_alpha, rtol=0, atol=tol_alpha)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_body_frames_satisfy_the_joint(beta_deg):
    """Frames are rotations; the spider's arms lie on both yokes; canonical frames at angle 0."""
    beta = math.radians(beta_deg)
    m = motions_at(TIMES, beta)
    a2 = np.array([math.cos(beta), math.sin(beta), 0.0])
    # orthonormal 3x3 matrices built from a few products: 20 ulp
    tol = 20 * EPS
    for name in ("input", "spider", "output"):
        rot = m[name].rotation
        np.testing.assert_allclose(np.swapaxes(rot, -1, -2) @ rot, np.broadcast_to(np.eye(3),
                                   rot.shape), rtol=0, atol=tol, err_msg=name)
        np.testing.assert_allclose(np.linalg.det(rot), 1.0, rtol=0, atol=tol, err_msg=name)
    np.testing.assert_allclose(m["input"].rotation[:, :, 0], np.broadcast_to([1.0, 0, 0],
                               (TIMES.size, 3)), rtol=0, atol=tol)
    np.testing.assert_allclose(m["output"].rotation[:, :, 0], np.broadcast_to(a2, (TIMES.size, 3)),
                               rtol=0, atol=tol)
    np.testing.assert_allclose(m["spider"].rotation[:, :, 1], m["input"].rotation[:, :, 1],
                               rtol=0, atol=tol)
    np.testing.assert_allclose(m["spider"].rotation[:, :, 2], m["output"].rotation[:, :, 2],
                               rtol=0, atol=tol)
    ref = body_motions(0.0, 0.0, 0.0, beta)
    c, s = math.cos(beta), math.sin(beta)
    np.testing.assert_allclose(ref["input"].rotation, np.eye(3), rtol=0, atol=tol)
    np.testing.assert_allclose(ref["spider"].rotation, np.eye(3), rtol=0, atol=tol)
    np.testing.assert_allclose(ref["output"].rotation, [[c, -s, 0], [s, c, 0], [0, 0, 1]],
                               rtol=0, atol=tol)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
@pytest.mark.parametrize("body", ["input", "spider", "output"])
def test_angular_velocity_and_acceleration_match_finite_differences(body, beta_deg):
    """skew(omega) = dA/dt A^T and alpha = d(omega)/dt for every body."""
    beta = math.radians(beta_deg)
    m = motions_at(TIMES, beta)[body]
    fd_rot, tol_rot = derivative(lambda t: motions_at(t, beta)[body].rotation, TIMES)
    fd_omega, tol_omega = derivative(lambda t: motions_at(t, beta)[body].omega, TIMES)
    # each entry of dA/dt A^T sums three products with |A_ij| <= 1: at most 3 entry errors
    np.testing.assert_allclose(m.omega, vee(fd_rot @ np.swapaxes(m.rotation, -1, -2)),
                               rtol=0, atol=3 * tol_rot)
    np.testing.assert_allclose(m.alpha, fd_omega, rtol=0, atol=tol_omega)


def relative_rotation(t: np.ndarray, beta: float, pair: str) -> np.ndarray:
    """Rotation of body b's copy of the pair frame relative to body a's, in a's pair frame."""
    a, b = PAIR_BODIES[pair]
    now, ref = motions_at(t, beta), body_motions(0.0, 0.0, 0.0, beta)
    local = pair_frames_in_body_a()[pair]
    frame_a = now[a].rotation @ local
    frame_b = now[b].rotation @ ref[b].rotation.T @ ref[a].rotation @ local
    return np.swapaxes(frame_a, -1, -2) @ frame_b


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
@pytest.mark.parametrize("pair", PAIR_NAMES)
def test_pairs_turn_about_their_axes_at_the_relative_speed(pair, beta_deg):
    """Each pair's relative motion is a rotation about its z axis whose rate is omega_rel."""
    beta = math.radians(beta_deg)
    rel = relative_rotation(TIMES, beta, pair)
    # products of three rotation matrices: 20 ulp per entry
    np.testing.assert_allclose(rel[:, 2, 2], 1.0, rtol=0, atol=20 * EPS)
    np.testing.assert_allclose(rel[:, :2, 2], 0.0, rtol=0, atol=20 * EPS)
    omega_rel = relative_speeds(motions_at(TIMES, beta))[pair]
    fd_rot, tol_rot = derivative(lambda t: relative_rotation(t, beta, pair), TIMES)
    # see test_angular_velocity_and_acceleration_match_finite_differences for the factor 3
    np.testing.assert_allclose(omega_rel, vee(fd_rot @ np.swapaxes(rel, -1, -2))[:, 2],
                               rtol=0, atol=3 * tol_rot)
