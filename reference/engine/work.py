"""Work integrals over the whole-revolution window by panel Gauss-Legendre quadrature, panels broken
at every kink of the integrand (friction ramp edges, :func:`reference.engine.breakpoints.sign_breakpoints`;
history knots), so the mean efficiency converges exponentially; a dense load history enters
through :class:`reference.engine.gauss.HistoryRule`'s weights.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from reference.engine.breakpoints import sign_breakpoints
from reference.engine.gauss import (
    DENSE_NODES,
    DENSE_WIDTH,
    GROSS_SCALE,
    HISTORY_SAMPLES_PER_PANEL,
    adaptive_gauss,
    initial_panels,
    quadrature_summary,
)
from reference.engine.motion import InputMotion
from reference.engine.options import ReferenceOptions
from reference.engine.table import columns_at
from reference.results.means import whole_revolution_window
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["WORK_KEYS", "time_at_angle", "window_times", "work_means", "work_quadrature"]


def time_at_angle(motion: InputMotion, theta: float, lo: float, hi: float) -> float:
    """The instant [s] the input ``motion`` passes ``theta`` [rad] in the bracket ``[lo, hi]`` [s], by
    Illinois regula falsi (the nearer end without a sign change). Why not ``scipy.optimize``: its
    import costs every ``mean_input`` scene about 0.3 s.
    """
    a = lo
    b = hi
    f_a = motion.angle(a) - theta
    f_b = motion.angle(b) - theta
    if f_a == 0.0 or f_b == 0.0 or f_a * f_b > 0:  # at an end within rounding
        return a if f_a == 0.0 else b
    for _ in range(100):
        c = b - f_b * (b - a) / (f_b - f_a)
        f_c = motion.angle(c) - theta
        a, f_a = (a, 0.5 * f_a) if (f_c > 0) == (f_b > 0) else (b, f_b)
        b = c
        f_b = f_c
        if f_b == 0.0 or abs(b - a) <= 1e-15 + 4 * np.finfo(float).eps * abs(b):
            break
    return b


WORK_KEYS = ("power_in", "power_out", "power_loss", "self_locking",
             *(f"power_loss_{p}" for p in PAIR_NAMES), *(f"power_loss_{p}_sliding" for p in PAIR_NAMES))
"""The columns :func:`work_quadrature` integrates over time, in this order."""


def window_times(motion: InputMotion, theta: np.ndarray, t: np.ndarray,
                  theta_0: float, theta_1: float) -> tuple[float, float]:
    """Instants ``(t_0, t_1)`` [s] the input ``motion`` passes the window's ends ``theta_0``,
    ``theta_1`` [rad], each solved between the table rows (``theta``, ``t``) that bracket it.
    """
    sign = 1.0 if theta[-1] >= theta[0] else -1.0

    def bracket(angle: float) -> tuple[float, float]:
        k = min(max(int(np.searchsorted(sign * theta, sign * angle)), 1), t.size - 1)
        return float(t[k - 1]), float(t[k])

    return (time_at_angle(motion, theta_0, *bracket(theta_0)),
            time_at_angle(motion, theta_1, *bracket(theta_1)))


def _integrate_powers(scene: Scene, motion: InputMotion, lo: np.ndarray, hi: np.ndarray,
                      ends: dict[str, np.ndarray], options: ReferenceOptions,
                      nodes: int | None = None, history: bool = False) -> tuple[np.ndarray, dict]:
    """:data:`WORK_KEYS` integrated over the panels ``[lo, hi]`` [s] (:func:`adaptive_gauss`, ``nodes``
    per panel, default ``options.gauss_nodes``); ``history``: load samples through :class:`HistoryRule`.
    """
    def integrand(times: np.ndarray, load: np.ndarray | None = None) -> np.ndarray:
        cols = columns_at(scene, motion, times, load)
        return np.stack([np.asarray(cols[k], float) for k in WORK_KEYS], -1)

    # work below a thousandth of the mechanical energy is at the scale's floor (zero input work)
    energy_scale = float(np.max(np.abs(ends["energy_kinetic"])) + np.max(np.abs(ends["energy_potential"])))
    load = scene.load.evaluator() if history else None
    with np.errstate(invalid="ignore"):
        return adaptive_gauss(integrand, lo, hi, nodes or options.gauss_nodes, options.quadrature_rtol,
                              scale_floor=GROSS_SCALE * energy_scale,
                              history=None if load is None else (load.time, load.value))


def work_means(work: dict[str, float], ends: dict[str, np.ndarray]) -> dict[str, Any]:
    """``input_work``, ``output_work``, ``loss_work``, ``loss_work_<pair>[_sliding]`` and
    ``energy_balance_residual`` [J] from the ``work`` integrals of :data:`WORK_KEYS` and the energies at
    the window's ``ends``.
    """
    out = {"input_work": work["power_in"], "output_work": work["power_out"],
           "loss_work": work["power_loss"]}
    for pair in PAIR_NAMES:
        out[f"loss_work_{pair}"] = work[f"power_loss_{pair}"]
        out[f"loss_work_{pair}_sliding"] = work[f"power_loss_{pair}_sliding"]
    energy = ends["energy_kinetic"] + ends["energy_potential"]
    out["energy_balance_residual"] = float(out["input_work"] - out["output_work"] - out["loss_work"]
                                           - (energy[1] - energy[0]))
    return out


def _panels(t_a: float, t_end: float, kinks: np.ndarray, knots: np.ndarray, width: float,
            gauss_nodes: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Initial panels ``(lo, hi)`` [s] over ``[t_a, t_end]`` at most ``width`` [s] wide, broken at
    the friction ramps' edges ``kinks`` and the histories' ``knots`` [s], and the nodes per panel
    (fewer where the knots alone make the panels dense: a densely sampled history)."""
    edges = np.unique(np.concatenate([[t_a, t_end], kinks, knots]))
    lo, hi = initial_panels(edges, width)
    k_lo, k_hi = initial_panels(np.unique(np.concatenate([[t_a, t_end], knots])), width)
    dense = knots.size and np.median(k_hi - k_lo) < DENSE_WIDTH * width
    return lo, hi, (min(gauss_nodes, DENSE_NODES) if dense else gauss_nodes)


