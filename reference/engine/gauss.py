"""Adaptive Gauss-Legendre quadrature on panels that break at every kink (friction ramp edges,
history knots), the reference engine's work integrals; a dense load history's samples enter through
:class:`HistoryRule`'s weights. :func:`quadrature_summary` is ``summary.extras["quadrature"]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

__all__ = ["GROSS_SCALE", "DENSE_WIDTH", "DENSE_NODES", "MAX_OPEN_PANELS", "ROUNDING_FLOOR",
           "LOAD_LEVELS", "HISTORY_SAMPLES_PER_PANEL", "GaussRule", "HistoryRule", "initial_panels",
           "adaptive_gauss", "quadrature_summary"]


def initial_panels(edges: np.ndarray, max_width: float) -> tuple[np.ndarray, np.ndarray]:
    """Panels ``(lo, hi)`` [s] covering the segments between the ascending ``edges`` [s] (repeated ones
    make none), none wider than ``max_width`` [s]; vectorised (a history may make 10^5 segments).
    """
    edges = np.asarray(edges, float)
    keep = edges[1:] > edges[:-1]
    a = edges[:-1][keep]
    b = edges[1:][keep]
    count = np.maximum(1, np.ceil((b - a) / max_width - 1e-9)).astype(int)
    owner = np.repeat(np.arange(a.size), count)
    k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    step = ((b - a) / count)[owner]
    lo = k * step + a[owner]
    hi = (k + 1) * step + a[owner]
    last = k + 1 == count[owner]
    hi[last] = b[owner[last]]
    return lo, hi


GROSS_SCALE = 1e-3
"""Least scale of an integral, as a fraction of the integral of its absolute value."""
DENSE_WIDTH = 0.125
DENSE_NODES = 3
"""History knots alone making panels mostly below ``DENSE_WIDTH`` of the initial width: at most
``DENSE_NODES`` Gauss nodes each (smooth between knots, error O(h^7)).
Measured: docs/engines.md#constants-of-the-reference-engine."""
MAX_OPEN_PANELS = 20_000
ROUNDING_FLOOR = 64 * np.finfo(float).eps
"""A panel whose whole and halves agree to this fraction of the integral's scale is closed
whatever its width (about 1.4e-14): a difference at the integral's rounding level is the rounding
of the integrand itself (e.g. a friction ramp a few hundred ulp of time wide), which halving does
not reduce."""


LOAD_LEVELS = 7
"""Load values per Gauss node at which :class:`HistoryRule` evaluates the integrand (odd: the
middle one is the panel's mid-range load, where a flat history is evaluated exactly).
Measured: docs/engines.md#constants-of-the-reference-engine."""
HISTORY_SAMPLES_PER_PANEL = 48
"""Load-history samples per panel of the initial width above which the reference engine takes
:class:`HistoryRule` rather than the samples as panel edges, the cheaper from there on.
Measured: docs/engines.md#constants-of-the-reference-engine."""


