"""Frictionless inverse dynamics (reference.engine.dynamics) against statics by hand and balance laws."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_reference_kinematics import derivative

from reference.engine import solve as engine
from reference.engine.dynamics import inverse_dynamics
from reference.engine.newton_euler import reaction_system
from reference.engine.options import ReferenceOptions
from reference.engine.table import EXTRA_COLUMNS
from reference.paper.scenes import named_scene
from reference.physics.joint_motion import joint_motion
from reference.physics.kinematics import body_motions, speed_ratio
from reference.results.columns import table_columns
from reference.results.summary import Status, Summary
from reference.scene.drives import SpeedDrive
from reference.scene.joint import PAIR_NAMES, Body, Geometry, Joint
from reference.scene.load import Load
from reference.scene.mapping import replace
from reference.scene.scene import Scene

EPS = np.finfo(float).eps
M_IN, M_SPIDER, M_OUT = 0.9, 0.05, 0.8  # [kg]
X_IN, X_OUT = 0.15, 0.08  # centres of mass on the shaft axes, distance from the joint centre [m]
L_IN, L_OUT = 0.11, 0.10  # frame bearings, away from the centres of mass so moments appear [m]
LOAD = 1.5  # [N m]
ANGLES_DEG = [0.0, 5.0, 37.0, 60.0, 85.0]
ANGLE_IDS = [f"{a:g}deg" for a in ANGLES_DEG]


def balanced_scene(beta_deg: float = 0.0, gravity=(0.0, 0.0, -9.81), rpm: float = 600.0) -> Scene:
    """Centres of mass on the shaft axes, principal axes along the canonical axes."""
    joint = Joint(
        input=Body(M_IN, np.diag([2e-4, 4e-3, 4e-3]), com=(-X_IN, 0.0, 0.0)),
        spider=Body(M_SPIDER, np.diag([2e-6, 3e-6, 3e-6])),
        output=Body(M_OUT, np.diag([1.8e-4, 3.5e-3, 3.5e-3]), com=(X_OUT, 0.0, 0.0)),
        geometry=Geometry(math.radians(beta_deg), input_bearing=L_IN, output_bearing=L_OUT),
    )
    return Scene(joint, SpeedDrive(rpm * 2 * math.pi / 60), Load(LOAD), gravity=gravity,
                 revolutions=1.0, name="balanced")


def hand_statics(gy: float, gz: float) -> dict[str, list[float]]:
    """Reactions (fx, fy, fz, mx, my, mz) at shaft angle 0, input angle 0, gravity (0, gy, gz).

    Nothing accelerates, so each body is in static equilibrium. The input-spider pair slides
    along y, so the spider's weight along y goes to the output, along z to the input; each shaft
    bearing carries the rest, and the bearing moments balance the offset between centre of mass
    and bearing. Pair frames at angle 0: frame_input and output_frame (e_y, e_z, e_x),
    input_spider (e_z, e_x, e_y), spider_output (e_x, e_y, e_z).
    """
    return {
        "frame_input": [-M_IN * gy, -(M_IN + M_SPIDER) * gz, 0.0,
                        (L_IN * (M_IN + M_SPIDER) - X_IN * M_IN) * gz, (X_IN - L_IN) * M_IN * gy, 0.0],
        "input_spider": [-M_SPIDER * gz, 0.0, 0.0, 0.0, LOAD, 0.0],
        "spider_output": [0.0, M_SPIDER * gy, 0.0, LOAD, 0.0, 0.0],
        "output_frame": [(M_SPIDER + M_OUT) * gy, M_OUT * gz, 0.0,
                         (L_OUT - X_OUT) * M_OUT * gz, (X_OUT * M_OUT - L_OUT * (M_SPIDER + M_OUT)) * gy,
                         0.0],
    }


def run(scene: Scene, samples_per_revolution: int | None = None):
    return engine.run(scene, ReferenceOptions(samples_per_revolution=samples_per_revolution))


GRAVITIES = {"gravity-z": (0.0, 0.0, -9.81), "gravity-y": (0.0, -9.81, 0.0),
             "gravity-yz": (0.0, 4.0, -8.0)}


@pytest.mark.parametrize("gravity", GRAVITIES.values(), ids=GRAVITIES.keys())
@pytest.mark.parametrize("pair", ["frame_input", "input_spider", "spider_output", "output_frame"])
def test_reactions_match_statics_by_hand(pair, gravity):
    """At shaft angle 0 and input angle 0 each pair carries exactly the hand-computed statics."""
    row = run(balanced_scene(0.0, gravity), samples_per_revolution=8).table.iloc[0]
    got = row[[f"{pair}_{c}" for c in ("fx", "fy", "fz", "mx", "my", "mz")]].to_numpy(float)
    # loads <= 9 N and 1.5 N m from one well-conditioned solve (cond ~ 4): rounding ~1e-14;
    # 1e-12 N / N m is 100 times that
    np.testing.assert_allclose(got, hand_statics(*gravity[1:])[pair], rtol=0, atol=1e-12)


def test_drive_torque_equals_load_when_aligned_and_balanced():
    """At shaft angle 0, balanced, constant speed: torque_in equals the load at every sample."""
    table = run(balanced_scene(0.0, (0.0, 3.0, -9.0)), samples_per_revolution=36).table
    # torque 1.5 N m from a solve with cond ~ 4 and reactions <= 9 N: 1e-12 is ~100x rounding
    np.testing.assert_allclose(table["torque_in"], LOAD, rtol=0, atol=1e-12)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_quasi_static_drive_torque_follows_hooke_ratio(beta_deg):
    """At rest the drive torque is the load times the speed ratio (virtual work)."""
    scene = balanced_scene(beta_deg)
    theta = np.linspace(0.0, 2 * np.pi, 73)
    torque = inverse_dynamics(scene, theta, np.zeros_like(theta), np.zeros_like(theta))["torque_in"]
    expected = LOAD * speed_ratio(theta, scene.joint.geometry.shaft_angle)
    # the ratio reaches 1 / cos(85 deg) = 11.5; 1e-12 relative is ~100 ulp of one small solve
    np.testing.assert_allclose(torque, expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_input_work_equals_output_work_over_whole_revolutions(beta_deg):
    """Without friction the mechanical energy is periodic, so input work = output work."""
    result = run(named_scene(f"paper-{beta_deg:g}deg-frictionless"))
    s, table = result.summary, result.table
    assert s.status is Status.OK and s.revolutions == 2
    scale = np.trapezoid(np.abs(table["power_in"]) + np.abs(table["power_out"]), table["t"])
    # worst-case rounding of the trapezoidal sums: n eps times the integral of |terms|
    tol = len(table) * EPS * scale
    assert abs(s.input_work - s.output_work) <= tol
    assert s.input_work == pytest.approx(2 * 2 * np.pi * s.scene["load"]["torque"], rel=0, abs=tol)


def energy_rate(scene: Scene, theta: np.ndarray, theta_t: np.ndarray):
    """d/dt (kinetic + potential energy) [W], a scale of its terms [W], and the energies [J].

    Built directly from the bodies' mass properties and the kinematics at constant input speed:
    dT/dt = m v.a + omega.J alpha and dV/dt = -m g.v for each body.
    """
    motions = body_motions(theta, theta_t, np.zeros_like(theta), scene.joint.geometry.shaft_angle)
    g = np.asarray(scene.gravity)
    rate, scale, kinetic, potential = 0.0, 0.0, 0.0, 0.0
    for name, body in scene.joint.bodies():
        mass, com, inertia = body.canonical()
        m = motions[name]
        r = m.rotation @ com
        v = np.cross(m.omega, r)
        a = np.cross(m.alpha, r) + np.cross(m.omega, v)
        j = m.rotation @ inertia @ np.swapaxes(m.rotation, -1, -2)
        terms = (mass * np.sum(v * a, -1), np.einsum("ni,nij,nj->n", m.omega, j, m.alpha),
                 -mass * (v @ g))
        rate, scale = rate + sum(terms), scale + sum(np.abs(t) for t in terms)
        kinetic = kinetic + 0.5 * (mass * np.sum(v * v, -1)
                                   + np.einsum("ni,nij,nj->n", m.omega, j, m.omega))
        potential = potential - mass * (r @ g)
    return rate, scale, kinetic, potential


@pytest.mark.parametrize("beta_deg", ANGLES_DEG, ids=ANGLE_IDS)
def test_power_balance_at_every_sample(beta_deg):
    """torque_in omega_in - torque_out omega_out = d/dt (kinetic + potential energy)."""
    scene = named_scene(f"paper-{beta_deg:g}deg-frictionless")
    table = run(scene, samples_per_revolution=90).table
    theta, omega = table["theta_in"].to_numpy(), table["omega_in"].to_numpy()
    rate, scale, kinetic, potential = energy_rate(scene, theta, omega)
    scale = scale + np.abs(table["power_in"]) + np.abs(table["power_out"])
    matrix, _ = reaction_system(scene, joint_motion(scene.joint, theta, omega, 0 * omega))
    # rounding: the drive torque comes from a solve of condition number cond (4 at 0 deg, 60 at
    # 85 deg); allow 10 cond ulp of the largest term of the balance
    tol = 10 * np.max(np.linalg.cond(matrix)) * EPS * scale
    residual = table["power_in"] - table["power_out"] - rate
    assert np.all(np.abs(residual) <= tol), f"max residual / tol {np.max(np.abs(residual) / tol)}"
    # the same energies, summed over three bodies of ~10 J: 100 ulp
    np.testing.assert_allclose(table["energy_kinetic"], kinetic, rtol=0, atol=100 * EPS * 10)
    np.testing.assert_allclose(table["energy_potential"], potential, rtol=0, atol=100 * EPS * 10)


def test_result_follows_the_schema():
    """Columns, sampling, zero friction columns and the summary match the common schema."""
    scene = replace(named_scene("paper-literal-10deg-frictionless"), **{"record.every": 2})
    result = run(scene, samples_per_revolution=36)
    table, s = result.table, result.summary
    assert list(table.columns) == table_columns() + list(EXTRA_COLUMNS)
    assert len(table) == (2 * 36) // 2 + 1  # 2 revolutions, endpoint included, every 2nd row
    assert table["t"].iloc[0] == 0.0
    assert table["theta_in"].iloc[-1] == pytest.approx(4 * np.pi, rel=1e-15)
    assert s.status is Status.OK and s.engine == "reference" and s.scene["name"] == scene.name
    assert {"engine_version", "wall_time_s", "input_work", "mean_efficiency"} <= s.to_dict().keys()
    # every field of the schema's summary, and beyond it only per-pair losses and the engine's extras
    schema = set(Summary(Status.OK).to_dict())
    pairs = {f"loss_work_{p}" for p in PAIR_NAMES} | {f"loss_work_{p}_sliding" for p in PAIR_NAMES}
    assert schema <= s.to_dict().keys() <= schema | pairs | set(s.extras)
    # no friction, no sliding, and no axial force / torque in the cylindrical pairs
    zero_suffixes = ("_mz", "friction_torque", "friction_force", "slide_rel")
    zero_cols = [c for c in table_columns() if c.startswith("power_loss") or c.endswith(zero_suffixes)
                 or (c.endswith("_fz") and c != "frame_input_fz")]
    assert not table[zero_cols].to_numpy().any()
    assert np.all(table["efficiency"] == 1.0) and s.mean_efficiency == 1.0
    assert run(replace(scene, **{"record.timeseries": False})).table is None


@pytest.mark.parametrize("bad", [0, 2.5, True], ids=["zero", "float", "bool"])
def test_bad_samples_per_revolution(bad):
    """samples_per_revolution must be a positive integer."""
    with pytest.raises(ValueError, match="`samples_per_revolution` must be a positive integer"):
        run(balanced_scene(), samples_per_revolution=bad)


def momentum(scene: Scene, t: np.ndarray) -> np.ndarray:
    """Linear momentum [kg m/s] and angular momentum about O [kg m^2/s] of the joint, (n, 6)."""
    speed = scene.drive.speed
    motions = body_motions(speed * t, np.full_like(t, speed), np.zeros_like(t),
                           scene.joint.geometry.shaft_angle)
    total = 0.0
    for name, body in scene.joint.bodies():
        mass, com, inertia = body.canonical()
        m = motions[name]
        r = m.rotation @ com
        v = np.cross(m.omega, r)
        j_omega = np.einsum("nij,jk,nlk,nl->ni", m.rotation, inertia, m.rotation, m.omega)
        total = total + np.concatenate([mass * v, mass * np.cross(r, v) + j_omega], -1)
    return total


def external_wrench(scene: Scene, table) -> np.ndarray:
    """Force [N] and moment about O [N m] of everything outside the three bodies, (n, 6).

    Ground pairs from the table (frame_input acts on the input; output_frame is what the output
    exerts on the ground, so it enters with a minus sign; its frame turns with the output by
    theta_out about a2), their friction torques, the drive and load torques, and gravity.
    """
    def reaction(pair):
        return (table[[f"{pair}_f{c}" for c in "xyz"]].to_numpy(),
                table[[f"{pair}_m{c}" for c in "xyz"]].to_numpy())

    geo, speed = scene.joint.geometry, scene.drive.speed
    beta, n = geo.shaft_angle, len(table)
    e_x, e_y, e_z = np.eye(3)
    a2, y0 = geo.output_axis(), np.array([-math.sin(beta), math.cos(beta), 0.0])
    f, m = reaction("frame_input")
    frame = np.column_stack([e_y, e_z, e_x])
    force, moment = f @ frame.T, m @ frame.T + np.cross(-geo.input_bearing * e_x, f @ frame.T)
    c, s = np.cos(table["theta_out"].to_numpy())[:, None], np.sin(table["theta_out"].to_numpy())[:, None]
    frame_out = np.stack([c * y0 + s * e_z, c * e_z - s * y0, np.broadcast_to(a2, (n, 3))], -1)
    f, m = reaction("output_frame")
    f_out = np.einsum("nij,nj->ni", frame_out, f)
    force = force - f_out
    moment = moment - np.einsum("nij,nj->ni", frame_out, m) - np.cross(geo.output_bearing * a2, f_out)
    moment = moment + np.outer(table["torque_in"], e_x) - np.outer(table["torque_out"], a2)
    # friction torques of the ground pairs: on the input (body b of frame_input) and, opposite,
    # on the output (body a of output_frame); the ideal joint does not slide (no axial force)
    moment = (moment + np.outer(table["frame_input_friction_torque"], e_x)
              - np.outer(table["output_frame_friction_torque"], a2))
    t = table["t"].to_numpy()
    motions = body_motions(speed * t, np.full_like(t, speed), np.zeros_like(t), beta)
    g = np.asarray(scene.gravity)
    for name, body in scene.joint.bodies():
        mass, com, _ = body.canonical()
        force = force + mass * g
        moment = moment + np.cross(motions[name].rotation @ com, mass * g)
    return np.concatenate([force, moment], -1)


@pytest.mark.parametrize("beta_deg", [0.0, 10.0, 37.0], ids=["0deg", "10deg", "37deg"])
def test_external_wrench_equals_momentum_rate(beta_deg):
    """Ground reactions, drive, load and gravity change the joint's momenta (gyroscopic terms)."""
    scene = named_scene(f"paper-{beta_deg:g}deg-frictionless")
    table = run(scene, samples_per_revolution=90).table
    t = table["t"].to_numpy()
    # a step of 1e-3 of a revolution: the Richardson estimate bounds the truncation error
    rate, tol_fd = derivative(lambda x: momentum(scene, x), t, h=1e-3 * t[-1] / 2)
    wrench = external_wrench(scene, table)
    # the reactions (<= 400 N, levers <= 0.13 m) come from solves with cond <= 10: 1e3 ulp
    tol = tol_fd + 1e3 * EPS * np.max(np.abs(wrench))
    np.testing.assert_allclose(wrench, rate, rtol=0, atol=tol)
