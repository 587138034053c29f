"""The work quadrature of :func:`reference.engine.work.work_quadrature` for many scenes at once: each
keeps its own window, breakpoints, panels and rules; one :meth:`SceneStack.columns` pass evaluates
every scene's open panels per round. Works agree with the single engine to rounding (within the
quadrature tolerance where rounding moves a panel across the closing threshold).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from reference.engine.batch.model import SceneStack
from reference.engine.crossings import (
    SCAN_PER_REVOLUTION,
    distinct_instants,
    grazing_brackets,
    grazing_candidates,
    sign_change_brackets,
)
from reference.engine.gauss import GROSS_SCALE, MAX_OPEN_PANELS, initial_panels, quadrature_summary
from reference.engine.motion import InputMotion
from reference.engine.options import ReferenceOptions
from reference.engine.work import WORK_KEYS, window_times, work_means
from reference.results.means import whole_revolution_window
from reference.scene.scene import Scene

__all__ = ["adaptive_gauss", "sign_breakpoints", "work_quadratures"]


def _scan(stack: SceneStack, members: Sequence[int], grids: list[np.ndarray]) -> list[tuple]:
    """Brackets ``(member position, t_a, t_b, f_a, f_b, column, level)`` of every ramp-edge crossing on
    each member's grid (:mod:`reference.engine.crossings`).
    """
    owner = np.repeat(np.asarray(members, int), [g.size for g in grids])
    values = np.split(stack.ramp_speeds(owner, np.concatenate(grids)),
                      np.cumsum([g.size for g in grids])[:-1])
    found = []
    grazing = []
    for k, (m, grid, v) in enumerate(zip(members, grids, values, strict=True)):
        for levels in (-stack.ramp_bands[m], stack.ramp_bands[m]):
            found += [(k, *br) for br in sign_change_brackets(grid, v, levels)]
            grazing += [(k, levels, c) for c in grazing_candidates(grid, v, levels)]
    if grazing:  # every scene's vertices in one evaluation
        at = stack.ramp_speeds(np.array([members[k] for k, _, _ in grazing], int),
                               np.array([c[0] for _, _, c in grazing]))
        for row, (k, levels, c) in enumerate(grazing):
            pair = grazing_brackets(grids[k], values[k], levels, [c], at[row, c[2]:c[2] + 1])
            found += [(k, *br) for br in pair]
    return found


def sign_breakpoints(stack: SceneStack, members: Sequence[int], t_a: np.ndarray,
                     t_b: np.ndarray) -> list[np.ndarray]:
    """:func:`reference.engine.breakpoints.sign_breakpoints` of the ``members`` of ``stack`` in their
    windows ``[t_a, t_b]`` [s], brackets refined together: per member the sorted instants [s].
    """
    empty = [np.zeros(0) for _ in members]
    if not stack.slots:
        return empty
    grids = []
    for m, a, b in zip(members, t_a, t_b, strict=True):
        turned = abs(stack.speed[m] * b - stack.speed[m] * a)
        grids.append(np.linspace(a, b, max(64, int(SCAN_PER_REVOLUTION * turned / (2.0 * math.pi))) + 1))
    found = _scan(stack, members, grids)
    if not found:
        return empty
    k, a, b, f_a, f_b, j, level = (np.array(v) for v in zip(*found, strict=True))
    scene = np.asarray(members, int)[k]
    active = np.ones(len(members), bool)
    for _ in range(100):  # Illinois regula falsi; a scene stops when all its brackets have
        on = np.flatnonzero(active[k])
        c = b[on] - f_b[on] * (b[on] - a[on]) / (f_b[on] - f_a[on])
        f_c = stack.ramp_speeds(scene[on], c)[np.arange(on.size), j[on]] - level[on]
        same = np.sign(f_c) == np.sign(f_b[on])
        a[on] = np.where(same, a[on], b[on])
        f_a[on] = np.where(same, 0.5 * f_a[on], f_b[on])
        b[on] = c
        f_b[on] = f_c
        converged = (np.abs(b - a) <= 1e-15) | (f_b == 0.0)
        active &= np.bincount(k, (~converged).astype(float), len(members)) > 0
        if not np.any(active):
            break
    return [distinct_instants(b[k == i], t_b[i] - t_a[i]) for i in range(len(members))]


def _gauss(integrand: Callable, rules: dict, nodes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
           hi: np.ndarray) -> np.ndarray:
    """Each panel's Gauss-Legendre integral with its scene's rule, all in one integrand call."""
    half = 0.5 * (hi - lo)
    centre = 0.5 * (lo + hi)
    groups = [(np.flatnonzero(nodes[owner] == n), x, w) for n, (x, w) in rules.items()]
    times = [(centre[sel][:, None] + half[sel][:, None] * x).ravel() for sel, x, _ in groups]
    scenes = [np.repeat(owner[sel], x.size) for sel, x, _ in groups]
    f = integrand(np.concatenate(scenes), np.concatenate(times))
    out = np.empty((lo.size, f.shape[-1]))
    start = 0
    for sel, x, w in groups:
        part = f[start:start + sel.size * x.size].reshape(sel.size, x.size, -1)
        out[sel] = np.einsum("mnk,n->mk", part, w) * half[sel][:, None]
        start += sel.size * x.size
    return out


def adaptive_gauss(integrand: Callable, owner: np.ndarray, a: np.ndarray, b: np.ndarray,
                   nodes: np.ndarray, rtol: float, scale_floor: np.ndarray,
                   max_rounds: int = 40) -> tuple[np.ndarray, list[dict]]:
    """``(integrals (S, k), infos)``: :func:`reference.engine.gauss.adaptive_gauss` for S scenes, all open
    panels of a round in one call of ``integrand(scenes, times)``; the panels ``[a, b]`` [s] belong to
    scenes ``owner``; ``nodes`` and ``scale_floor`` per scene, ``rtol`` and ``max_rounds`` shared.
    """
    count = nodes.size
    rules = {int(n): np.polynomial.legendre.leggauss(int(n)) for n in np.unique(nodes)}
    evaluations = np.zeros(count)

    def evaluate(owner: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        evaluations[:] += np.bincount(owner, nodes[owner], count)
        return _gauss(integrand, rules, nodes, owner, lo, hi)

    whole = evaluate(owner, a, b)
    total_width = np.bincount(owner, b - a, count)
    gross = np.bincount(owner, np.abs(whole[:, 0]), count)
    scale = np.maximum.reduce([np.abs(np.bincount(owner, whole[:, 0], count)), GROSS_SCALE * gross,
                               scale_floor, np.full(count, np.finfo(float).tiny)])

    def allowed(owner: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return rtol * scale[owner] * (hi - lo) / total_width[owner]

    result, error, closed, rounds = _rounds(evaluate, allowed, owner, a, b, whole, count, max_rounds)
    return result, [{"evaluations": int(evaluations[s]), "rounds": int(rounds[s]), "panels": int(closed[s]),
                     "error_estimate": error[s].tolist()} for s in range(count)]


def _rounds(evaluate: Callable, allowed: Callable, owner: np.ndarray, a: np.ndarray, b: np.ndarray,
            whole: np.ndarray, count: int, max_rounds: int) -> tuple[np.ndarray, ...]:
    """:func:`adaptive_gauss`' rounds of halving from the panels ``[a, b]`` of scenes ``owner``
    and their ``whole`` values (P, k); ``evaluate(owner, lo, hi)`` integrates panels,
    ``allowed(owner, lo, hi)`` gives their tolerances. Returns per scene (``count`` of them) the
    integrals and error estimates (S, k), the panels closed and the rounds made (S,)."""
    result = np.zeros((count, whole.shape[1]))
    error = np.zeros((count, whole.shape[1]))
    closed = np.zeros(count, int)
    rounds = np.zeros(count, int)
    for r in range(1, max_rounds + 1):
        rounds[np.unique(owner)] = r
        mid = 0.5 * (a + b)
        both = evaluate(np.concatenate([owner, owner]), np.concatenate([a, mid]), np.concatenate([mid, b]))
        left = both[:a.size]
        right = both[a.size:]
        diff = np.abs(left + right - whole)
        open_ = np.bincount(owner, minlength=count)[owner]
        done = (np.all(diff <= allowed(owner, a, b)[:, None], -1) | (r == max_rounds)
                | (2 * open_ > MAX_OPEN_PANELS) | ~np.all(np.isfinite(left + right), -1))
        np.add.at(result, owner[done], (left + right)[done])
        np.add.at(error, owner[done], diff[done])
        closed += np.bincount(owner[done], minlength=count)
        keep = ~done & np.all(np.isfinite(result), -1)[owner]  # a NaN decides its scene's integral
        if not np.any(keep):
            break
        a = np.concatenate([a[keep], mid[keep]])
        b = np.concatenate([mid[keep], b[keep]])
        owner = np.concatenate([owner[keep], owner[keep]])
        whole = np.concatenate([left[keep], right[keep]])
    return result, error, closed, rounds


def _window(scene: Scene, motion: InputMotion,
            table: dict[str, np.ndarray]) -> tuple[float, float, int] | None:
    """Start and end of the window [s] and the whole revolutions in it (None: none)."""
    theta = table["theta_in"]
    t = table["t"]
    theta_0, theta_1, n = whole_revolution_window(theta, scene.record.skip_revolutions)
    if n < 1:
        return None
    t_a, t_b = window_times(motion, theta, t, theta_0, theta_1)
    return t_a, t_b, n


def work_quadratures(stack: SceneStack, members: Sequence[int], motions: Sequence[InputMotion],
                     tables: Sequence[dict[str, np.ndarray]], options: ReferenceOptions) -> list[dict]:
    """:func:`reference.engine.work.work_quadrature` of the ``members`` of ``stack`` with their
    ``motions``, ``tables`` and ``options`` (constant speed and load: one revolution integrated, times
    the revolutions); one dict per member.
    """
    windows = [_window(stack.scenes[m], mo, tab) for m, mo, tab in zip(members, motions, tables, strict=True)]
    live = [i for i, w in enumerate(windows) if w is not None]
    out: list[dict] = [{} for _ in members]
    if not live:
        return out
    ids = np.array([members[i] for i in live], int)
    t_a, t_b, n = (np.array([windows[i][k] for i in live]) for k in range(3))
    t_end = t_a + (t_b - t_a) / n
    kinks = sign_breakpoints(stack, ids, t_a, t_end)
    owner, lo, hi = _panels(t_a, t_end, kinks, (t_b - t_a) / n / options.panels_per_revolution)
    nodes = np.full(ids.size, options.gauss_nodes)  # no history knots at constant speed and load
    ends = stack.columns(np.repeat(ids, 2), np.column_stack([t_a, t_b]).ravel())
    energy = np.abs(ends["energy_kinetic"]).reshape(-1, 2).max(1) + np.abs(ends["energy_potential"]).reshape(
        -1, 2).max(1)

    def integrand(scene: np.ndarray, times: np.ndarray) -> np.ndarray:
        cols = stack.columns(ids[scene], times, energy=False)
        return np.stack([np.asarray(cols[k], float) for k in WORK_KEYS], -1)

    with np.errstate(invalid="ignore"):
        values, infos = adaptive_gauss(integrand, owner, lo, hi, nodes, options.quadrature_rtol,
                                       GROSS_SCALE * energy)
    for s, i in enumerate(live):
        pair_ends = {k: ends[k][2 * s:2 * s + 2] for k in ("energy_kinetic", "energy_potential")}
        out[i] = _works(n[s] * values[s], pair_ends, infos[s], int(nodes[s]), kinks[s].size, options)
    return out


def _panels(t_a: np.ndarray, t_end: np.ndarray, kinks: list[np.ndarray],
            width: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every scene's initial panels over ``[t_a, t_end]`` (S,) [s], broken at its ``kinks`` [s],
    at most ``width`` (S,) [s] wide: each panel's scene, and the panels' ends (P,)."""
    owner = []
    lo = []
    hi = []
    for s in range(t_a.size):
        a, b = initial_panels(np.unique(np.concatenate([[t_a[s], t_end[s]], kinks[s]])), width[s])
        owner.append(np.full(a.size, s))
        lo.append(a)
        hi.append(b)
    return np.concatenate(owner), np.concatenate(lo), np.concatenate(hi)


def _works(values: np.ndarray, ends: dict[str, np.ndarray], info: dict, nodes: int, kinks: int,
           options: ReferenceOptions) -> dict:
    """The dict :func:`reference.engine.work.work_quadrature` returns (one revolution integrated)."""
    work = dict(zip(WORK_KEYS, values.tolist(), strict=True))
    out = work_means(work, ends)
    out["quadrature"] = quadrature_summary(info, nodes, options.quadrature_rtol, kinks, 0, 1)
    out["self_locking_nodes"] = bool(work["self_locking"] != 0 or not np.isfinite(out["input_work"]))
    return out
