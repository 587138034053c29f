"""The reference engine with friction: balance laws, the friction law, self-locking, drives,
quadrature self-convergence. Exudyn is not involved (see test_compare.py for that)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from test_reference_dynamics import EPS, energy_rate, external_wrench, momentum
from test_reference_kinematics import derivative

from reference.engine.newton_euler import reaction_system
from reference.engine.options import ReferenceOptions
from reference.engine.solve import run
from reference.engine.table import EXTRA_COLUMNS
from reference.paper.scenes import named_scene, paper_scene
from reference.physics.friction import friction_from_columns
from reference.physics.joint_motion import joint_motion
from reference.results.columns import table_columns
from reference.results.summary import Status
from reference.scene.drives import AngleDrive, TorqueDrive
from reference.scene.mapping import replace
from reference.scene.scene import Scene

FRICTION_SCENES = ["paper-literal-10deg", "paper-literal-35deg", "paper-matched-20deg"]


def one_revolution(name: str, **changes) -> Scene:
    return replace(named_scene(name), revolutions=1, **changes)


@pytest.mark.parametrize("name", FRICTION_SCENES)
def test_applied_friction_is_the_law_of_the_reported_reactions(name):
    """Every sample's friction equals eqs. (3), (5) (reference.physics.friction, written separately)
    applied to the reactions and speeds the engine reports: the fixed point is solved."""
    table = run(one_revolution(name), ReferenceOptions(samples_per_revolution=90)).table
    law = friction_from_columns(named_scene(name), table)
    for pair, (torque, force) in law.items():
        got = table[f"{pair}_friction_torque"].to_numpy()
        # Newton stops when its update is <= 1e-13 of the largest friction value; the law is
        # evaluated from reactions rounded at ~1e-15 relative: allow 1e-12 of the scale
        scale = np.max(np.abs(torque)) + 1e-300
        np.testing.assert_allclose(got, torque, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(table[f"{pair}_friction_force"], force, rtol=0,
                                   atol=1e-12 * (np.max(np.abs(force)) + 1e-300))
    assert not table["self_locking"].any()


@pytest.mark.parametrize("name", FRICTION_SCENES)
def test_power_balance_with_friction_at_every_sample(name):
    """P_in - P_out - P_loss = dE/dt at every sample (energy rate from the kinematics alone)."""
    scene = one_revolution(name)
    table = run(scene, ReferenceOptions(samples_per_revolution=90)).table
    theta, omega = table["theta_in"].to_numpy(), table["omega_in"].to_numpy()
    rate, scale, _, _ = energy_rate(scene, theta, omega)
    scale = scale + np.abs(table["power_in"]) + np.abs(table["power_out"]) + table["power_loss"]
    matrix, _ = reaction_system(scene, joint_motion(scene.joint, theta, omega, 0 * omega))
    # rounding of the solves (condition number cond), amplified by the friction loop (gain
    # <= 1 / (1 - max gain)): 10 cond ulp of the largest term, times that amplification
    gain = table["friction_loop_gain"].max()
    tol = 10 * np.max(np.linalg.cond(matrix)) * EPS * scale / (1.0 - gain)
    residual = table["power_in"] - table["power_out"] - table["power_loss"] - rate
    assert np.all(np.abs(residual) <= tol), f"max residual / tol {np.max(np.abs(residual) / tol)}"
    assert np.all(table["power_loss"] >= 0.0)


@pytest.mark.parametrize("name", ["paper-literal-10deg", "paper-literal-35deg"])
def test_momentum_balance_with_friction(name):
    """Ground reactions, their friction torques, drive, load and gravity change the momenta."""
    scene = one_revolution(name)
    table = run(scene, ReferenceOptions(samples_per_revolution=90)).table
    t = table["t"].to_numpy()
    rate, tol_fd = derivative(lambda x: momentum(scene, x), t, h=1e-3 * t[-1])
    wrench = external_wrench(scene, table)
    tol = tol_fd + 1e3 * EPS * np.max(np.abs(wrench)) / (1.0 - table["friction_loop_gain"].max())
    np.testing.assert_allclose(wrench, rate, rtol=0, atol=tol)


@pytest.mark.parametrize("name", FRICTION_SCENES)
def test_work_quadrature_closes_the_energy_balance(name):
    """W_in - W_out - W_loss - change of energy, from the quadrature, is at rounding level."""
    s = run(named_scene(name)).summary
    assert s.status is Status.OK and s.revolutions == 2
    # the quadrature is accepted at 1e-9 of W_in per panel; the balance holds node by node,
    # so only rounding of the sums (~1e3 nodes, terms <= 1e3 W) remains: 1e-12 W_in
    assert abs(s.extras["energy_balance_residual"]) <= 1e-12 * s.input_work
    assert s.loss_work == pytest.approx(sum(s.pair_loss_work[p] for p in
                                            ("frame_input", "input_spider", "spider_output",
                                             "output_frame")), rel=1e-13)


@pytest.mark.parametrize("name", ["paper-literal-10deg", "paper-literal-35deg", "paper-matched-20deg"])
def test_mean_efficiency_self_converges_to_1e_8(name):
    """Refining the quadrature and the table sampling moves the mean efficiency by < 1e-8."""
    scene = one_revolution(name)
    values = [run(scene, ReferenceOptions(samples_per_revolution=spr, quadrature_rtol=rtol,
                                          panels_per_revolution=panels)).summary.mean_efficiency
              for spr, rtol, panels in [(90, 1e-7, 4), (360, 1e-9, 8), (1000, 1e-11, 16)]]
    assert max(values) - min(values) < 1e-8, values


def test_table_trapezoid_agrees_with_the_quadrature():
    """An independent route to the loss work: the trapezoidal rule on the table's rows agrees
    with the quadrature within the trapezoid's error bound T h^2 / 12 max|f''|, with max|f''|
    estimated from the rows' own second differences (a kink of f' shows up as ~jump / h). The
    sign ramps are 1 mm/s wide (the absolute band, 1.5e-2 of the spider pairs' RMS speed: about
    30 rows; the default relative band, 1e-3, spans fewer than 2 and the bound below would see
    the ramps as jumps)."""
    scene = one_revolution("paper-literal-10deg", **{"friction.sign_band": 1e-3})
    r = run(scene, ReferenceOptions(samples_per_revolution=8000))
    t, f = r.table["t"].to_numpy(), r.table["power_loss"].to_numpy()
    h = t[1] - t[0]
    bound = (t[-1] - t[0]) * np.max(np.abs(np.diff(f, 2))) / 12.0
    assert abs(np.trapezoid(f, t) - r.summary.loss_work) <= bound
    assert bound < 3e-3 * r.summary.loss_work  # the check has teeth: 0.3 % of the loss
    assert h > 0


def test_self_locking_is_reported_per_sample():
    """Plain reading at 50 deg: the friction loop gain exceeds 1 over part of the revolution;
    those samples (and only those) are flagged, the run reports self_locking and no means."""
    scene = replace(paper_scene(50.0, parameters="literal"), revolutions=1)
    r = run(scene, ReferenceOptions(samples_per_revolution=180))
    table = r.table
    locked = table["self_locking"].to_numpy()
    assert r.summary.status is Status.SELF_LOCKING and "self-locks" in r.summary.reason
    assert 0 < locked.sum() < locked.size
    assert r.summary.mean_efficiency is None
    gain = table["friction_loop_gain"].to_numpy()  # infinite where no solution exists
    assert np.all(gain[locked] >= 1.0) and np.all(gain[~locked] < 1.0)
    assert table.loc[locked, "torque_in"].isna().all()
    assert table.loc[~locked, "torque_in"].notna().all()


def test_no_self_locking_below_the_threshold():
    """At 40 deg (plain reading) every sample has a loop gain below 1: no locking."""
    r = run(replace(paper_scene(40.0, parameters="literal"), revolutions=1),
            ReferenceOptions(samples_per_revolution=180))
    assert r.summary.status is Status.OK
    assert 0.5 < r.summary.max_friction_loop_gain < 1.0


def test_angle_history_of_a_constant_speed_equals_the_speed_drive():
    """A linear angle history (its cubic spline is exact) reproduces the constant-speed drive."""
    scene = one_revolution("paper-literal-20deg")
    w = scene.drive.speed
    t = np.linspace(0.0, 1.2 * 2 * math.pi / w, 13)
    angle_scene = dataclasses.replace(scene, drive=AngleDrive(tuple(t), tuple(w * t)))
    a, b = run(scene).summary, run(angle_scene).summary
    assert b.status is Status.OK and b.extras["quadrature"]["knots"] > 0
    assert b.mean_efficiency == pytest.approx(a.mean_efficiency, abs=1e-12)
    assert b.input_work == pytest.approx(a.input_work, rel=1e-11)


def torque_scene(torque: float, speed: float, name="paper-literal-10deg") -> Scene:
    return dataclasses.replace(named_scene(name), drive=TorqueDrive(torque, speed), revolutions=1)


def test_torque_drive_without_friction_conserves_energy():
    """Frictionless torque drive: W_in - W_out equals the change of mechanical energy, to the
    integrator's tolerance, and the run stops after the requested revolution."""
    r = run(torque_scene(8.0, 60.0, name="paper-literal-10deg-frictionless"),
            ReferenceOptions(ode_rtol=1e-10, ode_atol=1e-10))
    s, table = r.summary, r.table
    assert s.status is Status.OK
    assert table["theta_in"].iloc[-1] == pytest.approx(2 * math.pi, rel=1e-12)
    assert table["omega_in"].iloc[-1] > 60.0  # 8 N m against 2 N m accelerates the joint
    # the quadrature integrates the forward solution's own powers: the balance measures the
    # integration error of theta and omega (rtol 1e-10) against the input work
    assert abs(s.extras["energy_balance_residual"]) < 1e-8 * s.input_work
    assert s.mean_efficiency == 1.0


