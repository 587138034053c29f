"""Dual numbers, vectors and 3x3 matrices (``x + eps y`` with ``eps**2 = 0``), numpy-backed.

A :class:`Dual` holds two arrays of one shape: the real part and the dual ("moment") part. The
trailing axes decide what it is: a scalar array ``(...)``, a 3-vector ``(..., 3)`` or a 3x3 matrix
``(..., 3, 3)``; every operation broadcasts over the leading axes like numpy does.

Geometric meaning, following section 3.2 of the paper:

- a dual angle ``theta + eps s`` (eq. (13)) is a rotation ``theta`` [rad] about an axis and a
  slide ``s`` [m] along it;
- a line (screw axis) is the dual unit vector ``u + eps (p x u)`` (eq. (10)): its direction
  ``u`` [-] and its moment about the origin [m], ``p`` any point of the line;
- a velocity screw ``(omega + eps v) u`` (eq. (11)) has the angular velocity [rad/s] as real
  part and, as dual part, the velocity [m/s] of the body point at the origin;
- a rigid displacement (rotation ``R``, translation ``p``) is the dual orthogonal matrix
  ``R + eps [p]x R``: it maps lines and screws from the moved frame to the fixed one, and the
  product of two such matrices is the composed displacement.

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation", section 3.2, eqs. (10)-(14).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "Dual", "as_dual", "sin", "cos", "atan2", "dot", "cross", "matvec", "matrix", "stack",
    "rot_x", "rot_z", "screw_transform", "line", "line_point", "displacement", "solve",
]


class Dual:
    """Array of dual numbers ``re + eps du`` (``eps**2 = 0``).

    Parameters
    ----------
    re : array_like
        Real part.
    du : array_like, optional
        Dual part, broadcast to the shape of ``re``; zero when omitted.
    """

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
    """Dual angle whose sine and cosine are proportional to ``y`` and ``x``.

    The dual part ``(x y' - y x') / (x^2 + y^2)`` does not change when ``y`` and ``x`` are
    multiplied by one dual number with positive real part, so ``atan2(k sin t, k cos t) = t`` for
    the dual angle ``t``.

    Parameters
    ----------
    y, x : Dual
        Of one shape.

    Returns
    -------
    Dual
        Angle ``arctan2(y, x)`` in (-pi, pi] [rad] + eps slide [m].
    """
    return Dual(np.arctan2(y.re, x.re), (x.re * y.du - y.re * x.du) / (x.re**2 + y.re**2))


def dot(u: Dual, v: Dual) -> Dual:
    """Dot product over the last axis; of two lines: ``cos`` of their dual angle (eq. (13)).

    Parameters
    ----------
    u, v : Dual, shape (..., 3)
        Dual vectors.

    Returns
    -------
    Dual, shape (...)
    """
    return Dual(np.einsum("...i,...i->...", u.re, v.re),
                np.einsum("...i,...i->...", u.re, v.du) + np.einsum("...i,...i->...", u.du, v.re))


def cross(u: Dual, v: Dual) -> Dual:
    """Cross product over the last axis; ``V x S`` is the rate of a line ``S`` moving with ``V``.

    Parameters
    ----------
    u, v : Dual, shape (..., 3)
        Dual vectors.

    Returns
    -------
    Dual, shape (..., 3)
    """
    return Dual(np.cross(u.re, v.re), np.cross(u.re, v.du) + np.cross(u.du, v.re))


def matvec(m: Dual, v: Dual) -> Dual:
    """Matrix times vector, broadcast over the leading axes.

    Parameters
    ----------
    m : Dual, shape (..., 3, 3)
        Dual matrices.
    v : Dual or ndarray, shape (..., 3)
        Vectors (an array: zero dual part).

    Returns
    -------
    Dual, shape (..., 3)
    """
    v = as_dual(v)
    return Dual(np.einsum("...ij,...j->...i", m.re, v.re),
                np.einsum("...ij,...j->...i", m.re, v.du) + np.einsum("...ij,...j->...i", m.du, v.re))


def stack(items: Sequence[Dual], axis: int = -1) -> Dual:
    """Stack duals of one shape along a new axis (``numpy.stack``).

    Parameters
    ----------
    items : sequence of Dual or array_like
        Of one shape ``s``.
    axis : int
        Position of the new axis.

    Returns
    -------
    Dual
        Shape ``s`` with ``len(items)`` inserted at ``axis``.
    """
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
    """Denavit-Hartenberg link transform ``Z(theta) X(alpha)``, shape (..., 3, 3).

    Parameters
    ----------
    theta : Dual
        Joint angle [rad] + eps joint slide [m], about and along the joint's z axis.
    alpha : Dual
        Link twist [rad] + eps link offset [m], about and along the common normal (new x axis).
    """
    return rot_z(theta) @ rot_x(alpha)


def line(direction: np.ndarray, point: np.ndarray) -> Dual:
    """Plücker line ``u + eps (p x u)`` with ``u`` the normalised ``direction`` (..., 3) [-].

    Parameters
    ----------
    direction : ndarray, shape (..., 3)
        Direction of the line, non-zero [-].
    point : ndarray, shape (..., 3)
        Any point of the line [m].
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
    """Solution ``x`` of ``a x = b``.

    ``a.re x.re = b.re``, then ``a.re x.du = b.du - a.du x.re`` (the eps part of ``a x = b``).

    Parameters
    ----------
    a : Dual, shape (..., n, n)
        Dual matrices, real part regular.
    b : Dual or ndarray, shape (..., n)
        Right-hand sides.

    Returns
    -------
    Dual, shape (..., n)
    """
    b = as_dual(b)
    x_re = np.linalg.solve(a.re, b.re[..., None])[..., 0]
    x_du = np.linalg.solve(a.re, (b.du - np.einsum("...ij,...j->...i", a.du, x_re))[..., None])
    return Dual(x_re, x_du[..., 0])
