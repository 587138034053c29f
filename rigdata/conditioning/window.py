"""The whole-revolution window, where the measured efficiency is averaged, and integral weights over it.

``settle`` revolutions dropped at each end; the window starts and ends on input pulse edges, so the
input angle turned over it is exact.
"""

from __future__ import annotations

import math

import numpy as np

from rigdata.record import RigDataError

__all__ = ["revolution_window", "window_weights"]


def _window_start(t: np.ndarray, a: np.ndarray, edges: np.ndarray | None, first: float, last: float,
                  settle: float, file: object) -> float:
    """First instant [s] at or after the settled angle ``first``: an edge in [``first``, ``last``] where there
    are edges.
    """
    if edges is None:
        return float(np.interp(first, a, t))
    edge_angle = np.interp(edges, t, a)
    usable = edges[(edge_angle >= first) & (edge_angle <= last)]
    if usable.size < 2:
        raise RigDataError("less than one whole input revolution after trimming "
                           f"{settle:g} revolutions at each end", file=file, channel="angle_in")
    return float(usable[0])


def revolution_window(t: np.ndarray, angle: np.ndarray, edges: np.ndarray | None, settle: float,
                      file: object) -> tuple[float, float, int]:
    """The input shaft's whole-revolution window.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    angle : ndarray, shape (n,)
        Input angle [rad], either sense.
    edges : ndarray or None
        Input pulse edge instants [s].
    settle : float
        Revolutions dropped at each end [-].
    file : object
        Named in errors.

    Returns
    -------
    t_a, t_b : float
        Window start and end [s].
    n : int
        Whole revolutions in the window.

    Raises
    ------
    RigDataError
        Less than one whole revolution after settling.
    """
    sign = 1.0 if angle[-1] >= angle[0] else -1.0
    a = sign * angle
    first = a[0] + 2 * math.pi * settle
    last = a[-1] - 2 * math.pi * settle
    t_a = _window_start(t, a, edges, first, last, settle, file)
    a_a = float(np.interp(t_a, t, a))
    n = int(math.floor((last - a_a) / (2 * math.pi) + 1e-9))
    if n < 1:
        raise RigDataError(
            f"less than one whole input revolution: the record turns {(a[-1] - a[0]) / (2 * math.pi):.3g} "
            f"revolutions and {2 * settle:g} are trimmed for settling (--settle)", file=file,
            channel="angle_in")
    target = a_a + 2 * math.pi * n
    if edges is not None:  # the end is an edge too: the angle there is exact
        edge_angle = np.interp(edges, t, a)
        t_b = float(edges[int(np.argmin(np.abs(edge_angle - target)))])
    else:
        t_b = float(np.interp(target, a, t))
    return t_a, t_b, n


def window_weights(t: np.ndarray, t_a: float, t_b: float) -> np.ndarray:
    """Trapezoid weights [s] of ``int_{t_a}^{t_b} y dt`` on the grid ``t`` (``weights @ y``).

    Ends interpolated linearly: exact for piecewise-linear ``y``, continuous in ``t_a, t_b``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s], increasing, ``n >= 2``.
    t_a, t_b : float
        Limits [s], ``t[0] <= t_a < t_b <= t[-1]``.
    """
    grid = np.concatenate([[t_a], t[(t > t_a) & (t < t_b)], [t_b]])
    half = 0.5 * np.diff(grid)
    w_grid = np.zeros(grid.size)
    w_grid[:-1] += half
    w_grid[1:] += half
    # spread each node's weight onto the two samples it is interpolated from
    k = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    frac = (grid - t[k]) / (t[k + 1] - t[k])
    weights = np.zeros(t.size)
    np.add.at(weights, k, w_grid * (1.0 - frac))
    np.add.at(weights, k + 1, w_grid * frac)
    return weights