class GaussRule:
    """The ``nodes``-point Gauss-Legendre rule on panels, for an ``integrand`` of time (m,) [s] to (m, k).

    ``rule(lo, hi)`` gives the panels' integrals (P, k) and their own error bounds (zero: the
    comparison of whole and halves is the estimate); ``evaluations`` counts the instants evaluated,
    ``cut_panels`` the panels split otherwise than in halves.
    """

    def __init__(self, integrand: Callable[[np.ndarray], np.ndarray], nodes: int) -> None:
        self.integrand = integrand
        self.nodes = nodes
        self.x, self.w = np.polynomial.legendre.leggauss(nodes)
        self.evaluations = 0
        self.cut_panels = 0

    def __call__(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value = self._gauss(lo, hi, self.x, self.w, self.integrand)
        return value, np.zeros_like(value)

    def _gauss(self, lo: np.ndarray, hi: np.ndarray, x: np.ndarray, w: np.ndarray,
               integrand: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """The Gauss rule of nodes ``x``, weights ``w`` on the panels, ``integrand`` of time alone."""
        half = 0.5 * (hi - lo)
        t = (0.5 * (lo + hi))[:, None] + half[:, None] * x
        f = integrand(t.ravel()).reshape(lo.size, x.size, -1)
        self.evaluations += t.size
        return np.einsum("mnk,n->mk", f, w) * half[:, None]

    def children(self, lo: np.ndarray, hi: np.ndarray,
                 over: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(lo, hi, parent)``: the halves (2 P,) [s] of the panels ``[lo, hi]``, all left ones first, and
        each one's panel (``over`` is not needed here).
        """
        mid = 0.5 * (lo + hi)
        parent = np.arange(lo.size)
        return np.concatenate([lo, mid]), np.concatenate([mid, hi]), np.concatenate([parent, parent])


def _recurrence(x: np.ndarray, count: int, step: Callable) -> np.ndarray:
    """``count`` polynomials at ``x`` from a three-term recurrence ``p[a + 1] = step(a, x, p[a],
    p[a - 1])`` with ``p[0] = 1``, ``p[1] = x`` (Legendre, Chebyshev), stacked on a last axis."""
    out = np.empty(x.shape + (count,))
    out[..., 0] = 1.0
    if count > 1:
        out[..., 1] = x
    for a in range(1, count - 1):
        out[..., a + 1] = step(a, x, out[..., a], out[..., a - 1])
    return out


class _Pieces(NamedTuple):
    """Panels cut at the history's samples inside them, panel after panel (arrays per piece)."""

    owner: np.ndarray
    """The panel of each piece."""
    start: np.ndarray
    stop: np.ndarray
    """Each piece's ends [s]."""
    load_start: np.ndarray
    load_stop: np.ndarray
    """The history there (linear in between)."""
    first: np.ndarray
    """Each panel's first piece."""
    count: np.ndarray
    """Samples inside each panel (its pieces less one)."""


class HistoryRule(GaussRule):
    """Panels of ``integrand(t, L)`` with ``L`` the piecewise-linear history ``time`` [s], ``value``, at a
    cost that does not grow with the samples where ``f`` is smooth in the load.

    On a panel with samples inside, ``f`` is interpolated on the ``nodes`` Gauss nodes in time and by
    a Chebyshev series of degree :data:`LOAD_LEVELS` - 1 in the load over the panel's load range; the
    products with ``L(t)`` are integrated exactly piece by piece between samples, so samples cost
    arithmetic, not evaluations. The panel's bound is the size of the last two Chebyshev terms. A panel
    without samples inside uses the :data:`DENSE_NODES` rule (the ``nodes`` rule where flat). A panel
    whose bound fails is halved until it holds at most :attr:`cut_samples` samples, then cut at them.
    Why: with every sample a panel edge, a history costs 9 evaluations of the dynamics per sample.
    """

    def __init__(self, integrand: Callable[[np.ndarray, np.ndarray], np.ndarray], nodes: int,
                 time: np.ndarray, value: np.ndarray) -> None:
        super().__init__(integrand, nodes)
        self.time = np.asarray(time, float)
        self.value = np.asarray(value, float)
        m = LOAD_LEVELS
        self.u = np.cos(math.pi * (np.arange(m) + 0.5) / m)
        self.u[m // 2] = 0.0  # cos(pi / 2) in floats is 6e-17: a flat load is evaluated exactly
        # Chebyshev coefficients from the values at the levels u: c = dct @ values
        self.dct = (2.0 / m) * np.cos(math.pi * np.arange(m)[:, None] * (np.arange(m) + 0.5) / m)
        self.dct[0] *= 0.5
        # exact on a piece: time basis (degree nodes - 1) times T_j (degree m - 1)
        self.xq, self.wq = np.polynomial.legendre.leggauss((nodes + m) // 2)
        self.xd, self.wd = np.polynomial.legendre.leggauss(DENSE_NODES)
        a = np.arange(nodes)
        self.to_lagrange = (self.w[:, None] * np.polynomial.legendre.legvander(self.x, nodes - 1)
                            * (a + 0.5))  # l_i = sum_a w_i P_a(x_i) (a + 1/2) P_a
        self.cut_samples = 2 * nodes * m // (3 * DENSE_NODES) - 1  # 9 (S + 1) <= 2 nodes m

    def __call__(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        free = self._count(lo, hi) == 0
        flat = np.zeros_like(free)
        if not np.all(free):
            flat[~free] = self._range(self._pieces(lo[~free], hi[~free]))[1] == 0.0
        varied = ~free & ~flat
        groups = []
        for mask, x, w in ((free, self.xd, self.wd), (flat, self.x, self.w)):
            if np.any(mask):  # f(t, L(t)) itself: L is linear (no samples inside) or constant
                value = self._gauss(lo[mask], hi[mask], x, w, self._along)
                groups.append((mask, value, np.zeros_like(value)))
        if np.any(varied):
            groups.append((varied, *self._interpolated(lo[varied], hi[varied])))
        value = np.empty((lo.size, groups[0][1].shape[1]))
        bound = np.empty_like(value)
        for mask, part, part_bound in groups:
            value[mask] = part
            bound[mask] = part_bound
        return value, bound

    def _along(self, t: np.ndarray) -> np.ndarray:
        """``f(t, L(t))`` at the instants ``t`` [s]."""
        return self.integrand(t, np.interp(t, self.time, self.value))

    def children(self, lo: np.ndarray, hi: np.ndarray,
                 over: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`GaussRule.children`, except that a panel ``over`` its bound with at most
        :attr:`cut_samples` samples inside is cut at its samples rather than halved.
        """
        count = self._count(lo, hi)
        cut = over & (count > 0) & (count <= self.cut_samples)
        c_lo, c_hi, parent = super().children(lo, hi, over)
        if not np.any(cut):
            return c_lo, c_hi, parent
        self.cut_panels += int(np.count_nonzero(cut))
        halved = np.concatenate([~cut, ~cut])
        pieces = self._pieces(lo[cut], hi[cut])
        return (np.concatenate([c_lo[halved], pieces.start]), np.concatenate([c_hi[halved], pieces.stop]),
                np.concatenate([parent[halved], np.nonzero(cut)[0][pieces.owner]]))

    def _interpolated(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Integrals and bounds of panels with samples inside (the interpolation in time and load)."""
        pieces = self._pieces(lo, hi)
        centre, spread = self._range(pieces)
        half = 0.5 * (hi - lo)
        m = self.u.size
        times = np.repeat(((0.5 * (lo + hi))[:, None] + half[:, None] * self.x)[:, :, None], m, 2)
        levels = np.broadcast_to((centre[:, None] + spread[:, None] * self.u)[:, None, :], times.shape)
        f = self.integrand(times.ravel(), levels.ravel())
        self.evaluations += times.size
        coeff = np.einsum("pnjk,lj->pnlk", f.reshape(lo.size, self.nodes, m, -1), self.dct)
        weights = self._weights(pieces, lo, half, centre, spread)  # (P, n, m)
        value = np.einsum("pnlk,pnl->pk", coeff, weights)
        bound = np.einsum("pnk,n->pk", np.abs(coeff[:, :, -2:, :]).sum(2), self.w) * half[:, None]
        return value, bound

    @staticmethod
    def _range(pieces: _Pieces) -> tuple[np.ndarray, np.ndarray]:
        """The middle and half the width of the load's range on each panel (L is linear on a
        piece: its extremes are at the pieces' ends)."""
        ends = np.stack([pieces.load_start, pieces.load_stop], -1)
        low = np.minimum.reduceat(ends, pieces.first).min(-1)
        high = np.maximum.reduceat(ends, pieces.first).max(-1)
        return 0.5 * (low + high), 0.5 * (high - low)

    def _count(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Samples strictly inside each panel ``[lo, hi]`` [s]."""
        return np.maximum(np.searchsorted(self.time, hi, side="left")
                          - np.searchsorted(self.time, lo, side="right"), 0)

    def _pieces(self, lo: np.ndarray, hi: np.ndarray) -> _Pieces:
        """The panels ``[lo, hi]`` [s] cut at the samples inside them, panel after panel."""
        inside_from = np.searchsorted(self.time, lo, side="right")
        count = self._count(lo, hi)
        size = count + 1
        first = np.concatenate([[0], np.cumsum(size)[:-1]])
        owner = np.repeat(np.arange(lo.size), size)
        local = np.arange(int(size.sum())) - first[owner]  # the piece's place in its panel
        sample = inside_from[owner] + local  # the sample that ends the piece (unless it is the last)
        last = local == size[owner] - 1
        start = np.where(local == 0, lo[owner], self.time[np.clip(sample - 1, 0, self.time.size - 1)])
        stop = np.where(last, hi[owner], self.time[np.minimum(sample, self.time.size - 1)])
        return _Pieces(owner, start, stop, np.interp(start, self.time, self.value),
                       np.interp(stop, self.time, self.value), first, count)

    def _weights(self, pieces: _Pieces, lo: np.ndarray, half: np.ndarray,
                 centre: np.ndarray, spread: np.ndarray) -> np.ndarray:
        """``W[p, i, j]``: the integral over panel p of the i-th time basis function (Lagrange
        on the Gauss nodes) times ``T_j`` of the scaled load ``(L(t) - centre) / spread``."""
        owner, start, stop, load_a, load_b, first, _ = pieces
        s = 0.5 * (self.xq + 1.0)
        t = start[:, None] + (stop - start)[:, None] * s  # (S, q)
        load = load_a[:, None] + (load_b - load_a)[:, None] * s  # L is linear on a piece
        u = (load - centre[owner, None]) / np.where(spread > 0.0, spread, 1.0)[owner, None]
        tau = (t - (lo + half)[owner, None]) / half[owner, None]
        legendre = _recurrence(tau, self.nodes, lambda a, x, p, q: ((2 * a + 1) * x * p - a * q) / (a + 1))
        cheb = _recurrence(u, self.u.size, lambda a, x, p, q: 2.0 * x * p - q)
        per_piece = np.einsum("sq,sqa,sqj->saj", 0.5 * (stop - start)[:, None] * self.wq, legendre, cheb)
        # Lagrange basis on the Gauss nodes from the Legendre one (discrete orthogonality)
        return np.einsum("ia,paj->pij", self.to_lagrange, np.add.reduceat(per_piece, first, axis=0))


def adaptive_gauss(integrand: Callable[..., np.ndarray], a: np.ndarray, b: np.ndarray,
                   nodes: int, rtol: float, scale_key: int = 0,
                   max_rounds: int = 40, scale_floor: float = 0.0,
                   history: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, dict]:
    """``(integral (k,), info)``: the integrals of ``integrand`` (times (m,) [s], with ``history`` also
    loads, to (m, k)) over the panels ``[a, b]`` [s], each ``nodes``-point panel closed when whole and
    halves agree within ``rtol * scale * width / total width`` or ``ROUNDING_FLOOR * scale``, else halved
    (at most ``max_rounds``). The scale: at least ``GROSS_SCALE`` times the integral of
    ``|I[scale_key]|`` and ``scale_floor``. ``history`` (times [s], values): a piecewise-linear load
    through :class:`HistoryRule`. ``info``: ``evaluations``, ``rounds``, ``panels``, ``cut_panels``,
    ``error_estimate`` (per component, conservative).
    """
    rule = GaussRule(integrand, nodes) if history is None else HistoryRule(integrand, nodes, *history)
    total_width = float(np.sum(b - a))
    whole, whole_bound = rule(a, b)
    gross = float(np.sum(np.abs(whole[:, scale_key])))
    scale = max(abs(float(np.sum(whole[:, scale_key]))), GROSS_SCALE * gross, scale_floor,
                np.finfo(float).tiny)

    def allowed(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return scale * np.maximum(rtol * (hi - lo) / total_width, ROUNDING_FLOOR)

    result, error, closed, rounds = _rounds(rule, a, b, whole, whole_bound, allowed, max_rounds)
    return result, {"evaluations": rule.evaluations, "rounds": rounds, "panels": closed,
                    "cut_panels": rule.cut_panels, "error_estimate": error.tolist()}


def _rounds(rule: GaussRule, a: np.ndarray, b: np.ndarray, whole: np.ndarray, whole_bound: np.ndarray,
            allowed: Callable[[np.ndarray, np.ndarray], np.ndarray],
            max_rounds: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """:func:`adaptive_gauss`' rounds of halving from the panels ``[a, b]`` and their ``whole``
    values and bounds (P, k), ``allowed(lo, hi)`` each panel's tolerance (P,). Returns the
    integral and error estimate (k,), the panels closed and the rounds made."""
    result = np.zeros(whole.shape[1])
    error = np.zeros(whole.shape[1])
    closed = 0
    for rounds in range(1, max_rounds + 1):
        lo, hi, parent = rule.children(a, b, np.any(whole_bound > allowed(a, b)[:, None], -1))
        parts, bound = rule(lo, hi)
        both = np.zeros_like(whole)
        bounds = np.zeros_like(whole)
        np.add.at(both, parent, parts)  # two halves: left + right, as written out
        np.add.at(bounds, parent, bound)
        diff = np.abs(both - whole) + bounds
        # a non-finite panel (NaN from a locked or failed sample) cannot converge: closed, so
        # that the NaN reaches the result rather than the panel splitting every round
        done = (np.all(diff <= allowed(a, b)[:, None], -1) | (rounds == max_rounds)
                | (lo.size > MAX_OPEN_PANELS) | ~np.all(np.isfinite(both), -1))
        result += both[done].sum(0)
        error += diff[done].sum(0)
        closed += int(np.count_nonzero(done))
        # nothing open, or a NaN (locked sample) already decides the integral: refining the
        # steep panels next to a locked arc would only cost time
        if np.all(done) or not np.all(np.isfinite(result)):
            break
        keep = ~done[parent]
        a = lo[keep]
        b = hi[keep]
        whole = parts[keep]
        whole_bound = bound[keep]
    return result, error, closed, rounds


def quadrature_summary(info: dict, nodes: int, rtol: float, sign_breakpoints: int, knots: int,
                       revolutions_integrated: int, weighted_load_samples: int = 0) -> dict:
    """``summary.extras["quadrature"]``: how the works were integrated, from :func:`adaptive_gauss`'
    ``info`` (error estimates of the input and lost work [J]), ``nodes``, ``rtol``, the counts of
    friction ramp edges, history knots and weighted load samples, and the revolutions integrated.
    """
    return {"method": "adaptive Gauss-Legendre panels", "nodes_per_panel": nodes, "rtol": rtol,
            "sign_breakpoints": sign_breakpoints, "knots": knots,
            "weighted_load_samples": weighted_load_samples,
            "revolutions_integrated": revolutions_integrated,
            "evaluations": info["evaluations"], "rounds": info["rounds"], "panels": info["panels"],
            "input_work_error_estimate": info["error_estimate"][0],
            "loss_work_error_estimate": info["error_estimate"][2]}
