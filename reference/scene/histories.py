"""Evaluating prescribed histories (an input angle, a load torque) cheaply and exactly.

An engine that steps in time evaluates the drive's angle and the load's torque at every residual
evaluation, one instant at a time, from Python (Exudyn's user functions): that evaluation must
cost O(log n) in the number of samples ``n``, not O(n). :class:`LinearHistory` and
:class:`CubicPieces` find the sample interval by bisection in precomputed lists and evaluate one
linear or cubic piece in plain floats, a fraction of a spline call's cost (measured:
docs/engines.md#constants-of-the-reference-engine). Arrays of instants go to ``np.interp`` / the spline itself
(vectorised, O(m log n)).

:func:`largest_slope` and :func:`first_turn` answer the two questions engines ask of a whole
angle history (its highest speed, when it has turned a given angle) exactly from the cubic
pieces' coefficients, in O(n) vectorised work, instead of sampling the spline 20-50 times per
sample interval (10^7 - 10^8 evaluations for a 10^6-sample history).
"""

from __future__ import annotations

import bisect
import dataclasses
from typing import Any

import numpy as np

__all__ = ["CubicPieces", "LinearHistory", "first_turn", "largest_slope", "run_clock", "time_origin"]


class LinearHistory:
    """Samples ``(time, value)`` interpolated linearly, held at the end values outside.

    Parameters
    ----------
    time : array_like, shape (n,)
        Strictly increasing sample times [s], n >= 2.
    value : array_like, shape (n,)
        Values at those times.
    """

    __slots__ = ("time", "value", "_t", "_v", "_k")

    def __init__(self, time: Any, value: Any) -> None:
        self.time = np.asarray(time, dtype=float)
        self.value = np.asarray(value, dtype=float)
        self._t = self.time.tolist()
        self._v = self.value.tolist()
        self._k = 1

    def __call__(self, t: float) -> float:
        """The value at one instant ``t`` [s] (plain floats, O(log n); O(1) when ``t`` falls in
        the interval of the previous call, as a time stepper's calls do)."""
        times = self._t
        values = self._v
        k = self._k
        if not (k < len(times) and times[k - 1] <= t < times[k]):
            k = bisect.bisect_right(times, t)
            if k == 0:
                return values[0]
            if k == len(times):
                return values[-1]
            self._k = k
        t0 = times[k - 1]
        v0 = values[k - 1]
        # np.interp's formula, so both paths give the same value to rounding
        return (values[k] - v0) / (times[k] - t0) * (t - t0) + v0

    def at(self, t: Any) -> np.ndarray:
        """Values at the instants ``t`` (any shape) [s]."""
        return np.interp(t, self.time, self.value)


class CubicPieces:
    """A ``scipy.interpolate.CubicSpline`` (or any cubic ``PPoly``) evaluated at one instant in
    plain floats: bisection for the piece, Horner's rule for the value, the end pieces extended
    outside the breakpoints as the spline itself does.

    Parameters
    ----------
    spline : scipy.interpolate.PPoly
        Cubic pieces: ``spline.c`` of shape (4, n - 1), breakpoints ``spline.x`` of shape (n,).
    """

    __slots__ = ("_x", "_c0", "_c1", "_c2", "_c3", "_last", "_k")

    def __init__(self, spline: Any) -> None:
        c = np.asarray(spline.c, dtype=float)
        if c.shape[0] != 4:
            raise ValueError(f"`spline` must have cubic pieces (c of shape (4, n - 1)), got {c.shape}")
        self._x = np.asarray(spline.x, dtype=float).tolist()
        self._c0, self._c1, self._c2, self._c3 = (row.tolist() for row in c)
        self._last = len(self._x) - 2
        self._k = 0

    def __call__(self, t: float) -> float:
        """The spline's value at one instant ``t`` (plain floats, O(log n); O(1) when ``t``
        falls in the piece of the previous call)."""
        x = self._x
        k = self._k
        if not (x[k] <= t < x[k + 1]):
            k = self._k = min(max(bisect.bisect_right(x, t) - 1, 0), self._last)
        s = t - x[k]
        return ((self._c0[k] * s + self._c1[k]) * s + self._c2[k]) * s + self._c3[k]


