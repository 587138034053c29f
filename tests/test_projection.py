"""Velocity projection of Exudyn's recorded states (cardan_exudyn.model.projection).

Index-3 generalized-alpha keeps positions on the constraint manifold but misses the velocity
constraints by O(h^2); the projection must give the exact velocities of the computed positions
for a prescribed input, keep the drive torque untouched, and on a joint with mounting errors
(sliding cylindrical pairs) agree with the independent reference engine.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cardan_exudyn import ExudynOptions, run
from reference.paper.scenes import named_scene
from reference.physics.kinematics import speed_ratio
from reference.scene.mapping import replace


def _steps(scene, n):
    return replace(scene, **{"numerics.dt": 2.0 * math.pi / scene.drive.max_speed() / n,
                             "revolutions": 1})


def _ratio_error(scene, table):
    ratio = table["omega_out"].to_numpy() / table["omega_in"].to_numpy()
    return np.max(np.abs(ratio - speed_ratio(table["theta_in"].to_numpy(),
                                             scene.joint.geometry.shaft_angle)))


@pytest.mark.parametrize("angle", [10, 35])
def test_projection_gives_hookes_speed_ratio_at_a_coarse_step(angle):
    """At 50 steps per revolution the integrator's speed ratio is off by 1e-4..2e-3; projected, by
    rounding only. The drive torque (a Lagrange multiplier) is not touched."""
    scene = _steps(named_scene(f"paper-{angle}deg-frictionless"), 50)
    plain = run(scene)
    projected = run(scene, options=ExudynOptions(velocity_projection=True))
    assert plain.success and projected.success
    assert _ratio_error(scene, plain.table) > 5e-5
    assert _ratio_error(scene, projected.table) < 1e-12
    np.testing.assert_array_equal(plain.table["torque_in"], projected.table["torque_in"])
    np.testing.assert_array_equal(plain.table["theta_out"], projected.table["theta_out"])
    assert projected.summary.extras["max_velocity_correction"] > 0.0
    assert projected.summary.options["velocity_projection"] is True


def test_projection_with_mounting_errors_matches_the_reference_engine():
    """With offsets the cylindrical pairs slide (the rows carry the axis rotation term): the
    projected output speed and pair slide speeds equal the reference engine's at the same
    instants."""
    scene = replace(named_scene("rig-matched-errors-frictionless"),
                    **{"revolutions": 1, "numerics.dt": 2 * math.pi / 6.0 / 60})
    ex = run(scene, options=ExudynOptions(velocity_projection=True))
    plain = run(scene)
    ref = run(scene, "reference")
    assert ex.success and ref.success
    w_ref = ref.table["omega_out"].to_numpy()
    n = min(len(w_ref), len(ex.table))
    err_projected = np.max(np.abs(ex.table["omega_out"].to_numpy()[:n] - w_ref[:n]))
    err_plain = np.max(np.abs(plain.table["omega_out"].to_numpy()[:n] - w_ref[:n]))
    assert err_projected < 1e-9 * np.max(np.abs(w_ref))
    assert err_plain > 100 * err_projected
    # the slide speeds of the projection's first row (the velocity-level row) equal the reference
    for pair in ("input_spider", "output_frame"):
        assert ex.table[f"{pair}_slide_rel"].iloc[0] == pytest.approx(
            ref.table[f"{pair}_slide_rel"].iloc[0], abs=1e-9)


def test_torque_drive_projection_satisfies_the_constraints_and_is_idempotent():
    """With a torque drive one degree of freedom is left: the projection is the closest
    consistent velocity in the kinetic-energy metric; projecting it again changes nothing."""
    from cardan_exudyn.model.postprocess import body_states, pair_kinematics
    from cardan_exudyn.model.projection import constraint_jacobian, project_velocities
    from cardan_exudyn.model.solve import solve

    scene = replace(named_scene("paper-literal-20deg-frictionless"),
                    drive={"kind": "torque", "torque": 2.0, "initial_speed": 100.0},
                    load={"torque": 0.0}, revolutions=1, **{"numerics.dt": 2e-4})
    result = run(scene, options=ExudynOptions(velocity_projection=True))
    assert result.success
    # a fresh solve (the one solve sequence) to reach the unprojected states
    model = solve(scene, ExudynOptions(), reactions=False).model
    states = body_states(model)
    n = min(len(s["t"]) for s in states.values())
    states = {k: {c: v[:n] for c, v in s.items()} for k, s in states.items()}
    pairs = pair_kinematics(model, states, n)
    u_of = lambda st: np.concatenate([np.concatenate([st[b]["v"], st[b]["omega"]], axis=1)  # noqa: E731
                                      for b in ("input", "spider", "output")], axis=1)
    jac = constraint_jacobian(states, pairs)
    before = np.max(np.abs(np.einsum("nij,nj->ni", jac, u_of(states))))
    once = project_velocities(states, pairs, model.mass, model.inertia,
                              model.pair_frames["frame_input"][:, 2], None)
    once.pop("max_velocity_correction")
    after = np.max(np.abs(np.einsum("nij,nj->ni", jac, u_of(once))))
    twice = project_velocities(once, pairs, model.mass, model.inertia,
                               model.pair_frames["frame_input"][:, 2], None)
    assert twice.pop("max_velocity_correction") < 1e-10
    assert before > 1e-6          # the integrator's velocities miss the constraints
    assert after < 1e-10 * max(1.0, before)
