"""RCCC loop in dual numbers (reference.physics.rccc) against Hooke's closed forms and its own closure."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reference.physics import dual, kinematics, rccc
from reference.physics.dual import Dual
from reference.physics.loop_closure import LoopClosureError
from reference.scene.joint import PAIR_BODIES, PAIR_NAMES

EPS = np.finfo(float).eps
DEG = math.pi / 180.0
SHAFT_ANGLES_DEG = [0.0, 1.0, 10.0, 30.0, 45.0, 70.0, 85.0]
TIMES = np.linspace(0.0, 6.5, 1301)  # the input below turns a little over two revolutions
# Mounting errors of the paper's section 4.2 (a_i = 0.5 mm, twist errors 6e-3 deg, i = 1, 2, 3) and
# a set 10 to 170 times larger on every parameter, the frame link's included.
PAPER_ERRORS = {"a": (0.5e-3,) * 3 + (0.0,), "alpha": (6e-3 * DEG,) * 3 + (0.0,)}
LARGE_ERRORS = {"a": (5e-3, -3e-3, 4e-3, 2e-3), "alpha": (1 * DEG, -1 * DEG, 0.5 * DEG, 1 * DEG),
                "s1": 2e-3}
ERROR_SETS = {"paper-literal": PAPER_ERRORS, "large": LARGE_ERRORS}
H = 5e-4  # difference step [s]: truncation ~1e-11 and rounding ~1e-10 of rates of a few rad/s


def input_motion(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Non-uniform input angle [rad], speed [rad/s] and acceleration [rad/s^2]."""
    return 0.3 + 2.0 * t + 0.5 * np.sin(3.0 * t), 2.0 + 1.5 * np.cos(3.0 * t), -4.5 * np.sin(3.0 * t)


def with_errors(shaft_angle_deg: float, errors: str) -> rccc.DHParameters:
    return rccc.DHParameters.ideal(shaft_angle_deg * DEG).with_errors(**ERROR_SETS[errors])


def closure_bounds(params: rccc.DHParameters, positions: rccc.LoopPositions) -> tuple[float, float]:
    """Rounding bounds of loop_closure_residual: real [-] and dual [m] part.

    The product has 8 factors with entries <= 1 and 7 matrix products of 3 terms: ~30 ulp, plus
    the solved angles' own few ulp, so 40 ulp; the dual part carries the same relative rounding
    on its lengths, the offsets and slides.
    """
    length = sum(abs(a) for a in params.a) + abs(params.s1) + np.max(np.sum(np.abs(positions.s), -1))
    # (the floor: with no offsets at all the dual part is rounding noise of denormal size)
    return 40 * EPS, 40 * EPS * length + np.finfo(float).tiny


def fd_derivative(f, t: np.ndarray, h: float = H) -> tuple[np.ndarray, np.ndarray]:
    """Fourth-order central difference of ``f(t)`` (shape (n, ...)) and a bound on its error.

    The bound (per trailing component) is twice the Richardson estimate of the O(h^4) truncation
    error, max |D(2h) - D(h)| / 15, plus the rounding of the quotient: weights of total size 18/12
    over h applied to values accurate to 8 ulp of their largest magnitude times the largest input
    angle (~13 rad), since the input angles enter the trigonometric functions rounded to
    eps |theta_1| and move every output about as much, relative to its size.
    """
    def quotient(step: float) -> np.ndarray:
        return (f(t - 2 * step) - 8 * f(t - step) + 8 * f(t + step) - f(t + 2 * step)) / (12 * step)

    d_h, d_2h = quotient(h), quotient(2 * h)
    value_error = 8 * EPS * np.max(np.abs(f(t)), axis=0) * max(1.0, np.max(np.abs(input_motion(t)[0])))
    return d_h, 2 * np.max(np.abs(d_2h - d_h), axis=0) / 15 + 1.5 * value_error / h


def assert_close_per_component(actual: np.ndarray, desired: np.ndarray, atol: np.ndarray,
                               err_msg: str = "") -> None:
    """``assert_allclose(rtol=0)`` with one absolute tolerance per trailing component."""
    actual, desired = np.broadcast_arrays(actual, desired)
    for k in np.ndindex(np.shape(atol)):
        np.testing.assert_allclose(actual[(...,) + k], desired[(...,) + k], rtol=0, atol=atol[k],
                                   err_msg=f"{err_msg} component {k}")


