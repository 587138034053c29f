"""The input yoke phase (no index pulse): where Hooke's speed ratio best fits the measured one,
modulo 180 deg (the ratio's period).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

from reference.physics.kinematics import speed_ratio

__all__ = ["estimate_phase"]


def estimate_phase(angle_in: np.ndarray, ratio: np.ndarray, shaft_angle: float) -> dict:
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

    Returns
    -------
    dict
        ``phase`` [rad] (model input angle ``angle_in + phase``), ``rms`` ratio residual [-],
        ``ratio_ripple`` [-], ``shaft_angle_fit`` [rad], ``source``.
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
    return {"phase": phase, "rms": math.sqrt(fit.fun), "ratio_ripple": amplitude,
            "shaft_angle_fit": float(beta.x), "source": "Hooke's speed ratio fit"}
