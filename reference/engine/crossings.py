"""Where sampled speeds cross the edges of friction's sign ramps: brackets for a root finder.

Both reference engines (one scene, :func:`reference.engine.breakpoints.sign_breakpoints`; many,
:func:`reference.engine.batch.quadrature.sign_breakpoints`) sample each ramp speed on a uniform grid of
:data:`SCAN_PER_REVOLUTION` points per input revolution and refine every bracket to rounding.

A sign change between two samples brackets one crossing. Two crossings between the same samples
(a speed that dips across an edge and back, e.g. a pair that barely reverses) show no sign change;
they show as a sampled extremum on the near side of the edge. :func:`grazing_candidates` fits a
parabola through each such extremum and its two neighbours; where the parabola's vertex lies
across the edge, the caller evaluates the speed at the vertex, and where the vertex really is
across, :func:`grazing_brackets` gives the two brackets on either side of it. A finer grid would
only make such misses rarer; the check makes a grazing crossing that the parabola resolves a found
one at any grid.
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
    """Cells of the grid where a column of ``values`` crosses its level.

    Parameters
    ----------
    grid : ndarray, shape (m,)
        Sample instants [s].
    values : ndarray, shape (m, K)
        Sampled speeds [m/s].
    levels : ndarray, shape (K,)
        Each column's level [m/s].

    Returns
    -------
    list of tuple
        ``(t_a, t_b, f_a, f_b, column, level)`` per crossing, ``f = value - level``.
    """
    g = values - levels
    cell, col = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)
    return [(grid[i], grid[i + 1], g[i, j], g[i + 1, j], j, levels[j])
            for i, j in zip(cell, col, strict=True)]


def grazing_candidates(grid: np.ndarray, values: np.ndarray,
                       levels: np.ndarray) -> list[tuple[float, int, int]]:
    """Interior samples where a column has a sampled extremum on one side of its level and the
    parabola through it and its neighbours crosses the level.

    Parameters
    ----------
    grid : ndarray, shape (m,)
        Equispaced sample instants [s].
    values : ndarray, shape (m, K)
        Sampled speeds [m/s].
    levels : ndarray, shape (K,)
        Each column's level [m/s].

    Returns
    -------
    list of (float, int, int)
        ``(t_vertex, sample, column)``: the parabola's vertex [s], the extremum's row, its column.
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
    """The two brackets of each grazing candidate whose speed at the vertex is across the level.

    Parameters
    ----------
    grid, values, levels
        As for :func:`grazing_candidates`.
    candidates : list of (float, int, int)
        From :func:`grazing_candidates`.
    at_vertex : ndarray, shape (len(candidates),)
        Each candidate column's speed at its ``t_vertex`` [m/s].

    Returns
    -------
    list of tuple
        Brackets as :func:`sign_change_brackets`'s, two per candidate across its level; the
        other candidates are dropped.
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
    """Sorted instants, near duplicates merged.

    Parameters
    ----------
    instants : ndarray, shape (n,)
        Refined crossings [s].
    span : float
        The scanned span [s]; an instant within ``MERGE * span`` of the one before is dropped.

    Returns
    -------
    ndarray, shape (m,)
        The distinct instants [s], ascending.
    """
    t = np.unique(instants)
    if t.size < 2:
        return t
    return t[np.concatenate([[True], np.diff(t) > MERGE * span])]
