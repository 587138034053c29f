"""The calibration's statistics against closed forms: a linear model's weighted least squares."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from rigdata.campaign.calibration import calibrate
from rigdata.campaign.evaluate import Outcome
from rigdata.campaign.spec import Parameter


def linear_model(slopes: np.ndarray, offsets: np.ndarray):
    """An evaluator whose efficiency at recording i is ``offsets[i] + slopes[i] @ values``."""
    def evaluate(runs):
        return [Outcome("ok", None, float(offsets[r.recording] + slopes[r.recording] @ np.array(r.values)),
                        0.0, 0.0) for r in runs]
    return evaluate


def parameters(n: int) -> tuple[Parameter, ...]:
    """``n`` parameters on [0, 0.6] starting at 0.2."""
    return tuple(Parameter(f"p{j}", (f"key{j}",), 0.2, (0.0, 0.6)) for j in range(n))


def test_one_parameter_matches_weighted_least_squares():
    """Estimate, standard uncertainty, residuals and chi-square equal the closed form of a weighted fit."""
    rng = np.random.default_rng(3)
    slopes = -rng.uniform(0.02, 0.08, (5, 1))
    offsets = np.ones(5)
    sigma = rng.uniform(1e-3, 3e-3, 5)
    measured = offsets + slopes[:, 0] * 0.12 + rng.normal(0.0, sigma)
    cal = calibrate(linear_model(slopes, offsets), "x", parameters(1), range(5), measured, sigma, 0.95)
    a = slopes[:, 0] / sigma
    b = (measured - offsets) / sigma
    f = float(a @ b / (a @ a))
    assert cal.estimates[0].value == pytest.approx(f, abs=1e-6)
    assert cal.estimates[0].standard_uncertainty == pytest.approx(1.0 / math.sqrt(a @ a), rel=1e-3)
    chi2 = float(np.sum((a * f - b) ** 2))
    assert cal.chi_square == pytest.approx(chi2, rel=1e-5)
    assert cal.dof == 4
    assert cal.p_value == pytest.approx(stats.chi2.sf(chi2, 4), rel=1e-4)
    assert cal.estimates[0].identifiable


def test_misfit_is_rejected_not_absorbed():
    """A misfit far beyond the stated uncertainties rejects the model and leaves the parameter's
    uncertainty the data's (not scaled by the misfit)."""
    slopes = np.array([[-0.05], [-0.05], [-0.02], [-0.02]])
    offsets = np.ones(4)
    sigma = np.full(4, 1e-3)
    measured = offsets + slopes[:, 0] * 0.12 + np.array([0.01, 0.01, -0.01, -0.01])
    cal = calibrate(linear_model(slopes, offsets), "x", parameters(1), range(4), measured, sigma, 0.95)
    assert cal.rejected is True
    a = slopes[:, 0] / sigma
    assert cal.estimates[0].standard_uncertainty == pytest.approx(1.0 / math.sqrt(a @ a), rel=1e-3)


def test_parameters_acting_only_as_their_sum_are_not_identifiable():
    """Two parameters with equal effect everywhere: neither identifiable; their sum is, with its u."""
    slopes = np.array([[-0.04, -0.04], [-0.03, -0.03], [-0.05, -0.05]])
    offsets = np.ones(3)
    sigma = np.full(3, 2e-3)
    measured = offsets + slopes @ np.array([0.1, 0.15])
    cal = calibrate(linear_model(slopes, offsets), "x", parameters(2), range(3), measured, sigma, 0.95)
    assert [e.identifiable for e in cal.estimates] == [False, False]
    assert all(e.standard_uncertainty is None for e in cal.estimates)
    (combo,) = cal.combinations
    assert combo.coefficients == pytest.approx({"p0": 1.0, "p1": 1.0})
    assert combo.value == pytest.approx(0.25, abs=1e-6)
    a = slopes[:, 0] / sigma
    assert combo.standard_uncertainty == pytest.approx(1.0 / math.sqrt(a @ a), rel=1e-3)
    assert cal.correlation[0, 1] < -0.9


def test_separate_effects_are_identifiable():
    """Two parameters with different effects at different recordings are each determined."""
    slopes = np.array([[-0.04, -0.01], [-0.01, -0.04], [-0.03, -0.03]])
    offsets = np.ones(3)
    sigma = np.full(3, 1e-3)
    measured = offsets + slopes @ np.array([0.1, 0.15])
    cal = calibrate(linear_model(slopes, offsets), "x", parameters(2), range(3), measured, sigma, 0.95)
    assert [e.identifiable for e in cal.estimates] == [True, True]
    assert [e.value for e in cal.estimates] == pytest.approx([0.1, 0.15], abs=1e-6)
    assert cal.combinations == ()
