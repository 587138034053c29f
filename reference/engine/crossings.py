"""Where sampled speeds cross the edges of friction's sign ramps: brackets for a root finder.

Each ramp speed is sampled at :data:`SCAN_PER_REVOLUTION` points per input revolution. A sign
change brackets one crossing; two crossings between the same samples show as a sampled extremum
near the edge, and :func:`grazing_candidates` fits a parabola through it whose vertex the caller
evaluates; where it is really across, :func:`grazing_brackets` gives a bracket on either side.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SCAN_PER_REVOLUTION", "MERGE", "sign_change_brackets", "grazing_candidates", "grazing_brackets",
           "distinct_instants"]

SCAN_PER_REVOLUTION = 256
"""Samples per input revolution of the scan (at least 64 per scan)."""
MERGE = 1e-12
"""Refined crossings closer than this share of the scanned span are one (two slots with the same
crossing, e.g. the two spider pairs, converge to instants a few ulp apart)."""


def sign_change_brackets(grid: np.ndarray, values: np.ndarray, levels: np.ndarray) -> list[tuple]:
    """``(t_a, t_b, f_a, f_b, column, level)`` per cell of ``grid`` [s] where a column of ``values``
    (m, K) [m/s] crosses its ``levels`` (K,), ``f = value - level``.
    """
    g = values - levels
    cell, col = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)
    return [(grid[i], grid[i + 1], g[i, j], g[i + 1, j], j, levels[j])
            for i, j in zip(cell, col, strict=True)]


def grazing_candidates(grid: np.ndarray, values: np.ndarray,
                       levels: np.ndarray) -> list[tuple[float, int, int]]:
    """``(t_vertex, sample, column)`` of each interior sampled extremum on one side of its level whose
    parabola through its neighbours crosses it (``grid`` [s] equispaced, ``values`` (m, K), ``levels`` [m/s]).
    """
    g = values - levels
    if g.shape[0] < 3:
        return []
    left = g[:-2]
    mid = g[1:-1]
    right = g[2:]
    curvature = left - 2.0 * mid + right
    extremum = ((mid - left) * (right - mid) < 0) & (np.sign(left) == np.sign(mid)) & (
        np.sign(mid) == np.sign(right)) & (curvature != 0.0)
    i, j = np.nonzero(extremum)
    if i.size == 0:
        return []
    before = left[i, j]
    m = mid[i, j]
    after = right[i, j]
    c = curvature[i, j]
    vertex = m - (after - before) ** 2 / (8.0 * c)
    across = np.sign(vertex) != np.sign(m)
    offset = np.clip(-(after - before) / (2.0 * c), -1.0, 1.0)  # in cells from the middle sample
    step = grid[1] - grid[0]
    return [(grid[k + 1] + o * step, k + 1, col) for k, col, o in
            zip(i[across], j[across], offset[across], strict=True)]


def grazing_brackets(grid: np.ndarray, values: np.ndarray, levels: np.ndarray,
                     candidates: list[tuple[float, int, int]], at_vertex: np.ndarray) -> list[tuple]:
    """Two brackets (as :func:`sign_change_brackets`') per candidate whose speed ``at_vertex`` [m/s] is
    across its level; the other candidates are dropped.
    """
    out = []
    for (t_v, k, col), v in zip(candidates, at_vertex, strict=True):
        f_v = v - levels[col]
        f_k = values[k, col] - levels[col]
        if not np.sign(f_v) * np.sign(f_k) < 0:
            continue
        lo, hi = (k - 1, k) if t_v < grid[k] else (k, k + 1)
        f_lo = values[lo, col] - levels[col]
        f_hi = values[hi, col] - levels[col]
        out += [(grid[lo], t_v, f_lo, f_v, col, levels[col]), (t_v, grid[hi], f_v, f_hi, col, levels[col])]
    return out


def distinct_instants(instants: np.ndarray, span: float) -> np.ndarray:
    """Sorted ``instants`` [s], dropping one within ``MERGE * span`` [s] of the one before."""
    t = np.unique(instants)
    if t.size < 2:
        return t
    return t[np.concatenate([[True], np.diff(t) > MERGE * span])]
