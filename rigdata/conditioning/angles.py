"""Shaft angles on the record's sample grid: from pulse edges (a counted, staircase angle), from
an angle channel as given, or from a speed channel by the trapezoidal integral."""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import PchipInterpolator

from rigdata.record import RigDataError, RigRecord

__all__ = ["pulse_edges", "angle_on_grid"]


def pulse_edges(t: np.ndarray, angle: np.ndarray, quantum: float) -> tuple[np.ndarray, np.ndarray]:
    """Instants and angles of the pulse edges of a counted (staircase) angle.

    The count changes between two samples; the edge is placed midway (its timing uncertainty
    is one sample interval, rectangular). Several pulses within one interval share the instant.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    angle : ndarray, shape (n,)
        The counted angle [rad], a multiple of ``quantum`` at every sample.
    quantum : float
        Angle of one pulse [rad].

    Returns
    -------
    times : ndarray, shape (m,)
        Edge instants [s], increasing; empty when the count changes fewer than twice.
    levels : ndarray, shape (m,)
        The angle each edge reaches [rad].
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

    Pulse counts go through their edges by monotone cubic (PCHIP) interpolation, extrapolated
    linearly outside the first and last edge (that span is trimmed later).

    Parameters
    ----------
    record : RigRecord
        The measurement.
    shaft : {"in", "out"}
        Which shaft.

    Returns
    -------
    angle : ndarray, shape (n,)
        The angle at every sample [rad].
    edges : ndarray or None
        Pulse edge instants [s] for a counted angle, else None.

    Raises
    ------
    RigDataError
        Fewer than 4 pulse edges, or a count that goes back and forth.
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
