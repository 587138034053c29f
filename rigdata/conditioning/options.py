"""Settings of the conditioning (:class:`Conditioning`); defaults and why:
``docs/rigdata.md#choices-and-their-defaults``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DERIVATIVES", "Conditioning"]

DERIVATIVES = ("savgol", "spline")
"""How speeds are taken from a filtered angle: Savitzky-Golay or a smoothing spline."""


@dataclass(frozen=True)
class Conditioning:
    """Settings of :func:`rigdata.conditioning.condition`; a bad setting raises TypeError/ValueError.

    Attributes
    ----------
    cutoff_harmonics : float
        Low-pass cut-off as a multiple of the mean input shaft frequency [-].
    filter_order : int
        Butterworth order of one pass (applied twice).
    derivative : {"savgol", "spline"}
        Speed from a filtered angle (shaft without a speed channel).
    settle_revolutions : float
        Input revolutions dropped at each end before the window [-].
    phase : float or None
        Input yoke phase [rad] if known (skips the estimate).
    """

    cutoff_harmonics: float = 10.0
    filter_order: int = 4
    derivative: str = "savgol"
    settle_revolutions: float = 0.25
    phase: float | None = None

    def __post_init__(self) -> None:
        self._check_types()
        if self.phase is not None and not math.isfinite(self.phase):
            raise ValueError(f"`phase` must be finite [rad] or None, got {self.phase!r}")
        if not (math.isfinite(self.cutoff_harmonics) and self.cutoff_harmonics >= 2.0):
            raise ValueError(f"`cutoff_harmonics` must be >= 2 (Hooke's joint's 2nd harmonic), got "
                             f"{self.cutoff_harmonics!r}")
        if isinstance(self.filter_order, bool) or not isinstance(self.filter_order, int) \
                or not 1 <= self.filter_order <= 10:
            raise ValueError(f"`filter_order` must be an integer in 1..10, got {self.filter_order!r}")
        if self.derivative not in DERIVATIVES:
            raise ValueError(f"`derivative` must be one of {DERIVATIVES}, got {self.derivative!r}")
        if not (math.isfinite(self.settle_revolutions) and 0 <= self.settle_revolutions <= 1e6):
            raise ValueError(f"`settle_revolutions` must be in [0, 1e6], got {self.settle_revolutions!r}")
        if self.cutoff_harmonics > 1e6:
            raise ValueError(f"`cutoff_harmonics` must be at most 1e6, got {self.cutoff_harmonics!r}")

    def _check_types(self) -> None:
        """TypeError for a number setting that is not a number, or a ``derivative`` not a string."""
        for name in ("cutoff_harmonics", "settle_revolutions", "phase"):
            value = getattr(self, name)
            if (value is not None or name != "phase") and (
                    isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating))):
                raise TypeError(f"`{name}` must be a number, got {value!r:.80}")
        if not isinstance(self.derivative, str):
            raise TypeError(f"`derivative` must be one of {DERIVATIVES}, got {self.derivative!r:.80}")
