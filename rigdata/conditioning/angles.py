"""Shaft angles on the sample grid: from pulse edges, an angle channel, or the integral of a speed channel."""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import PchipInterpolator

from rigdata.record import RigDataError, RigRecord

__all__ = ["pulse_edges", "angle_on_grid"]


def pulse_edges(t: np.ndarray, angle: np.ndarray, quantum: float) -> tuple[np.ndarray, np.ndarray]:
    """Instants and angles of the pulse edges of a counted (staircase) angle.

    Each edge is placed midway between the samples where the count changes (timing uncertainty one
    sample interval, rectangular); pulses within one interval share the instant.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    angle : ndarray, shape (n,)
        Counted angle [rad], a multiple of ``quantum``.
    quantum : float
        Angle of one pulse [rad].

    Returns
    -------
    times, levels : ndarray, shape (m,)
        Edge instants [s] (empty if fewer than two changes) and the angles they reach [rad].
    """
    steps = np.flatnonzero(np.diff(angle) != 0.0)
    if steps.size < 2:
        return np.zeros(0), np.zeros(0)
    times = 0.5 * (t[steps] + t[steps + 1])
    levels = angle[steps + 1]
    # the angle at the edge is the level reached (crossing the multiple of the pulse angle)
    keep = np.concatenate([[True], np.diff(times) > 0])
    return times[keep], levels[keep]


def angle_on_grid(record: RigRecord, shaft: str) -> tuple[np.ndarray, np.ndarray | None]:
    """A shaft's angle on the record's grid and, for pulses, the edge instants.

    Pulse counts: monotone cubic (PCHIP) through the edges, linear outside them.

    Parameters
    ----------
    record : RigRecord
    shaft : {"in", "out"}

    Returns
    -------
    angle : ndarray, shape (n,)
        Angle at every sample [rad].
    edges : ndarray or None
        Pulse edge instants [s] for a counted angle.

    Raises
    ------
    RigDataError
        Fewer than 4 pulse edges, or a count going back and forth.
    """
    t = record.time
    angle = record.channels.get(f"angle_{shaft}")
    source = record.sources.get(f"angle_{shaft}")
    if angle is not None and source is not None and source.quantum > 0:
        times, levels = pulse_edges(t, angle, source.quantum)
        if times.size < 4:
            raise RigDataError(f"fewer than 4 pulse edges ({times.size}): the shaft hardly turns",
                               file=record.file, channel=f"angle_{shaft}")
        if not (np.all(np.diff(levels) > 0) or np.all(np.diff(levels) < 0)):
            raise RigDataError("the pulse count goes back and forth: the shaft reverses or the "
                               "counter is not a cumulative count", file=record.file,
                               channel=f"angle_{shaft}")
        return PchipInterpolator(times, levels, extrapolate=True)(t), times
    if angle is not None:
        return np.asarray(angle, float), None
    return cumulative_trapezoid(record.channels[f"speed_{shaft}"], t, initial=0.0), None
