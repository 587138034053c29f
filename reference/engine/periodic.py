"""One revolution of a periodic time table, repeated.

At a constant input speed and load every column repeats with the period ``T = 2 pi / |omega|``
except ``t`` and the two shaft angles, which advance by ``T`` and one turn. When the rows fall on
the same input angles in every revolution, the first period is evaluated and the others are copies
(the same values to rounding, at ``1 / revolutions`` of the cost). Summary-only runs use it: in a
recorded table a copied row's angle is ``theta + 2 pi k`` rounded, not the angle its state was
computed at. Measured: docs/engines.md#constants-of-the-reference-engine.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["period_rows", "repeat_period"]

SHIFTED = ("theta_in", "theta_out")
"""Columns that advance by one turn per period (times the sign of the speed); ``t`` advances by
the period; every other column repeats."""


def period_rows(t: np.ndarray, speed: float) -> int | None:
    """Rows of a uniform time table in one period of the input speed.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Equispaced instants [s].
    speed : float
        Constant input speed [rad/s].

    Returns
    -------
    int or None
        Rows per period; None unless the rows repeat on the same angles (a whole number of steps
        per period, at least one period after the first).
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
    """The whole table from its first period.

    Parameters
    ----------
    first : dict of str to ndarray, shape (rows,)
        The columns at ``t[:rows]`` (one period, :func:`period_rows`).
    t : ndarray, shape (n,)
        The whole table's instants [s], taken as given.
    speed : float
        Input speed [rad/s]; the shaft angles advance by ``2 pi`` per period in its direction.

    Returns
    -------
    dict of str to ndarray, shape (n,)
        Every column of ``first`` over the whole table.
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