def vee(w: np.ndarray) -> np.ndarray:
    """Axial vectors of (nearly) skew matrices, shape (..., 3)."""
    return 0.5 * np.stack([w[..., 2, 1] - w[..., 1, 2], w[..., 0, 2] - w[..., 2, 0],
                           w[..., 1, 0] - w[..., 0, 1]], -1)


# ------------------------------------------------------------------------------ dual algebra


def test_dual_arithmetic_and_trigonometry():
    """eps^2 = 0, eq. (14) is f(x) + eps x' f'(x), atan2 inverts a dually scaled sin/cos pair."""
    x, y = Dual(0.7, 0.3), Dual(-1.2, 2.0)
    product = (x - 1.0) * (2.0 - y)
    np.testing.assert_allclose([product.re, product.du], [-0.3 * 3.2, -0.3 * -2.0 + 0.3 * 3.2])
    eps = Dual(0.0, 1.0)
    assert (eps * eps).re == 0.0 and (eps * eps).du == 0.0
    angle = Dual(np.linspace(-3.0, 3.0, 7), np.linspace(-0.01, 0.02, 7))
    np.testing.assert_allclose(dual.sin(angle).du, angle.du * np.cos(angle.re))
    np.testing.assert_allclose(dual.cos(angle).du, -angle.du * np.sin(angle.re))
    scale = Dual(2.5, -0.7)  # any dual number with positive real part
    back = dual.atan2(scale * dual.sin(angle), scale * dual.cos(angle))
    np.testing.assert_allclose([back.re, back.du], [angle.re, angle.du], rtol=0, atol=4 * EPS)