def test_torque_drive_reverses_and_stops_after_the_turn():
    """A drive weaker than the load: the joint slows, reverses, and the run stops when the input
    has turned the requested angle either way (as the Exudyn engine stops)."""
    r = run(torque_scene(0.5, 20.0, name="paper-literal-10deg-frictionless"),
            ReferenceOptions(ode_rtol=1e-8, ode_atol=1e-8))
    table = r.table
    assert table["omega_in"].iloc[-1] < 0 and table["theta_in"].iloc[-1] == pytest.approx(-2 * math.pi)
    assert r.summary.status is Status.NO_WHOLE_REVOLUTION  # the angle is not monotonic


@pytest.fixture(scope="module")
def exact_sign_from_rest():
    """The 8 N m drive from 1e-300 rad/s with friction's exact sign (no ramps)."""
    scene = torque_scene(8.0, 1e-300)
    return run(dataclasses.replace(scene, friction=dataclasses.replace(scene.friction, sign_band=0.0)))


@pytest.mark.parametrize("speed", [1e-300, 1e-12, 1e-6])
def test_torque_drive_from_rest_accelerates(speed, exact_sign_from_rest):
    """8 N m against 2 N m and friction spins the joint up from (almost) rest to the exact-sign efficiency."""
    # bands sized for the initial speed are all but zero: their share at 1e-6 rad/s is 2e-10 of
    # the efficiency, the ODE's error at rtol 1e-11 about 3e-11
    r = run(torque_scene(8.0, speed))
    s, table = r.summary, r.table
    assert s.status is Status.OK and exact_sign_from_rest.summary.status is Status.OK
    assert table["theta_in"].iloc[-1] == pytest.approx(2 * math.pi, rel=1e-12)
    assert table["omega_in"].iloc[-1] > 100.0
    assert s.ode_evaluations < 10_000 and s.extras["quadrature"]["evaluations"] < 2_000
    assert s.mean_efficiency == pytest.approx(exact_sign_from_rest.summary.mean_efficiency, rel=0, abs=1e-9)


