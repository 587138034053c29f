"""Work integrals over the whole-revolution window by panel Gauss-Legendre quadrature.

The mean values that matter (input, output and lost work, hence the mean efficiency) are not
taken from the time table but by Gauss-Legendre quadrature over the whole-revolution window, on
panels that break at every kink of the integrand: the edges of each friction sign ramp
(relative surface speed = +- the pair's band, :mod:`reference.physics.bands`;
:func:`reference.engine.breakpoints.sign_breakpoints`) and the knots of an angle or load history.
Inside a panel the integrand is smooth, so the quadrature converges exponentially; the mean
efficiency is stable to 1e-8 and better as the panels are refined (tested). A load history denser
than :data:`reference.engine.gauss.HISTORY_SAMPLES_PER_PANEL` samples a panel enters through its
samples' weights instead (:class:`reference.engine.gauss.HistoryRule`, the integrand interpolated
in time and in the load), so that its cost does not grow with the samples.
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
    """The instant at which the input passes an angle, by Illinois regula falsi.

    (Not ``scipy.optimize``: its import would cost every command that builds a ``mean_input``
    scene about 0.3 s.)

    Parameters
    ----------
    motion : InputMotion
        The input's motion.
    theta : float
        The angle [rad].
    lo, hi : float
        A bracket of the instant [s].

    Returns
    -------
    float
        The instant [s], to rounding; the nearer end when the bracket holds no sign change.
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
    """The instants at which the input passes the window's ends.

    Parameters
    ----------
    motion : InputMotion
        The input's motion.
    theta, t : ndarray, shape (n,)
        The time table's input angles [rad] and instants [s]; each end is solved between the
        rows that bracket it.
    theta_0, theta_1 : float
        The window's first and last input angle [rad].

    Returns
    -------
    t_0, t_1 : float
        The instants [s].
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
    """:data:`WORK_KEYS` integrated over the panels ``[lo, hi]`` [s] (:func:`adaptive_gauss`,
    ``nodes`` per panel, default ``options.gauss_nodes``); ``history``: the load history's
    samples enter through :class:`reference.engine.gauss.HistoryRule`, not as panel edges."""
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
    """Summary keys from the works over the window.

    Parameters
    ----------
    work : dict of str to float
        The integrals of :data:`WORK_KEYS` [J].
    ends : dict of str to ndarray, shape (2,)
        ``energy_kinetic`` and ``energy_potential`` [J] at the window's ends.

    Returns
    -------
    dict
        ``input_work``, ``output_work``, ``loss_work``, ``loss_work_<pair>``,
        ``loss_work_<pair>_sliding`` and ``energy_balance_residual`` [J]; the means derived from
        them are :func:`reference.results.means.mean_values`'.
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
    """Work integrals over the whole-revolution window by panel Gauss-Legendre quadrature.

    Parameters
    ----------
    scene : Scene
        The scene on the run's clock.
    motion : InputMotion
        The input's motion (:func:`reference.engine.motion.input_motion`).
    table : dict of str to ndarray
        The time table's ``t`` [s] and ``theta_in`` [rad] (they locate the window).
    options : ReferenceOptions
        Panels per revolution, nodes per panel and the quadrature's tolerance.

    Returns
    -------
    dict
        The summary keys ``input_work``, ``output_work``, ``loss_work`` [J], ``loss_work_<pair>``
        and its axial-friction part ``loss_work_<pair>_sliding`` [J] (zero in the ideal joint),
        ``energy_balance_residual`` (W_in - W_out - W_loss - change of mechanical energy [J], zero
        up to rounding for an exact solution), ``quadrature`` (how it was done) and
        ``self_locking_nodes`` (friction locks at some node); empty when there is no whole
        revolution.
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
