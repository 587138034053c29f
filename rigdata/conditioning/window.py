"""The whole-revolution window: where the measured efficiency is averaged.

``settle`` revolutions are dropped at each end (filter transients, start-up); the window starts
at the first input pulse edge after them (or at the settled angle, without pulses) and ends a
whole number of revolutions later, also on an edge, so the input angle turned over it is exact.
"""

from __future__ import annotations

import math

import numpy as np

from rigdata.record import RigDataError

__all__ = ["revolution_window"]


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
