"""Zero-phase low-pass filtering and the speed of a filtered angle."""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.interpolate import make_smoothing_spline

from rigdata.record import RigDataError

__all__ = ["lowpass", "lowpass_adjoint", "angular_speed"]


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


def _causal_adjoint(sos: np.ndarray, g: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Transpose of ``y = sosfilt(sos, x, zi=zi * x[0])`` applied to ``g``, shape (..., N); ``start`` is
    that filter's output for a unit ``x[0]`` through ``zi`` alone, shape (N,).
    """
    out = signal.sosfilt(sos, g[..., ::-1])[..., ::-1]
    out[..., 0] += g @ start
    return out


def lowpass_adjoint(v: np.ndarray, cutoff: float, rate: float, order: int) -> np.ndarray:
    """Transpose of :func:`lowpass` (same settings) applied to ``v``, shape (..., n), along the last axis:
    ``v @ lowpass(x) == lowpass_adjoint(v) @ x`` for every ``x``, odd padding and edge states included.
    """
    v = np.asarray(v, float)
    nyquist = 0.5 * rate
    if cutoff >= nyquist:
        return v.copy()
    sos = signal.butter(order, cutoff / nyquist, output="sos")
    ntaps = 2 * len(sos) + 1 - min(int(np.sum(sos[:, 2] == 0)), int(np.sum(sos[:, 5] == 0)))
    pad = 3 * ntaps  # sosfiltfilt's default odd extension
    n = v.shape[-1]
    start = signal.sosfilt(sos, np.zeros(n + 2 * pad), zi=signal.sosfilt_zi(sos))[0]
    g = np.zeros(v.shape[:-1] + (n + 2 * pad,))
    g[..., pad:pad + n] = v
    # lowpass = cut . reverse . F . reverse . F . extend, F the causal pass started at its first value
    g = _causal_adjoint(sos, g[..., ::-1].copy(), start)
    g = _causal_adjoint(sos, g[..., ::-1].copy(), start)
    x = g[..., pad:pad + n].copy()
    x[..., 0] += 2.0 * g[..., :pad].sum(axis=-1)
    x[..., pad:0:-1] -= g[..., :pad]
    x[..., -1] += 2.0 * g[..., pad + n:].sum(axis=-1)
    x[..., n - 2 - np.arange(pad)] -= g[..., pad + n:]
    return x


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