def test_torque_drive_that_rocks_stops_with_a_reason():
    """Drive torque = load, no friction, from 1e-3 rad/s: the joint rocks, never turns: incomplete, why."""
    # it swings between 0 and -0.9 revolutions, 25 s a swing, for the 25,000 s allowed
    r = run(torque_scene(2.0, 1e-3, name="paper-literal-10deg-frictionless"))
    assert r.summary.status is Status.INCOMPLETE and r.table is None
    assert r.summary.ode_evaluations < 100_000
    assert "raise the drive torque or the initial speed" in r.summary.reason
    assert r.summary.mean_efficiency is None


@pytest.mark.slow
def test_torque_drive_that_friction_holds_stops_with_a_reason():
    """2.1 N m against 2 N m and friction, from 1e-3 rad/s: friction holds the joint; incomplete, a reason."""
    # it creeps inside its sign ramps: 4e-11 revolutions in the first 6 us (about 3 s)
    r = run(torque_scene(2.1, 1e-3))
    assert r.summary.status is Status.INCOMPLETE and r.table is None
    assert "does not overcome the load and friction" in r.summary.reason


@pytest.mark.slow
def test_torque_drive_with_friction_converges_with_the_tolerance():
    """With friction the ODE tolerance controls the mean efficiency: tighter tolerances agree
    and the energy balance closes to the tolerance (about 1.4 s with reference/engine/forward.py's
    right-hand side; 10 s with the direct solve at every evaluation)."""
    scene = torque_scene(8.0, 60.0)
    s = [run(scene, ReferenceOptions(ode_rtol=rt, ode_atol=rt)).summary for rt in (1e-8, 1e-10)]
    assert all(e.status is Status.OK for e in s)
    assert abs(s[0].mean_efficiency - s[1].mean_efficiency) < 1e-6
    assert abs(s[1].extras["energy_balance_residual"]) < 1e-8 * s[1].input_work


def test_extra_columns_and_schema():
    table = run(one_revolution("paper-literal-10deg"), ReferenceOptions(samples_per_revolution=36)).table
    assert list(table.columns) == table_columns() + list(EXTRA_COLUMNS)
    assert np.all(table["input_acceleration"] == 0.0)


@pytest.mark.parametrize("field, value", [("samples_per_revolution", 0),
                                          ("gauss_nodes", 1.5), ("quadrature_rtol", 0.0),
                                          ("ode_rtol", 2.0), ("panels_per_revolution", True)])
def test_bad_options(field, value):
    with pytest.raises(ValueError, match=f"`{field}`"):
        ReferenceOptions(**{field: value})
