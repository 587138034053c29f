"""Fast forward dynamics (reference.engine.forward): the series right-hand side against the direct solve.

The direct solve (:func:`reference.engine.dynamics.solve_dynamics` per sample) is the reference engine's
right-hand side before the series; it stays reachable as ``method="direct"``. Both build the
same Newton-Euler equations, so they must agree to rounding, friction and the self-locking
verdict included. The direct solve's own rounding is about 1e-12 of the acceleration (its
forward system takes the acceleration's column as a difference of two right-hand sides, which
cancels about three digits against gravity); its inverse-dynamics residual (below) shows it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import cardan_exudyn
from reference.engine.dynamics import solve_dynamics
from reference.engine.forward import ForwardDynamics, right_hand_side
from reference.engine.newton_euler import reaction_system
from reference.engine.series import fit_periodic
from reference.engine.slots import (
    FrictionLaw,
    friction_matrix,
    friction_slots,
    slot_bands,
    slot_signs,
    slot_speeds,
)
from reference.paper.scenes import named_scene
from reference.physics.joint_motion import joint_motion
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace

SPEED = 209.44  # 2000 rpm [rad/s], the paper's speed
AGREE = 1e-10
"""Relative to the largest acceleration: 50 times the direct solve's rounding (measured 2e-12);
a wrong part of the system, a wrong sign or an unresolved series would be off by 1e-6 or more."""


def torque_scene(name: str, torque: float, **changes) -> object:
    return replace(named_scene(name), drive={"kind": "torque", "torque": torque, "initial_speed": SPEED},
                   **changes)


def random_states(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Angles over several revolutions (either sign) and speeds either way, from rest to 1.5x."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-20.0, 20.0, n), rng.uniform(-1.5, 1.5, n) * SPEED


def series_states(fast: ForwardDynamics, theta, theta_t, load=None):
    loads = [None] * len(theta) if load is None else load
    return [fast.solve(a, w, f) for a, w, f in zip(theta, theta_t, loads, strict=True)]


SCENES = {
    "literal-10deg": ("paper-literal-10deg", 4.25, {}),  # gravity, eccentric bodies
    "literal-35deg": ("paper-literal-35deg", 8.0, {}),
    "physical-45deg": ("paper-45deg", 2.2, {}),
    "rig-errors": ("rig-matched-errors", 0.3, {}),  # mounting errors: the pairs slide
    "rig-errors-resultant": ("rig-physical-errors", 0.3, {}),  # resultant-slip law
    "uncoupled": ("paper-literal-10deg", 4.25, {"friction.coupling": "uncoupled"}),
    "exact-sign": ("rig-matched-errors", 0.3, {"friction.sign_band": 0.0}),  # no ramps
    # loop gains up to 0.93: Newton's warm start hands over to solve_friction's start
    "rig-errors-near-locking": ("rig-matched-errors", 8.0, {f"joint.pairs.{p}.friction_coefficient": 0.5
                                                           for p in PAIR_NAMES}),
}


@pytest.mark.parametrize("key", list(SCENES), ids=list(SCENES))
def test_series_equals_the_direct_solve(key):
    """Acceleration and friction values at random states equal solve_dynamics'; so does the
    self-locking verdict, and the loop gain bounds the spectral radius."""
    name, torque, changes = SCENES[key]
    scene = torque_scene(name, torque, **changes)
    fast = ForwardDynamics.of_scene(scene, torque)
    assert fast is not None
    theta, theta_t = random_states(60)
    _, direct = solve_dynamics(scene, theta, theta_t, torque_in=torque)
    states = series_states(fast, theta, theta_t)
    accel = np.array([s.acceleration for s in states])
    scale = np.max(np.abs(direct.x[:, -1]))
    np.testing.assert_allclose(accel, direct.x[:, -1], rtol=0, atol=AGREE * scale)
    friction = np.array([s.friction for s in states])
    np.testing.assert_allclose(friction, direct.friction, rtol=0,
                               atol=AGREE * max(np.max(np.abs(direct.friction)), 1e-300))
    assert [s.self_locking for s in states] == direct.self_locking.tolist()
    # the series gives the spectral radius or an upper bound (an infinity norm) below 0.9; the
    # direct solve the radius from 0.5 on (a norm below, over all seven slots: not comparable).
    # The warm-started radius is that of the last Newton Jacobian (1e-7 relative measured).
    gain = np.array([s.loop_gain for s in states])
    exact = direct.loop_gain >= 0.5
    assert np.all(gain[exact] >= direct.loop_gain[exact] * (1.0 - 1e-6))


def equation_residuals(scene, torque, theta, theta_t, accel, friction):
    """Newton-Euler with the acceleration and the friction values given (no fixed point, no
    forward system): the relative error of the drive torque it needs, and of the friction law
    (eqs. (3), (5)) at its reactions, per sample."""
    motion = joint_motion(scene.joint, theta, theta_t, accel)
    matrix, rhs = reaction_system(scene, motion)
    slots = friction_slots(scene)
    wrenches = friction_matrix(motion, slots)
    x = np.linalg.solve(matrix, (rhs - np.einsum("nik,nk->ni", wrenches, friction))[..., None])[..., 0]
    speeds = slot_speeds(scene, slots, motion.omega_rel, motion.slide_rel)
    law, _ = FrictionLaw(scene, slots)(x, slot_signs(scene, slots, speeds, slot_bands(scene, slots)))
    return (np.abs(x[:, -1] - torque) / abs(torque),
            np.max(np.abs(law - friction), 1) / np.max(np.abs(friction), 1))


@pytest.mark.parametrize("name, torque, f", [("paper-literal-35deg", 8.0, None),
                                             ("rig-matched-errors", 0.3, None),
                                             ("paper-literal-50deg", 8.0, 0.8)],
                         ids=["35deg", "errors", "near-locking"])
def test_series_satisfies_the_equations(name, torque, f):
    """Independent check: the series' acceleration and friction satisfy the Newton-Euler
    equations and the friction law to 1e-12 (drive torque) and 1e-10 (friction) over a
    revolution. Measured: series 3e-14 / 2e-11, the direct solve 1e-9 / 2e-10 near locking (its
    forward system cancels digits; the friction loop amplifies them)."""
    changes = {} if f is None else {f"joint.pairs.{p}.friction_coefficient": f for p in PAIR_NAMES}
    scene = torque_scene(name, torque, **changes)
    fast = ForwardDynamics.of_scene(scene, torque)
    theta = np.linspace(0.0, 2.0 * math.pi, 361)
    theta_t = np.full(theta.shape, SPEED)
    states = series_states(fast, theta, theta_t)
    ok = ~np.array([s.self_locking for s in states])
    torque_error, friction_error = equation_residuals(
        scene, torque, theta[ok], theta_t[ok], np.array([s.acceleration for s in states])[ok],
        np.array([s.friction for s in states])[ok])
    assert np.max(torque_error) < 1e-12 and np.max(friction_error) < 1e-10


def locking_scene(torque: float, **changes):
    """Literal set at 50 deg with f = 0.8 in every pair: under a torque drive at 2000 rpm the
    friction loop gain crosses 1 within the revolution (43 of 361 samples lock)."""
    return torque_scene("paper-literal-50deg", torque, **changes,
                        **{f"joint.pairs.{p}.friction_coefficient": 0.8 for p in PAIR_NAMES})


def test_self_locking_verdict_near_the_boundary():
    """Where the loop gain crosses 1, along the revolution (Newton warm-started from the previous
    sample, as in the integrator) and sample by sample, the series flags exactly the samples the
    direct solve flags, and agrees on the others' accelerations."""
    torque = 8.0
    scene = locking_scene(torque)
    theta = np.linspace(0.0, 2.0 * math.pi, 721)
    theta_t = np.full(theta.shape, SPEED)
    _, direct = solve_dynamics(scene, theta, theta_t, torque_in=torque)
    assert 0 < np.count_nonzero(direct.self_locking) < theta.size
    along = ForwardDynamics.of_scene(scene, torque)
    states = series_states(along, theta, theta_t)
    assert [s.self_locking for s in states] == direct.self_locking.tolist()
    fresh = [ForwardDynamics.of_scene(scene, torque).solve(a, w) for a, w in zip(theta[::20], theta_t[::20],
                                                                                 strict=True)]
    assert [s.self_locking for s in fresh] == direct.self_locking[::20].tolist()
    ok = ~direct.self_locking
    accel = np.array([s.acceleration for s in states])
    # near locking the direct solve's own error reaches 1e-9 (test_series_satisfies_the_equations)
    np.testing.assert_allclose(accel[ok], direct.x[ok, -1], rtol=1e-8)


