"""Real Fourier series of many periodic functions of the input angle, fitted and evaluated at once."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["KEEP_TOLERANCE", "RESOLVED_TOLERANCE", "TAU", "TrigSeries", "fit_periodic"]

TAU = 2.0 * math.pi
RESOLVED_TOLERANCE = 1e-14
"""A fit is resolved when every harmonic from a quarter of the grid on is below this fraction of
its group's largest sample (the solution's parts, the friction response, the speeds)."""
KEEP_TOLERANCE = 1e-15
"""Harmonics are kept up to the last one above this fraction of the group's largest sample (the
samples' rounding noise is about 1e-17 of it at
:data:`reference.engine.forward.PART_SCALE`)."""


@dataclass(frozen=True)
class TrigSeries:
    """Real Fourier series ``f(theta) = sum_k a_k cos(k theta) + b_k sin(k theta)``, k = 0..H, of M
    functions evaluated in one product: ``frequencies`` and ``phases`` (0, then pi/2) of the 2 (H + 1)
    rows, coefficients ``table`` (2 (H + 1), M), and the ``grid`` points per revolution fitted on.
    """

    frequencies: np.ndarray
    phases: np.ndarray
    table: np.ndarray
    grid: int

    def __call__(self, theta: float) -> np.ndarray:
        """The M functions at one input angle [rad], shape (M,)."""
        return np.cos(self.frequencies * (theta % TAU) - self.phases) @ self.table


def fit_periodic(values: np.ndarray, scale: np.ndarray) -> TrigSeries | None:
    """:class:`TrigSeries` of ``values`` (n, M) on ``n`` (even) angles ``2 pi j / n``, harmonics kept up to
    the last above :data:`KEEP_TOLERANCE` times each function's group ``scale``; None when one from
    ``n / 4`` on exceeds :data:`RESOLVED_TOLERANCE`.
    """
    n = values.shape[0]
    c = np.fft.rfft(values, axis=0) / n  # (n/2 + 1, M)
    a = 2.0 * c.real
    b = -2.0 * c.imag
    a[0] *= 0.5
    size = np.hypot(a, b) / np.maximum(scale, np.finfo(float).tiny)
    if np.any(size[n // 4:] > RESOLVED_TOLERANCE):
        return None
    kept = np.nonzero(np.any(size > KEEP_TOLERANCE, 1))[0]
    h = int(kept[-1]) + 1 if kept.size else 1
    k = np.arange(h, dtype=float)
    return TrigSeries(np.concatenate([k, k]), np.concatenate([np.zeros(h), np.full(h, 0.5 * math.pi)]),
                      np.concatenate([a[:h], b[:h]]), n)
