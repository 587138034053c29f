"""Zero-phase low-pass filtering and the speed of a filtered angle."""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.interpolate import make_smoothing_spline

from rigdata.record import RigDataError

__all__ = ["lowpass", "angular_speed"]


def lowpass(x: np.ndarray, cutoff: float, rate: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth low-pass (forward and backward, ``scipy.signal.sosfiltfilt``).

    Parameters
    ----------
    x : ndarray, shape (..., n)
        Signal, filtered along its last axis (any unit).
    cutoff : float
        Cut-off frequency [Hz]; at or above the Nyquist frequency ``x`` is returned as a copy.
    rate : float
        Sampling rate [Hz].
    order : int
        Butterworth order of one pass.

    Returns
    -------
    ndarray
        The filtered signal, same shape and unit as ``x``.
    """
    nyquist = 0.5 * rate
    if cutoff >= nyquist:
        return np.asarray(x, float).copy()
    sos = signal.butter(order, cutoff / nyquist, output="sos")
    return signal.sosfiltfilt(sos, x)


def angular_speed(angle: np.ndarray, dt: float, cutoff: float, method: str) -> np.ndarray:
    """Speed of a filtered angle.

    Savitzky-Golay: cubic over a window of half a cut-off period (odd, >= 7 samples), whose own
    smoothing then stays above the cut-off. Spline: a cubic smoothing spline whose penalty puts
    its half-power frequency at the cut-off.

    Parameters
    ----------
    angle : ndarray, shape (n,)
        Filtered angle [rad] on a uniform grid.
    dt : float
        Sampling interval [s].
    cutoff : float
        The filter's cut-off [Hz].
    method : {"savgol", "spline"}
        See :data:`rigdata.conditioning.options.DERIVATIVES`.

    Returns
    -------
    ndarray, shape (n,)
        Speed [rad/s].

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
