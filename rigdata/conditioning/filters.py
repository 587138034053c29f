"""Zero-phase low-pass filtering and the speed of a filtered angle."""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.interpolate import make_smoothing_spline

from rigdata.record import RigDataError

__all__ = ["lowpass", "angular_speed"]


def lowpass(x: np.ndarray, cutoff: float, rate: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth low-pass (``scipy.signal.sosfiltfilt``) along the last axis.

    Parameters
    ----------
    x : ndarray, shape (..., n)
        Signal, any unit.
    cutoff : float
        Cut-off [Hz]; at or above Nyquist ``x`` is returned as a copy.
    rate : float
        Sampling rate [Hz].
    order : int
        Butterworth order of one pass.
    """
    nyquist = 0.5 * rate
    if cutoff >= nyquist:
        return np.asarray(x, float).copy()
    sos = signal.butter(order, cutoff / nyquist, output="sos")
    return signal.sosfiltfilt(sos, x)


def angular_speed(angle: np.ndarray, dt: float, cutoff: float, method: str) -> np.ndarray:
    """Speed [rad/s] of a filtered angle.

    Savitzky-Golay: cubic over half a cut-off period (odd, >= 7 samples), its smoothing above the
    cut-off. Spline: cubic smoothing spline with its half-power frequency at the cut-off.

    Parameters
    ----------
    angle : ndarray, shape (n,)
        Filtered angle [rad] on a uniform grid.
    dt : float
        Sampling interval [s].
    cutoff : float
        Filter cut-off [Hz].
    method : {"savgol", "spline"}

    Raises
    ------
    RigDataError
        Fewer than 5 samples for the Savitzky-Golay window.
    """
    if method == "spline":
        t = np.arange(angle.size) * dt
        # the penalty lam int f''^2 makes the spline a low-pass with gain 1 / (1 + lam (2 pi f)^4
        # / dt) on a uniform grid: half power at the cut-off for this lam (generalised
        # cross-validation, the default, smooths the 2nd harmonic away on these records)
        spline = make_smoothing_spline(t, angle, lam=dt / (2 * math.pi * cutoff) ** 4)
        return spline(t, 1)
    window = max(7, int(round(0.5 / (cutoff * dt))) | 1)
    if window > angle.size:
        window = angle.size if angle.size % 2 else angle.size - 1
    if window < 5:
        raise RigDataError(f"too few samples ({angle.size}) for derivatives")
    return signal.savgol_filter(angle, window, 3, deriv=1, delta=dt, mode="interp")