def work_quadrature(scene: Scene, motion: InputMotion, table: dict[str, np.ndarray],
                    options: ReferenceOptions) -> dict:
    """The window's works [J] of ``scene`` driven by ``motion``, located by the ``table``'s ``t`` and
    ``theta_in``, with ``options``' panels, nodes and tolerance: :func:`work_means`' keys, ``quadrature``
    (how) and ``self_locking_nodes``; empty without a whole revolution.
    """
    theta = table["theta_in"]
    t = table["t"]
    theta_0, theta_1, n = whole_revolution_window(theta, scene.record.skip_revolutions)
    if n < 1:
        return {}
    t_a, t_b = window_times(motion, theta, t, theta_0, theta_1)
    period = (t_b - t_a) / n
    # at constant speed every revolution repeats the first exactly: integrate one, times n
    repeats = n if motion.periodic else 1
    t_end = t_a + period if motion.periodic else t_b
    kinks = sign_breakpoints(scene, motion, t_a, t_end)
    width = period / options.panels_per_revolution
    # a dense load history enters through its samples' weights (HistoryRule), not as edges
    samples = scene.load.knots[(scene.load.knots > t_a) & (scene.load.knots < t_end)]
    history = bool(samples.size > HISTORY_SAMPLES_PER_PANEL * (t_end - t_a) / width)
    knots = np.concatenate([motion.knots, [] if history else samples])  # the histories' knots
    knots = knots[(knots > t_a) & (knots < t_end)]
    lo, hi, nodes = _panels(t_a, t_end, kinks, knots, width, options.gauss_nodes)
    ends = columns_at(scene, motion, np.array([t_a, t_b]))
    values, info = _integrate_powers(scene, motion, lo, hi, ends, options, nodes, history)
    work = dict(zip(WORK_KEYS, (repeats * values).tolist(), strict=True))
    out = work_means(work, ends)
    out["quadrature"] = quadrature_summary(info, nodes, options.quadrature_rtol, int(kinks.size),
                                           int(knots.size), n // repeats, int(samples.size) if history else 0)
    # a locked node makes its panel's values NaN; the self_locking column integrates to > 0
    out["self_locking_nodes"] = bool(work["self_locking"] != 0 or not np.isfinite(out["input_work"]))
    return out
