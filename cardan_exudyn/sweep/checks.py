"""What every check of a sweep specification shares: the error, the largest sweep, the number check."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["SweepError", "MAX_CASES", "finite_number"]

MAX_CASES = 100_000
"""Most cases one sweep may have (grid points times random samples): more would take weeks and a
plan too large for memory."""


class SweepError(ValueError):
    """The sweep specification or the output folder is invalid; the message names the key."""


def finite_number(where: str, value: Any) -> float:
    """``value`` as a float; SweepError naming key ``where`` unless a finite number (booleans refused)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SweepError(f"{where} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SweepError(f"{where} must be finite, got {value!r}")
    return value
