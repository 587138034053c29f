"""Evaluating prescribed histories (an input angle, a load torque) cheaply and exactly.

A time stepper evaluates them one instant at a time from Python, so that must cost O(log n):
:class:`LinearHistory` and :class:`CubicPieces` bisect precomputed lists and evaluate one piece in
plain floats (measured: docs/engines.md#constants-of-the-reference-engine). :func:`largest_slope`
and :func:`first_turn` answer exactly from the cubic pieces' coefficients in O(n) vectorised work.
"""

from __future__ import annotations

import bisect
import dataclasses
from typing import Any

import numpy as np

__all__ = ["CubicPieces", "LinearHistory", "first_turn", "largest_slope", "run_clock", "time_origin"]


class LinearHistory:
    """Samples ``(time, value)`` interpolated linearly, held at the end values outside; ``time`` [s]
    strictly increasing, n >= 2.
    """

    __slots__ = ("time", "value", "_t", "_v", "_k")

    def __init__(self, time: Any, value: Any) -> None:
        self.time = np.asarray(time, dtype=float)
        self.value = np.asarray(value, dtype=float)
        self._t = self.time.tolist()
        self._v = self.value.tolist()
        self._k = 1

    def __call__(self, t: float) -> float:
        """The value at one instant ``t`` [s] (plain floats, O(log n); O(1) in the previous call's
        interval).
        """
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
    """A cubic ``PPoly`` ``spline`` (e.g. ``CubicSpline``) evaluated at one instant in plain floats:
    bisection for the piece, Horner's rule, the end pieces extended outside as the spline does.
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
        """The spline's value at one instant ``t`` (plain floats, O(log n); O(1) in the previous call's
        piece).
        """
        x = self._x
        k = self._k
        if not (x[k] <= t < x[k + 1]):
            k = self._k = min(max(bisect.bisect_right(x, t) - 1, 0), self._last)
        s = t - x[k]
        return ((self._c0[k] * s + self._c1[k]) * s + self._c2[k]) * s + self._c3[k]


def largest_slope(spline: Any) -> float:
    """Largest ``|s'(t)|`` of a cubic ``spline`` over its span, exactly: at a piece's end or at the vertex
    ``-c1 / (3 c0)`` of the quadratic ``s'``.
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
    """First time [s] the angle ``spline`` [rad] has moved ``angle`` [rad] (> 0) either way from its
    start, refined to rounding within the monotone piece bracketing it; None if it never does.
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
    """Where ``scene``'s clock starts [s]: the angle history's first sample, else the load history's, else
    0 (drive and load histories share one clock).
    """
    if scene.drive.kind == "angle":
        return float(scene.drive.time[0])
    if scene.load.time is not None:
        return float(scene.load.time[0])
    return 0.0


def run_clock(scene: Any) -> tuple[Any, float]:
    """``scene`` with its histories on a clock starting at 0, and the origin moved [s]. Why: at t = 1e9 s
    doubles are 1.2e-7 s apart; engines add the origin back to the time column.
    """
    origin = time_origin(scene)
    if origin == 0.0:
        return scene, 0.0
    drive = scene.drive.shifted(origin) if scene.drive.kind == "angle" else scene.drive
    return dataclasses.replace(scene, drive=drive, load=scene.load.shifted(origin)), origin
