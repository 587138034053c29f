"""Exudyn kinematics against Hooke's closed form, and the integrator's order of convergence."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import balanced_scene

from cardan_exudyn import run
from reference.physics.kinematics import output_angle, speed_ratio


def ratio_error(result) -> float:
    t = result.table
    beta = result.summary.scene["joint"]["geometry"]["shaft_angle"]
    return float(np.max(np.abs(t["omega_out"] / t["omega_in"] - speed_ratio(t["theta_in"].to_numpy(), beta))))


@pytest.mark.parametrize("beta_deg", [3.0, 10.0, 35.0, 47.0, 63.0], ids=lambda b: f"{b:g}deg")
def test_auto_step_meets_accuracy(beta_deg):
    """The automatic step's speed-ratio error is within 1.1x the requested accuracy (1.03x at 35 deg)."""
    accuracy = 1e-5
    result = run(balanced_scene(beta_deg, rpm=2000, gravity=(0, 0, 0), accuracy=accuracy))
    assert result.success
    # the step model K(beta) h^2 is fitted within 10 % (cardan_exudyn/model/stepsize.py)
    assert ratio_error(result) <= 1.1 * accuracy


@pytest.mark.parametrize("beta_deg", [10.0, 47.0], ids=lambda b: f"{b:g}deg")
def test_output_angle_matches_hooke(beta_deg):
    """The output angle follows tan(theta_out) = tan(theta_in) / cos(beta)."""
    result = run(balanced_scene(beta_deg, rpm=2000, gravity=(0, 0, 0), accuracy=1e-6))
    t = result.table
    expected = output_angle(t["theta_in"].to_numpy(), math.radians(beta_deg))
    # angle errors are the integral of the speed error: <= accuracy * 2 pi per revolution
    np.testing.assert_allclose(t["theta_out"], expected, rtol=0, atol=2 * math.pi * 1e-6)


@pytest.mark.parametrize("beta_deg", [10.0, 35.0, 63.0], ids=lambda b: f"{b:g}deg")
def test_second_order_convergence(beta_deg):
    """Halving the step divides the speed-ratio error by four (generalized-alpha is 2nd order)."""
    period = 2 * math.pi / (2000 * 2 * math.pi / 60)
    errors = [ratio_error(run(balanced_scene(beta_deg, rpm=2000, gravity=(0, 0, 0),
                                             dt=period / n))) for n in (400, 800)]
    order = math.log2(errors[0] / errors[1])
    assert 1.9 < order < 2.1, (errors, order)