def test_lines_meet_at_their_dual_angle():
    """Two skew lines: S1 . S2 = cos(t + eps d) and S1 x S2 = sin(t + eps d) times their normal."""
    t, d = 0.8, 0.03  # angle [rad] and distance [m] from line 1 to line 2 along +z
    s1 = dual.line([1.0, 0.0, 0.0], [0.3, 0.0, 0.0])
    s2 = dual.line([math.cos(t), math.sin(t), 0.0], [0.0, 0.0, d])
    angle = Dual(t, d)
    cos_hat, sin_hat = dual.cos(angle), dual.sin(angle)
    dot = dual.dot(s1, s2)
    np.testing.assert_allclose([dot.re, dot.du], [cos_hat.re, cos_hat.du], rtol=0, atol=4 * EPS)
    cross = dual.cross(s1, s2)
    normal = dual.line([0.0, 0.0, 1.0], [0.0, 0.0, 0.0])  # the common normal, the z axis
    np.testing.assert_allclose(cross.re, sin_hat.re * normal.re, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(cross.du, (sin_hat * normal).du, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(dual.line_point(s2), [0.0, 0.0, d], rtol=0, atol=4 * EPS)


def test_screw_transform_is_the_rigid_displacement():
    """Z(t + eps s) X(a + eps l) rotates by Rz(t) Rx(a), translates by s e_z + Rz(t) l e_x."""
    theta, alpha = Dual(0.4, 0.02), Dual(1.1, -0.05)
    rotation, translation = dual.displacement(dual.screw_transform(theta, alpha))
    np.testing.assert_allclose(rotation, kinematics.rot_z(0.4) @ kinematics.rot_x(1.1), atol=4 * EPS)
    np.testing.assert_allclose(translation, [-0.05 * math.cos(0.4), -0.05 * math.sin(0.4), 0.02],
                               rtol=0, atol=4 * EPS)
    m = dual.screw_transform(theta, alpha)
    identity = m @ m.T
    np.testing.assert_allclose(identity.re, np.eye(3), rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(identity.du, 0.0, rtol=0, atol=4 * EPS)
    b = Dual(np.array([0.3, -1.0, 2.0]), np.array([0.01, 0.0, -0.02]))
    x = dual.solve(m, b)
    back = dual.matvec(m, x)
    np.testing.assert_allclose([back.re, back.du], [b.re, b.du], rtol=0, atol=8 * EPS)


# ------------------------------------------------------------------ the ideal joint is Hooke's


@pytest.mark.parametrize("beta_deg", SHAFT_ANGLES_DEG, ids=[f"{b:g}deg" for b in SHAFT_ANGLES_DEG])
@pytest.mark.parametrize("branch", rccc.BRANCHES)
def test_ideal_joint_reproduces_hooke(beta_deg, branch):
    """Output and spider angles, speeds, accelerations equal the closed forms; no slides."""
    beta = beta_deg * DEG
    motion = input_motion(TIMES)
    positions, rates = rccc.solve_motion(rccc.DHParameters.ideal(beta), *motion, branch=branch)
    # Angles up to 4.3 pi: the dual route and the closed form each round a few times at the scale
    # of theta (eps * 13.5 rad = 3e-15 rad): 10 ulp of the largest input angle, 3e-14 rad.
    # Rates come from a linear solve whose joint-axis matrix has a condition number of about
    # 2 / cos(beta) (23 at 85 deg): 50 ulp of the largest value, times 1 / cos(beta).
    angle_tol = 10 * EPS * np.max(np.abs(motion[0]))
    got = rccc.output_motion(positions, rates) + rccc.spider_motion(positions, rates)
    want = kinematics.output_motion(*motion, beta) + kinematics.spider_motion(*motion, beta)
    for k, name in enumerate(["theta_out", "omega_out", "alpha_out", "gamma", "gamma_t", "gamma_tt"]):
        scale = max(np.max(np.abs(want[k])), 1.0)  # gamma is 0 at 0 deg; its rounding is at 1 rad
        tol = angle_tol if k % 3 == 0 else 50 * EPS * scale / math.cos(beta)
        np.testing.assert_allclose(got[k], want[k], rtol=0, atol=tol, err_msg=name)
    # all a_k, s_1 are zero, so every dual part is a sum of products with an exact zero
    for values in (positions.s, rates.s_t, rates.s_tt):
        np.testing.assert_array_equal(values, 0.0)


@pytest.mark.parametrize("beta_deg", [0.0, 30.0, 85.0], ids=["0deg", "30deg", "85deg"])
def test_ideal_joint_bodies_and_pairs_match_kinematics(beta_deg):
    """Body frames, angular motion, pair axes and relative speeds equal reference.physics.kinematics."""
    beta = beta_deg * DEG
    motion = input_motion(TIMES)
    params = rccc.DHParameters.ideal(beta)
    positions, rates = rccc.solve_motion(params, *motion)
    got, want = rccc.body_motions(params, positions, rates), kinematics.body_motions(*motion, beta)
    scale = 1.0 / math.cos(beta)  # condition of the rate equations, as in the Hooke test
    for body in want:
        np.testing.assert_allclose(got[body].rotation, want[body].rotation, rtol=0, atol=20 * EPS)
        for field in ("omega", "alpha"):
            w = getattr(want[body], field)
            np.testing.assert_allclose(getattr(got[body], field), w, rtol=0,
                                       atol=50 * EPS * scale * max(np.max(np.abs(w)), 1.0))
        for field in ("origin", "velocity", "acceleration"):
            np.testing.assert_array_equal(getattr(got[body], field), 0.0)
    frames = kinematics.pair_frames(want)
    axes = rccc.pair_axes(params, positions)
    speeds = kinematics.relative_speeds(want)
    pairs = rccc.pair_motions(positions, rates)
    for pair in PAIR_NAMES:
        np.testing.assert_allclose(axes[pair][0], frames[pair][..., :, 2], rtol=0, atol=20 * EPS)
        np.testing.assert_array_equal(axes[pair][1], 0.0)
        np.testing.assert_allclose(pairs[pair].speed, speeds[pair], rtol=0,
                                   atol=50 * EPS * scale * max(np.max(np.abs(speeds[pair])), 1.0))


def test_ideal_reference_configuration_is_the_scene():
    """At theta_1 = 0 the joint angles are (0, 90, 90 + b, 90) deg and the bodies canonical."""
    beta = 20 * DEG
    positions = rccc.solve_positions(rccc.DHParameters.ideal(beta), 0.0)
    np.testing.assert_allclose(positions.reference, [0.0, 0.5 * np.pi, 0.5 * np.pi + beta, 0.5 * np.pi],
                               rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(positions.theta, positions.reference, rtol=0, atol=4 * EPS)
    poses = rccc.body_poses(rccc.DHParameters.ideal(beta), positions)
    c, s = math.cos(beta), math.sin(beta)
    for body in ("ground", "input", "spider"):
        np.testing.assert_allclose(poses[body].rotation, np.eye(3), rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(poses["output"].rotation, [[c, -s, 0], [s, c, 0], [0, 0, 1]],
                               rtol=0, atol=4 * EPS)


# ------------------------------------------------------------------------ with mounting errors


@pytest.mark.parametrize("beta_deg", [0.0, 15.0, 45.0, 85.0], ids=lambda b: f"{b:g}deg")
@pytest.mark.parametrize("errors", sorted(ERROR_SETS))
@pytest.mark.parametrize("branch", rccc.BRANCHES)
def test_loop_closes_at_every_sample(beta_deg, errors, branch):
    """The dual product of the eight screw transforms is the identity to rounding."""
    params = with_errors(beta_deg, errors)
    positions = rccc.solve_positions(params, input_motion(TIMES)[0], branch)
    real, dual_part = rccc.loop_closure_residual(params, positions)
    bound_real, bound_dual = closure_bounds(params, positions)
    assert real <= bound_real
    assert dual_part <= bound_dual
    assert np.ptp(positions.s[:, 0]) == 0.0 and positions.s[0, 0] == params.s1


@pytest.mark.parametrize("errors", sorted(ERROR_SETS))
def test_branches_differ_and_both_close(errors):
    """The two assemblies are distinct solutions of the same loop."""
    params = with_errors(15.0, errors)
    theta1 = input_motion(TIMES)[0]
    hooke, flipped = (rccc.solve_positions(params, theta1, b) for b in rccc.BRANCHES)
    gap = np.angle(np.exp(1j * (hooke.theta[:, 1:] - flipped.theta[:, 1:])))
    assert np.min(np.abs(gap)) > 1.0  # for the ideal joint the spider and output differ by pi
    for positions in (hooke, flipped):
        real, dual_part = rccc.loop_closure_residual(params, positions)
        assert real <= closure_bounds(params, positions)[0]
        assert dual_part <= closure_bounds(params, positions)[1]


def positions_at(params: rccc.DHParameters, branch: str):
    def f(t: np.ndarray) -> np.ndarray:
        p = rccc.solve_positions(params, input_motion(t)[0], branch)
        return np.concatenate([p.theta, p.s], -1)
    return f


def rates_at(params: rccc.DHParameters, branch: str):
    def f(t: np.ndarray) -> np.ndarray:
        _, r = rccc.solve_motion(params, *input_motion(t), branch=branch)
        return np.concatenate([r.theta_t, r.s_t], -1)
    return f


@pytest.mark.parametrize("beta_deg", [15.0, 45.0], ids=lambda b: f"{b:g}deg")
@pytest.mark.parametrize("errors", sorted(ERROR_SETS))
@pytest.mark.parametrize("branch", rccc.BRANCHES)
def test_rates_are_time_derivatives(beta_deg, errors, branch):
    """Analytic joint speeds and accelerations equal differences of positions and speeds."""
    params = with_errors(beta_deg, errors)
    t = TIMES[::4]
    _, rates = rccc.solve_motion(params, *input_motion(t), branch=branch)
    fd_speed, tol_speed = fd_derivative(positions_at(params, branch), t)
    fd_accel, tol_accel = fd_derivative(rates_at(params, branch), t)
    assert_close_per_component(np.concatenate([rates.theta_t, rates.s_t], -1), fd_speed, tol_speed)
    assert_close_per_component(np.concatenate([rates.theta_tt, rates.s_tt], -1), fd_accel, tol_accel)


@pytest.mark.parametrize("body", ["input", "spider", "output"])
def test_body_motions_are_time_derivatives(body):
    """omega = vee(dR/dt R^T), alpha = d(omega)/dt, and the origin's velocity and acceleration."""
    params = with_errors(30.0, "large")
    t = TIMES[::4]

    def motion(s: np.ndarray) -> rccc.BodyMotion:
        return rccc.body_motions(params, *rccc.solve_motion(params, *input_motion(s)))[body]

    now = motion(t)
    fd_rot, tol_rot = fd_derivative(lambda s: motion(s).rotation, t)
    # each entry of dR/dt R^T sums three products with |R_ij| <= 1: at most 3 entry errors
    np.testing.assert_allclose(now.omega, vee(fd_rot @ np.swapaxes(now.rotation, -1, -2)), rtol=0,
                               atol=3 * np.max(tol_rot))
    for field, rate in (("omega", "alpha"), ("origin", "velocity"), ("velocity", "acceleration")):
        fd, tol = fd_derivative(lambda s, f=field: getattr(motion(s), f), t)
        # the components of one vector share its rounding scale: one tolerance for all three
        np.testing.assert_allclose(getattr(now, rate), fd, rtol=0, atol=np.max(tol), err_msg=rate)


@pytest.mark.parametrize("pair", PAIR_NAMES)
def test_pair_axes_are_fixed_in_both_bodies(pair):
    """Each joint axis keeps its direction and moment in the frames of the two bodies it joins."""
    params = with_errors(30.0, "large")
    positions = rccc.solve_positions(params, input_motion(TIMES)[0])
    poses = rccc.body_poses(params, positions)
    direction, point = rccc.pair_axes(params, positions)[pair]
    screw = rccc.joint_screws(params, positions)[:, PAIR_NAMES.index(pair)]
    rebuilt = dual.line(direction, point)  # renormalised direction: 2 ulp; moments < 0.1 m
    np.testing.assert_allclose(rebuilt.re, screw.re, rtol=0, atol=2 * EPS)
    np.testing.assert_allclose(rebuilt.du, screw.du, rtol=0, atol=4 * EPS * 0.1)
    # joint 1 is the global x axis by construction; the errors move the others off the origin
    assert (np.max(np.abs(screw.du)) > 1e-4) == (pair != "frame_input")
    for body in PAIR_BODIES[pair]:
        rot_t = np.swapaxes(poses[body].rotation, -1, -2)
        local_u = np.einsum("...ij,...j->...i", rot_t, direction)
        local_m = np.einsum("...ij,...j->...i", rot_t,
                            np.cross(point - poses[body].origin, direction))
        # unit vectors and moments of a few cm, each through ~6 roundings per component
        np.testing.assert_allclose(local_u, np.broadcast_to(local_u[0], local_u.shape), rtol=0,
                                   atol=20 * EPS, err_msg=body)
        np.testing.assert_allclose(local_m, np.broadcast_to(local_m[0], local_m.shape), rtol=0,
                                   atol=20 * EPS * 0.1, err_msg=body)


@settings(max_examples=40, deadline=None)
@given(beta_deg=st.floats(0.0, 80.0),
       a=st.tuples(*[st.floats(-5e-3, 5e-3)] * 4),
       alpha=st.tuples(*[st.floats(-1.0, 1.0)] * 4),
       s1=st.floats(-5e-3, 5e-3),
       branch=st.sampled_from(rccc.BRANCHES),
       phase=st.floats(0.0, 2 * np.pi))
def test_small_errors_always_close(beta_deg, a, alpha, s1, branch, phase):
    """Any errors up to 5 mm and 1 deg: the loop closes to rounding and the velocity screws sum to 0."""
    params = rccc.DHParameters.ideal(beta_deg * DEG).with_errors(
        a=a, alpha=tuple(x * DEG for x in alpha), s1=s1)
    theta1 = phase + np.linspace(0.0, 2 * np.pi, 64)
    positions, rates = rccc.solve_motion(params, theta1, 1.0, 0.0, branch=branch)
    real, dual_part = rccc.loop_closure_residual(params, positions)
    bound_real, bound_dual = closure_bounds(params, positions)
    assert real <= bound_real and dual_part <= bound_dual
    screws = rccc.joint_screws(params, positions)
    total = (Dual(rates.theta_t, rates.s_t)[..., None] * screws).sum(-2)
    # rates of order 1 / cos(beta) rad/s (6 at 80 deg) times axes of unit length or moments < 0.1 m
    assert np.max(np.abs(total.re)) <= 100 * EPS / math.cos(beta_deg * DEG)
    assert np.max(np.abs(total.du)) <= 100 * EPS / math.cos(beta_deg * DEG)


# ------------------------------------------------------------------------------------- errors


def test_open_loop_names_the_angles():
    """A spider twist too small for the frame and input twists leaves a gap near theta_1 = pi."""
    # |z_2' . e_z| reaches cos(150 deg) at pi: the loop needs cos^2(alpha_2) <= 1/4 there
    params = rccc.DHParameters(alpha=(120 * DEG, 45 * DEG, 90 * DEG, -30 * DEG))
    theta1 = np.linspace(0.0, 2 * np.pi, 13)
    with pytest.raises(LoopClosureError, match=r"cannot close .* theta_1 = \[2.61799, 3.14159, "
                       r"3.66519\] rad") as info:
        rccc.solve_positions(params, theta1)
    np.testing.assert_array_equal(info.value.angles, theta1[[5, 6, 7]])
    assert isinstance(info.value, ValueError)


def test_meeting_branches_are_singular():
    """With cos^2(alpha_2) = 1/4 the branches touch at theta_1 = pi: a singular configuration."""
    params = rccc.DHParameters(alpha=(120 * DEG, 60 * DEG, 90 * DEG, -30 * DEG))
    with pytest.raises(LoopClosureError, match=r"branches meet .* theta_1 = \[3.14159\] rad"):
        rccc.solve_positions(params, [0.5, np.pi, 1.0])
    rccc.solve_positions(params, [0.5, 1.0, np.pi - 0.1])


def test_loop_must_close_at_the_reference():
    """Angles are measured from theta_1 = 0, so a loop that cannot close there is refused."""
    params = rccc.DHParameters(alpha=(90 * DEG, 10 * DEG, 90 * DEG, -30 * DEG))
    with pytest.raises(LoopClosureError, match="reference input angle theta_1 = \\[0\\]"):
        rccc.solve_positions(params, [1.5])


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"alpha": (1.0, 1.0, 1.0)}, r"`alpha` must be a sequence of 4"),
    ({"alpha": "abcd"}, r"`alpha` must be a sequence of 4"),
    ({"alpha": (1.0, np.inf, 1.0, 0.0)}, r"`alpha\[1\]` must be finite"),
    ({"alpha": (1.0, 0.0, 1.0, 0.0)}, r"`alpha\[1\]` \(twist of the spider\) must be in \(0, 180\)"),
    ({"alpha": (1.0, 1.0, 1.0, 1.6)}, r"`alpha\[3\]` .* must be in \(-90, 90\)"),
    ({"alpha": (1.0, 1.0, 1.0, 0.0), "a": (0.0, 0.0, None, 0.0)}, r"`a\[2\]` must be a number"),
    ({"alpha": (1.0, 1.0, 1.0, 0.0), "s1": math.nan}, r"`s1` must be finite"),
], ids=["short", "string", "inf", "zero-twist", "shaft-90", "none-offset", "nan-s1"])
def test_bad_parameters_are_named(kwargs, match):
    """Invalid D-H parameters raise ValueError naming the field and the value."""
    with pytest.raises(ValueError, match=match):
        rccc.DHParameters(**kwargs)


def test_bad_shaft_angle_and_errors_are_named():
    """ideal() and with_errors() validate their arguments."""
    with pytest.raises(ValueError, match=r"`shaft_angle` must be in \[0, 90\) deg, got 90.0"):
        rccc.DHParameters.ideal(0.5 * math.pi)
    with pytest.raises(ValueError, match=r"`a` must be a sequence of 4"):
        rccc.DHParameters.ideal(0.1).with_errors(a=(1e-3, 1e-3))
    with pytest.raises(ValueError, match=r"`alpha\[0\]` \(twist of the input\)"):
        rccc.DHParameters.ideal(0.1).with_errors(alpha=(-2.0, 0.0, 0.0, 0.0))


def test_bad_samples_are_named():
    """Input angles, speeds and accelerations must be finite numbers of matching shape."""
    params = rccc.DHParameters.ideal(0.2)
    with pytest.raises(ValueError, match=r"`theta1` must be finite"):
        rccc.solve_positions(params, [0.0, np.nan])
    with pytest.raises(ValueError, match=r"`theta1` must be a numeric array"):
        rccc.solve_positions(params, ["a"])
    with pytest.raises(ValueError, match=r"`branch` must be one of \['hooke', 'flipped'\], got 'open'"):
        rccc.solve_positions(params, 0.0, branch="open")
    positions = rccc.solve_positions(params, np.linspace(0.0, 1.0, 5))
    with pytest.raises(ValueError, match=r"`theta1_t` must broadcast to the shape \(5,\) .* \(3,\)"):
        rccc.solve_rates(params, positions, np.ones(3), 0.0)
    with pytest.raises(ValueError, match=r"`theta1_tt` must be finite"):
        rccc.solve_rates(params, positions, 1.0, np.inf)


def test_modules_use_numpy_only():
    """dual.py, loop_closure.py and the rccc package import nothing but numpy, the standard
    library and reference."""
    root = Path(rccc.__file__).resolve().parents[1]
    allowed = {"__future__", "collections", "dataclasses", "functools", "math", "numpy", "reference"}
    names = ["dual.py", "loop_closure.py", *(f"rccc/{p.name}" for p in sorted((root / "rccc").glob("*.py")))]
    assert len(names) > 3
    for name in names:
        tree = ast.parse((root / name).read_text(encoding="utf-8"))
        roots = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        roots |= {n.module.split(".")[0] for n in ast.walk(tree)
                  if isinstance(n, ast.ImportFrom) and n.module}
        assert roots <= allowed, name
