"""The friction fixed point ``phi = G(x0 - S phi)`` of one sample by Newton's method, LAPACK called
directly: :func:`reference.engine.fixed_point.solve_friction`'s rule without its batched arrays, for
the forward dynamics' right-hand side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg.lapack import dgeev, dgesv  # a tenth of np.linalg.solve's cost: docs/engines.md

from reference.engine.fixed_point import power_bound

__all__ = ["NEWTON_ITERATIONS", "NEWTON_TOLERANCE", "WARM_START_GAIN", "friction_newton"]

NEWTON_TOLERANCE = 1e-13
"""Stopping rule of :func:`reference.engine.fixed_point.solve_friction`: a Newton update at most this
fraction of the largest friction value."""
NEWTON_ITERATIONS = 50
WARM_START_GAIN = 0.9
"""Newton starts from the previous call's friction (the integrator's calls are close); where the
loop gain it finds is at least this, the sample is solved again from
:func:`reference.engine.fixed_point.solve_friction`'s start, so that a verdict near self-locking is
the same as the direct solve's. Measured: docs/engines.md#constants-of-the-reference-engine."""


_TINY = np.finfo(float).tiny  # n + tiny is n for every normal n, and keeps 0 / 0 away


def _spectral_radius(matrix: np.ndarray) -> float:
    wr, wi, _, _, info = dgeev(matrix, compute_vl=0, compute_vr=0)
    return float(np.max(np.hypot(wr, wi))) if info == 0 else math.inf


def _gain(matrix: np.ndarray, exact_from: float = 0.5) -> float:
    """One sample's loop gain: the spectral radius, or an upper bound below ``exact_from`` (infinity norm;
    for ``exact_from`` >= 1 also :func:`reference.engine.fixed_point.power_bound`).
    """
    norm = float(np.abs(matrix).sum(1).max())
    if not math.isfinite(norm):
        return math.inf
    if norm < exact_from:
        return norm
    if exact_from >= 1.0:  # the verdict only
        bound = float(power_bound(matrix[None], np.array([norm]))[0])
        if bound < exact_from:
            return bound
    return _spectral_radius(matrix)


def friction_newton(sxa: np.ndarray, ks: np.ndarray, coupled: bool = True,
                    start: np.ndarray | None = None) -> tuple[np.ndarray, bool, float, int]:
    """``(phi, converged, loop_gain, iterations)`` of one sample, as
    :func:`reference.engine.fixed_point.solve_friction`: ``sxa`` (4 K, K + 1) row ``4 j + i`` the
    component i of slot j's pair, its response to unit friction and frictionless value (``c = sxa @
    [-phi, 1]``); ``phi_j = ks[2j] |F_j| + ks[2j + 1] |M_j|``; ``coupled`` False: friction of the
    frictionless reactions. ``start`` None: ``solve_friction`` exactly; else the first iterate, and
    Newton also stops where quadratic convergence puts the next update below
    :data:`NEWTON_TOLERANCE` (gain of the last Jacobian, the norm below :data:`WARM_START_GAIN`).
    """
    k = sxa.shape[1] - 1
    ops = _OPERATORS[k]
    strict = start is None or not coupled
    if strict:
        phi = _frictionless(sxa, ks, ops)
        if not coupled:
            return phi, True, 0.0, 0
    else:
        phi = start
    values = phi.tolist()
    scale = max(map(abs, values))  # warm: the start's size, close to the solution's
    before = 0.0
    p = np.ones(k + 1)
    for iterations in range(1, NEWTON_ITERATIONS + 1):
        phi, gm, info = _iterate(phi, p, sxa, ks, ops)
        last = values
        values = phi.tolist()
        size = max(abs(a - b) for a, b in zip(values, last, strict=True))
        top = max(map(abs, values))
        if info or not math.isfinite(size + sum(values)):
            break
        scale = max(scale, top)
        if size <= NEWTON_TOLERANCE * scale:
            if strict:
                gm = _products_at(phi, p, sxa, ks, ops)[:, :k]
            return phi, True, _gain(gm, 0.5 if strict else WARM_START_GAIN), iterations
        if not strict and size ** 3 <= 0.01 * NEWTON_TOLERANCE * scale * before ** 2:
            return phi, True, _gain(gm, WARM_START_GAIN), iterations
        before = size
    return phi, False, math.inf, iterations


def _frictionless(sxa: np.ndarray, ks: np.ndarray, ops: _Operators) -> np.ndarray:
    """The friction (K,) of the frictionless reactions (:func:`friction_newton`'s arguments)."""
    c0 = sxa[:, -1]
    return ops.slots @ (ks * np.sqrt(ops.norms @ (c0 * c0)))


def _products_at(phi: np.ndarray, p: np.ndarray, sxa: np.ndarray, ks: np.ndarray,
                 ops: _Operators) -> np.ndarray:
    """:func:`_products` at the friction ``phi`` (K,); ``p`` (K + 1,) is a buffer ending in 1."""
    p[:phi.size] = -phi
    return _products(sxa @ p, ks, sxa, ops)


def _iterate(phi: np.ndarray, p: np.ndarray, sxa: np.ndarray, ks: np.ndarray,
             ops: _Operators) -> tuple[np.ndarray, np.ndarray, int]:
    """``(iterate, -dG/dphi (K, K), info)``: Newton's next iterate from ``phi``; ``G = W c`` is
    homogeneous in the components, so it is ``(I + W sx)^-1 W c0``.
    """
    k = phi.size
    both = _products_at(phi, p, sxa, ks, ops)
    gm = both[:, :k]
    _, _, phi, info = dgesv(gm + ops.eye, both[:, k])
    return phi, gm, info


@dataclass(frozen=True)
class _Operators:
    """0/1 matrices of :func:`friction_newton` for K slots: ``norms`` (2 K, 4 K) squared
    components to squared norms, ``spread`` (4 K, 2 K) back, ``slots`` (K, 2 K) per-norm terms to
    friction values, ``blocks`` (K, 4 K) rows to their slot; ``eye`` (K, K)."""

    norms: np.ndarray
    spread: np.ndarray
    slots: np.ndarray
    blocks: np.ndarray
    eye: np.ndarray

    @classmethod
    def of(cls, k: int) -> _Operators:
        norms = np.kron(np.eye(2 * k), np.ones(2))
        return cls(norms, norms.T.copy(), np.kron(np.eye(k), np.ones(2)), np.kron(np.eye(k), np.ones(4)),
                   np.eye(k))


_OPERATORS = [_Operators.of(k) for k in range(8)]  # at most seven friction values


def _products(c: np.ndarray, ks: np.ndarray, sxa: np.ndarray, ops: _Operators) -> np.ndarray:
    """``W @ sxa``, shape (K, K + 1): the loop's Jacobian ``-dG/dphi`` and ``W c0``, with ``W``
    (K, 4 K) block-diagonal, the unit pair components of ``c`` (4 K,) times their factors (zero
    where a norm vanishes: there ``c`` is zero)."""
    w = c * (ops.spread @ (ks / (np.sqrt(ops.norms @ (c * c)) + _TINY)))
    return (ops.blocks * w) @ sxa
