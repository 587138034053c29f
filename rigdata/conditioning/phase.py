"""The input yoke phase (no index pulse): where Hooke's speed ratio best fits the measured one,
modulo 180 deg (the ratio's period).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

from reference.physics.kinematics import speed_ratio

__all__ = ["estimate_phase"]


def _fit_covariance(angle_in: np.ndarray, ratio: np.ndarray, phase: float, beta: float,
                    independent: float) -> np.ndarray:
    """Covariance of (phase, shaft angle) [rad^2] of the least-squares fit: ``s^2 (J^T J)^-1`` with the
    residual variance ``s^2`` and Jacobian ``J``, scaled by samples over ``independent`` ones (the
    low-passed residuals are correlated over about one cut-off period).
    """
    h = 1e-6
    columns = [(speed_ratio(angle_in + phase + h, beta) - speed_ratio(angle_in + phase - h, beta)) / (2 * h),
               (speed_ratio(angle_in + phase, beta + h) - speed_ratio(angle_in + phase, beta - h)) / (2 * h)]
    jac = np.column_stack(columns)
    residual = ratio - speed_ratio(angle_in + phase, beta)
    variance = float(np.mean(residual ** 2))
    scale = ratio.size / max(min(independent, ratio.size), 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return variance * scale * np.linalg.pinv(jac.T @ jac)


def estimate_phase(angle_in: np.ndarray, ratio: np.ndarray, shaft_angle: float,
                   independent: float | None = None) -> dict:
    """Input yoke phase in [0, pi) that best fits Hooke's speed ratio to the measured one.

    Least squares: 360-point scan, then bounded refinement; the best-fitting shaft angle is a check.

    Parameters
    ----------
    angle_in : ndarray, shape (n,)
        Input angle [rad], zero unknown.
    ratio : ndarray, shape (n,)
        Measured ``omega_out / omega_in`` [-].
    shaft_angle : float
        Shaft angle [rad].
    independent : float, optional
        Independent samples among ``ratio``'s (two per cut-off period after a low-pass); default all.

    Returns
    -------
    dict
        ``phase`` [rad] (model input angle ``angle_in + phase``), ``rms`` ratio residual [-],
        ``ratio_ripple`` [-], ``shaft_angle_fit`` [rad] and its standard uncertainty
        ``shaft_angle_fit_u`` [rad] (from the residuals), ``source``.
    """
    def residual(phase: float, beta: float = shaft_angle) -> float:
        return float(np.mean((ratio - speed_ratio(angle_in + phase, beta)) ** 2))

    scan = np.linspace(0.0, math.pi, 360, endpoint=False)
    best = scan[int(np.argmin([residual(p) for p in scan]))]
    step = scan[1] - scan[0]
    fit = minimize_scalar(residual, bounds=(best - step, best + step), method="bounded",
                          options={"xatol": 1e-7})
    phase = float(fit.x) % math.pi
    beta = minimize_scalar(lambda b: residual(phase, b), bounds=(0.0, 1.4), method="bounded",
                           options={"xatol": 1e-7})
    amplitude = float(np.ptp(speed_ratio(np.linspace(0, math.pi, 181), shaft_angle)))
    cov = _fit_covariance(angle_in, ratio, phase, float(beta.x), independent or float(ratio.size))
    return {"phase": phase, "rms": math.sqrt(fit.fun), "ratio_ripple": amplitude,
            "shaft_angle_fit": float(beta.x), "shaft_angle_fit_u": math.sqrt(max(float(cov[1, 1]), 0.0)),
            "source": "Hooke's speed ratio fit"}
