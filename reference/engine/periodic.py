"""One revolution of a periodic time table, repeated: at constant speed and load every column but
``t`` and the shaft angles repeats with ``T = 2 pi / |omega|``, so summary-only runs evaluate the
first period and copy it. Measured: docs/engines.md#constants-of-the-reference-engine.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["period_rows", "repeat_period"]

SHIFTED = ("theta_in", "theta_out")
"""Columns that advance by one turn per period (times the sign of the speed); ``t`` advances by
the period; every other column repeats."""


def period_rows(t: np.ndarray, speed: float) -> int | None:
    """Rows per period of the speed [rad/s] in the equispaced instants ``t`` [s]; None unless the rows
    repeat on the same angles (a whole number of steps, at least one period after the first).
    """
    if t.size < 3 or speed == 0.0:
        return None
    period = 2.0 * math.pi / abs(speed)
    step = (t[-1] - t[0]) / (t.size - 1)
    rows = round(period / step)
    if rows < 1 or rows >= t.size or abs(rows * step - period) > 1e-12 * period:
        return None
    return rows


def repeat_period(first: dict[str, np.ndarray], t: np.ndarray, speed: float) -> dict[str, np.ndarray]:
    """Every column of ``first`` (one period, :func:`period_rows`) over the whole table's instants ``t``
    [s], the shaft angles advancing ``2 pi`` per period in the direction of ``speed``.
    """
    rows = next(iter(first.values())).shape[0]
    k = np.arange(t.size)
    turns, index = np.divmod(k, rows)
    out = {key: np.asarray(value)[index] for key, value in first.items()}
    turn = math.copysign(2.0 * math.pi, speed)
    for key in SHIFTED:
        if key in out:
            out[key] = out[key] + turn * turns
    if "t" in out:
        out["t"] = np.asarray(t, float)
    return out
