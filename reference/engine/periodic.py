"""One revolution of a periodic time table, repeated.

At a constant input speed and a constant load the joint's state is a function of the input angle
modulo one revolution (closed-form or loop kinematics, inverse dynamics, friction): every column
of the time table repeats with the period ``T = 2 pi / |omega|`` except the time and the two shaft
angles, which advance by ``T`` and one turn. When the table's rows fall on the same input angles in
every revolution (a whole number of rows per period, as :func:`reference.engine.table.table_times` gives
for whole revolutions), the rows of the first period are evaluated and the others are copies: the
same values to rounding (the trigonometric functions of ``theta`` and ``theta + 2 pi k`` differ
in the last bits only), at ``1 / revolutions`` of the cost.

Only summary-only runs (``record.timeseries = false``) use it, where the table serves the verdict
and the means: in a recorded table a copied row's angle is its own ``theta + 2 pi k`` rounded, not
the angle its state was computed at, which a user recomputing the state from the row (the power
balance at 85 deg, ``tests/test_reference_dynamics.py``) would see at 1e-8 of the power.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["period_rows", "repeat_period"]

SHIFTED = ("theta_in", "theta_out")
"""Columns that advance by one turn per period (times the sign of the speed); ``t`` advances by
the period; every other column repeats."""


def period_rows(t: np.ndarray, speed: float) -> int | None:
    """Rows of the uniform table ``t`` [s] in one period of the input speed ``speed`` [rad/s]:
    None unless the rows repeat on the same angles (a whole number of steps per period, at least
    one period after the first)."""
    if t.size < 3 or speed == 0.0:
        return None
    period = 2.0 * math.pi / abs(speed)
    step = (t[-1] - t[0]) / (t.size - 1)
    rows = round(period / step)
    if rows < 1 or rows >= t.size or abs(rows * step - period) > 1e-12 * period:
        return None
    return rows


def repeat_period(first: dict[str, np.ndarray], t: np.ndarray, speed: float) -> dict[str, np.ndarray]:
    """The whole table at ``t`` [s] from ``first``, the columns at ``t[:rows]`` (one period, see
    :func:`period_rows`); ``t`` is taken as given, the shaft angles advance by ``2 pi`` per period
    in the direction of ``speed`` [rad/s]."""
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
