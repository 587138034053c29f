"""The friction fixed point of the inverse (and forward) dynamics, for many samples at once.

With friction values ``phi`` the reactions are ``x = x0 - S phi`` and eqs. (3), (5) give
``phi = G(x)``; :func:`solve_friction` solves ``phi = G(x0 - S phi)`` by Newton per sample on the
four components of ``x`` each slot reads, (n, K, 4). Loop gain (spectral radius of ``dG/dphi``)
>= 1: the joint self-locks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["FixedPoint", "loop_gain", "solve_friction", "power_bound", "POWER_SQUARINGS"]

POWER_SQUARINGS = 6
"""Squarings of :func:`power_bound`: the bound of ``||G^64||^(1/64)``.
Measured: docs/engines.md#constants-of-the-reference-engine."""


@dataclass
class FixedPoint:
    """Outcome of the friction fixed point per sample: ``x`` (n, 18) reactions and drive unknown,
    ``friction`` (n, K), ``converged`` (n,), ``loop_gain`` (n,) (spectral radius of ``dG/dphi``, or an
    upper bound below ``exact_gain``; infinite where Newton failed), and the slowest sample's
    ``iterations``.
    """

    x: np.ndarray
    friction: np.ndarray
    converged: np.ndarray
    loop_gain: np.ndarray
    iterations: int

    @property
    def self_locking(self) -> np.ndarray:
        """Per sample: no converged fixed point, or a loop gain of 1 or more (bool array)."""
        return ~self.converged | ~(self.loop_gain < 1.0)


def power_bound(g: np.ndarray, norm: np.ndarray) -> np.ndarray:
    """Upper bounds (n,), at most ``norm``, of the spectral radii of ``g`` (n, K, K) with infinity norms
    ``norm``: ``rho(G) <= ||G^m||^(1/m)`` (Gelfand), ``m = 2^POWER_SQUARINGS`` by squaring ``G / ||G||``.
    """
    p = g / norm[:, None, None]
    for _ in range(POWER_SQUARINGS):
        p = p @ p
    return np.minimum(norm, norm * np.max(np.sum(np.abs(p), -1), -1) ** (1.0 / 2 ** POWER_SQUARINGS))


def solve_friction(law: Any, x0: np.ndarray, s: np.ndarray, signs: np.ndarray,
                   tolerance: float = 1e-13, max_iterations: int = 50,
                   exact_gain: float = 0.5) -> FixedPoint:
    """:class:`FixedPoint` of ``phi = G(x0 - S phi)`` per sample by Newton's method: ``law`` gives ``G``
    (its ``index`` (K, 4) and ``reduced(c, signs)``), ``x0`` (n, 18) the frictionless solution, ``s``
    (n, 18, K) its response to unit friction, ``signs`` (n, K); converged when the update is at most
    ``tolerance`` times the sample's largest friction value, within ``max_iterations``; ``exact_gain``
    as for :func:`loop_gain`.
    """
    n = x0.shape[0]
    k = s.shape[-1]
    if k == 0:
        return FixedPoint(x0, np.zeros((n, 0)), np.ones(n, bool), np.zeros(n), 0)
    # the law reads 4 components per slot: Newton on those, (n, K, 4) and (n, K, 4, K), not on x
    index = law.index
    s_c = s[:, index, :]
    c0 = x0[:, index]
    phi, _ = law.reduced(c0, signs)  # the friction of the frictionless reactions
    converged, iterations = _newton(law, c0, s_c, signs, phi, tolerance, max_iterations)
    x = x0 - np.einsum("nik,nk->ni", s, phi)
    _, g_c = law.reduced(x[:, index], signs)
    gain = loop_gain(g_c, s_c, exact_gain)
    gain[~converged] = np.inf  # no solution found: the friction loop has no finite value
    return FixedPoint(x, phi, converged, gain, iterations)


def _newton(law: Any, c0: np.ndarray, s_c: np.ndarray, signs: np.ndarray, phi: np.ndarray,
            tolerance: float, max_iterations: int) -> tuple[np.ndarray, int]:
    """Newton on ``phi = G(c0 - S_c phi)`` per sample, compacting unconverged samples; ``phi`` (n, K), the
    first iterate, is overwritten with the solution. Returns ``converged`` (n,) and the slowest's
    iterations.
    """
    n = phi.shape[0]
    converged = np.zeros(n, bool)
    active = np.arange(n)
    c_a = c0
    s_a = s_c
    signs_a = signs
    phi_a = phi.copy()
    scale_a = np.max(np.abs(phi), -1)
    iterations = 0
    eye = np.eye(s_c.shape[-1])
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (returned)
        step = _newton_step(law, c_a, s_a, signs_a, phi_a, eye)
        phi_a -= step
        scale_a = np.maximum(scale_a, np.max(np.abs(phi_a), -1))
        done = np.max(np.abs(step), -1) <= tolerance * np.maximum(scale_a, np.finfo(float).tiny)
        bad = ~np.all(np.isfinite(phi_a), -1)
        stop = done | bad
        phi[active] = phi_a
        converged[active[done & ~bad]] = True
        if np.all(stop):
            break
        if np.any(stop):
            keep = ~stop
            active = active[keep]
            c_a = c_a[keep]
            s_a = s_a[keep]
            signs_a = signs_a[keep]
            phi_a = phi_a[keep]
            scale_a = scale_a[keep]
    return converged, iterations


def _newton_step(law: Any, c: np.ndarray, s_c: np.ndarray, signs: np.ndarray, phi: np.ndarray,
                 eye: np.ndarray) -> np.ndarray:
    """Newton's update of ``phi`` (n, K) for ``phi = G(c - S_c phi)``: ``J^-1 (phi - G)`` with
    ``J = I + d(G(c - S_c phi))/dphi``.
    """
    k = eye.shape[0]
    shift = (s_c.reshape(s_c.shape[0], 4 * k, k) @ phi[..., None]).reshape(c.shape)
    g, g_c = law.reduced(c - shift, signs)
    jac = eye + (g_c[:, :, None, :] @ s_c)[:, :, 0, :]
    with np.errstate(all="ignore"):
        return np.linalg.solve(jac, (phi - g)[..., None])[..., 0]


def loop_gain(g_c: np.ndarray, s_c: np.ndarray, exact_gain: float = 0.5) -> np.ndarray:
    """Loop gain (n,) [-] per sample: the spectral radius of ``dG/dphi`` from ``g_c`` (n, K, 4) and
    ``s_c`` (n, K, 4, K), or an upper bound below ``exact_gain`` (at >= 1 only the verdict is asked);
    infinite where the Jacobian is not finite.
    """
    with np.errstate(all="ignore"):
        gain_matrix = np.nan_to_num((g_c[:, :, None, :] @ s_c)[:, :, 0, :], nan=np.inf, posinf=np.inf,
                                    neginf=-np.inf)
    finite = np.all(np.isfinite(gain_matrix), (-2, -1))
    gain = np.where(finite, np.max(np.sum(np.abs(gain_matrix), -1), -1), np.inf)
    exact = finite & (gain >= exact_gain)  # the spectral radius is at most any induced norm
    if exact_gain >= 1.0:  # only the verdict is asked for: a sharper bound may settle it
        gain[exact] = power_bound(gain_matrix[exact], gain[exact])
        exact &= gain >= exact_gain
    gain[exact] = np.max(np.abs(np.linalg.eigvals(gain_matrix[exact])), -1)
    return gain