def largest_slope(spline: Any) -> float:
    """Largest ``|s'(t)|`` of a cubic spline over its breakpoints' span, exactly.

    ``s'`` is quadratic on each piece: its largest magnitude is at an end of the piece or at the
    vertex ``-c1 / (3 c0)`` when that lies inside.
    """
    c = np.asarray(spline.c, dtype=float)
    h = np.diff(np.asarray(spline.x, dtype=float))
    c0 = c[0]
    c1 = c[1]
    c2 = c[2]
    ends = np.maximum(np.abs(c2), np.abs((3.0 * c0 * h + 2.0 * c1) * h + c2))
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = -c1 / (3.0 * c0)
    inside = np.isfinite(vertex) & (vertex > 0.0) & (vertex < h)
    at_vertex = np.where(inside, np.abs(c2 - c1 * c1 / np.where(inside, 3.0 * c0, 1.0)), 0.0)
    return float(max(ends.max(), at_vertex.max()))


def _turning_points(spline: Any) -> np.ndarray:
    """Breakpoints and the interior extrema of each cubic piece, in increasing order [s]."""
    c = np.asarray(spline.c, dtype=float)
    x = np.asarray(spline.x, dtype=float)
    h = np.diff(x)
    a = 3.0 * c[0]  # s'(tau) = a tau^2 + b tau + d on each piece
    b = 2.0 * c[1]
    d = c[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.maximum(b * b - 4.0 * a * d, 0.0))
        quadratic = [(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)]
        linear = -d / b
    cand = [np.where(a != 0.0, q, linear) for q in quadratic]
    extra = [x[:-1][(tau > 0.0) & (tau < h)] + tau[(tau > 0.0) & (tau < h)] for tau in cand]
    return np.unique(np.concatenate([x, *extra]))


def first_turn(spline: Any, angle: float) -> float | None:
    """First time at which the spline has moved ``angle`` either way from its start.

    Between consecutive breakpoints and interior extrema the spline is monotone, so the first
    such point where ``|s - s(x0)|`` reaches ``angle`` brackets exactly one crossing.

    Parameters
    ----------
    spline : scipy.interpolate.PPoly
        Cubic pieces of an angle history [rad] over time [s].
    angle : float
        Angle to turn [rad], > 0.

    Returns
    -------
    float or None
        The time [s], refined to rounding; None if the spline never moves that far within its
        span.
    """
    from scipy.optimize import brentq  # scipy.optimize takes ~0.5 s to import

    points = _turning_points(spline)
    start = float(spline(points[0]))
    turned = np.maximum.accumulate(np.abs(spline(points) - start))
    k = int(np.searchsorted(turned, angle))
    if k >= points.size:
        return None
    if k == 0:
        return float(points[0])
    return float(brentq(lambda t: abs(float(spline(t)) - start) - angle, points[k - 1], points[k],
                        xtol=1e-15, rtol=4 * np.finfo(float).eps))


def time_origin(scene: Any) -> float:
    """Where a scene's clock starts [s]: the angle history's first sample, else the load
    history's first sample, else 0 (constant speed or torque drive, constant load).

    The drive's and the load's histories share one clock, so a measured angle and torque keep
    their alignment; only the origin moves.
    """
    if scene.drive.kind == "angle":
        return float(scene.drive.time[0])
    if scene.load.time is not None:
        return float(scene.load.time[0])
    return 0.0


def run_clock(scene: Any) -> tuple[Any, float]:
    """The scene with its histories on a clock that starts at 0, and the origin moved [s].

    Engines run on this clock, so that a history starting at t = 1e9 s gives what the same
    history starting at 0 gives: at 1e9 s doubles are 1.2e-7 s apart, the step's own instants
    would round by a part in 10^4 at a 1 ms step, and every time difference (speeds from
    positions, the step, the friction log's matching of instants) with them. The shift subtracts
    the first sample from every sample time, exactly for samples within a factor two of it; the
    engines add the origin back to the time column they return.
    """
    origin = time_origin(scene)
    if origin == 0.0:
        return scene, 0.0
    drive = scene.drive.shifted(origin) if scene.drive.kind == "angle" else scene.drive
    return dataclasses.replace(scene, drive=drive, load=scene.load.shifted(origin)), origin