def test_load_history_enters_per_call():
    """A measured load (a history): the series takes it per call; the callable reads it at t."""
    torque = 0.3
    t = np.linspace(0.0, 1.0, 50)
    load = {"torque": (0.2 + 0.05 * np.sin(7.0 * t)).tolist(), "time": t.tolist()}
    scene = torque_scene("rig-matched-errors", torque, load=load)
    load = scene.load
    fast = ForwardDynamics.of_scene(scene, torque)
    times = np.linspace(0.0, 1.0, 30)
    theta, theta_t = random_states(30, seed=2)
    _, direct = solve_dynamics(scene, theta, theta_t, torque_in=torque, load_torque=load.at(times))
    accel = np.array([fast(tt, a, w)[0] for tt, a, w in zip(times, theta, theta_t, strict=True)])
    np.testing.assert_allclose(accel, direct.x[:, -1], rtol=0,
                               atol=AGREE * np.max(np.abs(direct.x[:, -1])))
    with pytest.raises(ValueError, match="`load`"):
        fast.solve(0.0, 1.0)


def test_short_run_agrees_with_the_direct_right_hand_side():
    """A quarter revolution integrated with both right-hand sides (DOP853, rtol 1e-10): the
    trajectories agree to the integrator's tolerance (measured 1.4e-13 relative). Not at the
    very end: the last step crosses a friction ramp's kink there and the two step sequences end
    1e-7 apart in speed (an integrator error, both right-hand sides agreeing to 1e-12)."""
    torque = 4.25
    scene = torque_scene("paper-literal-10deg", torque)
    span = 0.5 * math.pi / SPEED
    runs = []
    for method in ("series", "direct"):
        accel = right_hand_side(scene, torque, method)

        def rhs(t, y, accel=accel):
            return np.array([y[1], accel(t, float(y[0]), float(y[1]))[0]])

        runs.append(solve_ivp(rhs, (0.0, span), [0.0, SPEED], method="DOP853", dense_output=True,
                              rtol=1e-10, atol=[1e-10, 1e-10 * SPEED]))
    t = np.linspace(0.0, 0.95 * span, 50)
    series, direct = (r.sol(t) for r in runs)
    assert runs[0].success and runs[1].success
    np.testing.assert_allclose(series[0], direct[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(series[1], direct[1], rtol=1e-9)


def test_engine_run_uses_the_series_and_reports_its_cost():
    """Through the dispatch: a torque-driven paper scene runs with the series right-hand side,
    counts its evaluations, and stops after the requested revolution."""
    scene = torque_scene("paper-10deg", 2.05, revolutions=1)
    assert isinstance(right_hand_side(scene, 2.05), ForwardDynamics)
    result = cardan_exudyn.run(scene, engine="reference")
    s = result.summary
    assert s.status == "ok" and s.ode_evaluations > 100
    assert result.table["theta_in"].iloc[-1] == pytest.approx(2.0 * math.pi, rel=1e-12)
    assert 0.9 < s.mean_efficiency < 1.0


def test_engine_self_locking_under_a_torque_drive():
    """The integrator stops where friction locks (here at the start: at 1000 rad/s the loop gain
    at 0 deg exceeds 1), with the status and the angle in the reason."""
    scene = replace(locking_scene(8.0, revolutions=1), **{"drive.initial_speed": 1000.0})
    result = cardan_exudyn.run(scene, engine="reference")
    assert result.summary.status == "self_locking" and "input angle 0 deg" in result.summary.reason
    assert result.summary.ode_evaluations >= 1


def test_loop_that_cannot_close_is_still_a_status():
    """Mounting errors the loop cannot close with: no series; the engine reports the status as
    before (the sign bands, needed by either right-hand side, cannot be sized)."""
    scene = replace(torque_scene("paper-literal-30deg-frictionless", 2.0),
                    **{"joint.errors.alpha1_deg": -60.0, "joint.errors.alpha2_deg": -60.0})
    assert ForwardDynamics.of_scene(scene, 2.0) is None
    assert cardan_exudyn.run(scene, engine="reference").summary.status == "loop_does_not_close"
    with pytest.raises(ValueError, match="`method`"):
        right_hand_side(scene, 2.0, "fast")


def test_fit_periodic_resolves_or_refuses():
    """``1 / (1.25 - cos)`` has harmonics falling as 0.5^k: resolved to rounding on 256 points,
    refused on 64 (its harmonic 16, at n/4, is still 2e-5 of its size)."""
    def f(theta):
        return 1.0 / (1.25 - np.cos(theta))

    for n, resolved in ((64, False), (256, True)):
        theta = 2.0 * math.pi * np.arange(n) / n
        values = f(theta)[:, None]
        series = fit_periodic(values, np.max(np.abs(values), 0))
        assert (series is not None) == resolved
    x = np.linspace(-7.0, 7.0, 101)
    np.testing.assert_allclose([series(v)[0] for v in x], f(x), rtol=1e-14)
