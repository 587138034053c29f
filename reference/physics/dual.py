"""Dual numbers, vectors and 3x3 matrices (``x + eps y``, ``eps**2 = 0``), numpy-backed.

A :class:`Dual`'s trailing axes make it a scalar ``(...)``, a 3-vector ``(..., 3)`` or a matrix
``(..., 3, 3)``; operations broadcast over the leading axes. After the paper's section 3.2: a dual
angle ``theta + eps s`` is a rotation [rad] and slide [m] (eq. (13)); a line is ``u + eps (p x u)``
(eq. (10)); a velocity screw ``(omega + eps v) u`` (eq. (11)); a rigid displacement is
``R + eps [p]x R``, mapping lines and screws from the moved frame to the fixed one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "Dual", "as_dual", "sin", "cos", "atan2", "dot", "cross", "matvec", "matrix", "stack",
    "rot_x", "rot_z", "screw_transform", "line", "line_point", "displacement", "solve",
]


class Dual:
    """Array of dual numbers ``re + eps du`` (``du`` broadcast to ``re``'s shape, zero when omitted)."""

    __array_ufunc__ = None  # numpy defers ``ndarray * Dual`` to Dual.__rmul__

    def __init__(self, re: np.ndarray, du: np.ndarray | None = None) -> None:
        re = np.asarray(re, dtype=float)
        du = np.zeros_like(re) if du is None else np.asarray(du, dtype=float)
        self.re, self.du = np.broadcast_arrays(re, du)

    def __repr__(self) -> str:
        return f"Dual(re={self.re!r}, du={self.du!r})"

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of both parts."""
        return self.re.shape

    @property
    def T(self) -> Dual:
        """Transpose of the last two axes (the inverse of a dual rotation matrix)."""
        return Dual(np.swapaxes(self.re, -1, -2), np.swapaxes(self.du, -1, -2))

    def __getitem__(self, index) -> Dual:
        return Dual(self.re[index], self.du[index])

    def sum(self, axis: int) -> Dual:
        """Sum along ``axis``."""
        return Dual(self.re.sum(axis), self.du.sum(axis))

    def cumsum(self, axis: int) -> Dual:
        """Cumulative sum along ``axis``."""
        return Dual(np.cumsum(self.re, axis), np.cumsum(self.du, axis))

    def __neg__(self) -> Dual:
        return Dual(-self.re, -self.du)

    def __add__(self, other) -> Dual:
        other = as_dual(other)
        return Dual(self.re + other.re, self.du + other.du)

    __radd__ = __add__

    def __sub__(self, other) -> Dual:
        return self + (-as_dual(other))

    def __rsub__(self, other) -> Dual:
        return as_dual(other) + (-self)

    def __mul__(self, other) -> Dual:
        """Elementwise product ``a b + eps (a b' + a' b)``."""
        other = as_dual(other)
        return Dual(self.re * other.re, self.re * other.du + self.du * other.re)

    __rmul__ = __mul__

    def __matmul__(self, other) -> Dual:
        """Matrix product (numpy ``matmul`` rules) ``A B + eps (A B' + A' B)``."""
        other = as_dual(other)
        return Dual(self.re @ other.re, self.re @ other.du + self.du @ other.re)


def as_dual(value: Dual | np.ndarray | float) -> Dual:
    """``value`` itself if it is a :class:`Dual`, else a dual with zero dual part."""
    return value if isinstance(value, Dual) else Dual(value)


def sin(x: Dual) -> Dual:
    """``sin x + eps x' cos x`` (eq. (14))."""
    return Dual(np.sin(x.re), x.du * np.cos(x.re))


def cos(x: Dual) -> Dual:
    """``cos x - eps x' sin x`` (eq. (14))."""
    return Dual(np.cos(x.re), -x.du * np.sin(x.re))


def atan2(y: Dual, x: Dual) -> Dual:
    """Dual angle ``arctan2(y, x)`` in (-pi, pi] [rad] + eps slide [m]; ``atan2(k sin t, k cos t) = t``
    for any dual ``k`` with positive real part.
    """
    return Dual(np.arctan2(y.re, x.re), (x.re * y.du - y.re * x.du) / (x.re**2 + y.re**2))


def dot(u: Dual, v: Dual) -> Dual:
    """Dot product over the last axis of dual vectors; of two lines, ``cos`` of their dual angle (eq. (13)).
    """
    return Dual(np.einsum("...i,...i->...", u.re, v.re),
                np.einsum("...i,...i->...", u.re, v.du) + np.einsum("...i,...i->...", u.du, v.re))


def cross(u: Dual, v: Dual) -> Dual:
    """Cross product over the last axis of dual vectors; ``V x S`` is the rate of a line ``S`` moving with
    ``V``.
    """
    return Dual(np.cross(u.re, v.re), np.cross(u.re, v.du) + np.cross(u.du, v.re))


def matvec(m: Dual, v: Dual) -> Dual:
    """Dual matrices (..., 3, 3) times vectors (..., 3) (an array: zero dual part), broadcast."""
    v = as_dual(v)
    return Dual(np.einsum("...ij,...j->...i", m.re, v.re),
                np.einsum("...ij,...j->...i", m.re, v.du) + np.einsum("...ij,...j->...i", m.du, v.re))


def stack(items: Sequence[Dual], axis: int = -1) -> Dual:
    """Stack duals (or arrays) of one shape along a new ``axis`` (``numpy.stack``)."""
    items = [as_dual(x) for x in items]
    return Dual(np.stack([x.re for x in items], axis), np.stack([x.du for x in items], axis))


def matrix(rows: Sequence[Sequence[Dual]]) -> Dual:
    """3x3 dual matrices from nested rows of dual scalars of one shape, shape (..., 3, 3)."""
    return stack([stack(row, -1) for row in rows], -2)


def _zeros_ones(like: Dual) -> tuple[Dual, Dual]:
    return Dual(np.zeros_like(like.re)), Dual(np.ones_like(like.re))


def rot_z(angle: Dual) -> Dual:
    """Screw displacement about z: rotation ``angle.re`` [rad], slide ``angle.du`` [m]."""
    c = cos(angle)
    s = sin(angle)
    zero, one = _zeros_ones(angle)
    return matrix([[c, -s, zero], [s, c, zero], [zero, zero, one]])


def rot_x(angle: Dual) -> Dual:
    """Screw displacement about x: rotation ``angle.re`` [rad], slide ``angle.du`` [m]."""
    c = cos(angle)
    s = sin(angle)
    zero, one = _zeros_ones(angle)
    return matrix([[one, zero, zero], [zero, c, -s], [zero, s, c]])


def screw_transform(theta: Dual, alpha: Dual) -> Dual:
    """Denavit-Hartenberg link transform ``Z(theta) X(alpha)`` (..., 3, 3): joint angle [rad] + eps
    slide [m] ``theta``, link twist [rad] + eps offset [m] ``alpha`` (about and along the new x axis).
    """
    return rot_z(theta) @ rot_x(alpha)


def line(direction: np.ndarray, point: np.ndarray) -> Dual:
    """Plücker line ``u + eps (p x u)``: ``u`` the normalised non-zero ``direction`` (..., 3), ``p`` a
    ``point`` [m].
    """
    u = np.asarray(direction, float)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    return Dual(u, np.cross(np.asarray(point, float), u))


def line_point(lines: Dual) -> np.ndarray:
    """Point of each unit line closest to the origin, ``u x m`` [m], shape (..., 3)."""
    return np.cross(lines.re, lines.du)


def displacement(m: Dual) -> tuple[np.ndarray, np.ndarray]:
    """Rotation ``R`` [-] and translation ``p`` [m] of dual matrices ``R + eps [p]x R``."""
    skew = m.du @ np.swapaxes(m.re, -1, -2)
    return m.re, 0.5 * np.stack([skew[..., 2, 1] - skew[..., 1, 2], skew[..., 0, 2] - skew[..., 2, 0],
                                 skew[..., 1, 0] - skew[..., 0, 1]], -1)


def solve(a: Dual, b: Dual) -> Dual:
    """``x`` solving ``a x = b`` for dual matrices ``a`` (real part regular): ``a.re x.du = b.du - a.du
    x.re``.
    """
    b = as_dual(b)
    x_re = np.linalg.solve(a.re, b.re[..., None])[..., 0]
    x_du = np.linalg.solve(a.re, (b.du - np.einsum("...ij,...j->...i", a.du, x_re))[..., None])
    return Dual(x_re, x_du[..., 0])
