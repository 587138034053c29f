"""The whole-revolution window, where the measured efficiency is averaged, and the weights of an
integral over it.

``settle`` revolutions are dropped at each end (filter transients, start-up); the window starts
at the first input pulse edge after them (or at the settled angle, without pulses) and ends a
whole number of revolutions later, also on an edge, so the input angle turned over it is exact.
"""

from __future__ import annotations

import math

import numpy as np

from rigdata.record import RigDataError

__all__ = ["revolution_window", "window_weights"]


def _window_start(t: np.ndarray, a: np.ndarray, edges: np.ndarray | None, first: float, last: float,
                  settle: float, file: object) -> float:
    """The first instant [s] at or after the settled angle ``first``: an edge whose angle lies in
    [``first``, ``last``] where there are edges."""
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
    """The whole-revolution window of the input shaft (see the module docstring).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    angle : ndarray, shape (n,)
        Input angle on the grid [rad] (either sense of rotation).
    edges : ndarray or None
        Input pulse edge instants [s], None without pulses.
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
        Less than one whole revolution after the settling.
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
    """Trapezoid weights of ``int_{t_a}^{t_b} y dt`` for samples ``y`` on the grid ``t``.

    The ends are interpolated linearly between the samples that bracket them, so the weights
    are exact for piecewise-linear ``y`` and the integral moves continuously with ``t_a, t_b``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s], increasing, ``n >= 2``.
    t_a, t_b : float
        The integral's limits [s], ``t[0] <= t_a < t_b <= t[-1]``.

    Returns
    -------
    ndarray, shape (n,)
        Weights [s]: ``weights @ y`` is the integral.
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
