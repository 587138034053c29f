"""Adaptive Gauss-Legendre quadrature on panels: the reference engine's work integrals.

:func:`adaptive_gauss` integrates a vector integrand over panels that break at every kink (the
reference engine puts the edges of the friction sign ramps and the knots of histories there, so
inside a panel the integrand is smooth and the rule converges exponentially);
:func:`quadrature_summary` is how a run reports it (``summary.extras["quadrature"]``). The batched
engine (:mod:`reference.engine.batch.quadrature`) uses the same panels, constants and report.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["GROSS_SCALE", "DENSE_WIDTH", "DENSE_NODES", "MAX_OPEN_PANELS", "ROUNDING_FLOOR",
           "initial_panels", "adaptive_gauss", "quadrature_summary"]


def initial_panels(edges: np.ndarray, max_width: float) -> tuple[np.ndarray, np.ndarray]:
    """Panels ``(a, b)`` covering consecutive segments ``edges``, none wider than ``max_width``:
    each segment cut into equal parts, ``np.linspace``'s cuts (vectorised: a history's samples
    may make 10^5 segments)."""
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
DENSE_WIDTH = 0.125
DENSE_NODES = 3
"""History knots alone making panels mostly below ``DENSE_WIDTH`` of the initial width: at most
``DENSE_NODES`` Gauss nodes each (smooth between knots, error O(h^7); 9 evaluations per knot, not 24)."""
MAX_OPEN_PANELS = 20_000
ROUNDING_FLOOR = 64 * np.finfo(float).eps
"""A panel whose whole and halves agree to this fraction of the integral's scale is closed
whatever its width (about 1.4e-14): a difference at the integral's rounding level is the rounding
of the integrand itself (a friction ramp a few hundred ulp of time wide, where the speed's last
digits decide the friction), which halving does not reduce; under the width-proportional rule
alone such a panel splits every round, both halves too, until :data:`MAX_OPEN_PANELS`."""


def adaptive_gauss(integrand: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray,
                   nodes: int, rtol: float, scale_key: int = 0,
                   max_rounds: int = 40, scale_floor: float = 0.0) -> tuple[np.ndarray, dict]:
    """Integrals of a vector integrand over the union of panels ``[a, b]``, adaptively.

    Every open panel is integrated with the ``nodes``-point Gauss-Legendre rule as a whole and
    as two halves; it is closed when the two agree within ``rtol * |I[scale_key]| * width /
    total width``, or within ``ROUNDING_FLOOR * |I[scale_key]|``, in every component (the halves'
    value is kept; their difference goes into the error estimate), otherwise it is split and its
    halves are the next round's panels, whose whole-panel values are already known. All open
    panels of a round are evaluated in one call; the integrand maps times (m,) to values (m, k).
    The scale is at least ``GROSS_SCALE`` times the integral of ``|I[scale_key]|`` and at least
    ``scale_floor`` (so that an integral that cancels or vanishes, e.g. the input work of a joint
    with no load and no loss, does not ask for rounding-level accuracy), and at most
    ``MAX_OPEN_PANELS`` panels stay open.

    Returns
    -------
    integral : ndarray, shape (k,)
    info : dict
        ``evaluations``, ``rounds``, ``panels`` (closed), ``error_estimate`` (sum of the closed
        panels' whole-versus-halves differences, per component; a conservative bound).
    """
    x, w = np.polynomial.legendre.leggauss(nodes)

    def gauss(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        half = 0.5 * (hi - lo)
        t = (0.5 * (lo + hi))[:, None] + half[:, None] * x
        f = integrand(t.ravel()).reshape(lo.size, nodes, -1)
        return np.einsum("mnk,n->mk", f, w) * half[:, None]

    total_width = float(np.sum(b - a))
    whole = gauss(a, b)
    evaluations = a.size * nodes
    gross = float(np.sum(np.abs(whole[:, scale_key])))
    scale = max(abs(float(np.sum(whole[:, scale_key]))), GROSS_SCALE * gross, scale_floor,
                np.finfo(float).tiny)
    result = np.zeros(whole.shape[1])
    error = np.zeros(whole.shape[1])
    closed = 0
    for rounds in range(1, max_rounds + 1):
        mid = 0.5 * (a + b)
        both = gauss(np.concatenate([a, mid]), np.concatenate([mid, b]))
        evaluations += 2 * a.size * nodes
        left = both[:a.size]
        right = both[a.size:]
        diff = np.abs(left + right - whole)
        allowed = scale * np.maximum(rtol * (b - a) / total_width, ROUNDING_FLOOR)
        # a non-finite panel (NaN from a locked or failed sample) cannot converge: close it and
        # let the NaN reach the result instead of splitting it every round (2^rounds panels)
        done = (np.all(diff <= allowed[:, None], -1) | (rounds == max_rounds)
                | (2 * a.size > MAX_OPEN_PANELS) | ~np.all(np.isfinite(left + right), -1))
        result += (left + right)[done].sum(0)
        error += diff[done].sum(0)
        closed += int(np.count_nonzero(done))
        keep = ~done
        # nothing open, or a NaN (locked sample) already decides the integral: refining the
        # steep panels next to a locked arc would only cost (19 s at 47 deg, 2000 rpm)
        if not np.any(keep) or not np.all(np.isfinite(result)):
            break
        a = np.concatenate([a[keep], mid[keep]])
        b = np.concatenate([mid[keep], b[keep]])
        whole = np.concatenate([left[keep], right[keep]])
    return result, {"evaluations": evaluations, "rounds": rounds, "panels": closed,
                    "error_estimate": error.tolist()}


def quadrature_summary(info: dict, nodes: int, rtol: float, sign_breakpoints: int, knots: int,
                       revolutions_integrated: int) -> dict:
    """``summary.extras["quadrature"]``: how the works were integrated (``info`` from
    :func:`adaptive_gauss`; its error estimates of the input and lost work [J], components 0 and 2
    of the reference engine's ``WORK_KEYS``)."""
    return {"method": "adaptive Gauss-Legendre panels", "nodes_per_panel": nodes, "rtol": rtol,
            "sign_breakpoints": sign_breakpoints, "knots": knots,
            "revolutions_integrated": revolutions_integrated,
            "evaluations": info["evaluations"], "rounds": info["rounds"], "panels": info["panels"],
            "input_work_error_estimate": info["error_estimate"][0],
            "loss_work_error_estimate": info["error_estimate"][2]}
