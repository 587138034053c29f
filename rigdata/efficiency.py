"""Measured efficiency and its standard uncertainty.

Over whole input revolutions the measured mean efficiency is output work over input work,
``eta = W_out / W_in`` with ``W = int T omega dt`` of the conditioned signals (the rig measures
both powers; over whole revolutions of a periodic motion the kinetic energy returns to its
value, so this is also 1 - lost work / input work). The instantaneous one is ``P_out / P_in``.

The uncertainty follows the GUM's law of propagation (first order, uncorrelated inputs): each
transducer's accuracy-class error (a constant offset within +-class x full scale, rectangular),
the acquisition's resolution (half a step either way, rectangular: without noise to dither it,
rounding is a constant error, at 0.2 N m on a 16-bit card 0.8 % of the torque), its zero drift
(a linear ramp over the record, rectangular limit), its noise (white, its level estimated from
the data) and the timing of the window's ends (one sample interval,
rectangular). Monte Carlo (GUM Supplement 1) propagates the same distributions through the
filter and the integrals as a check on the linearisation; at 0.2 N m the accuracy class makes
the relative uncertainty of each torque about 30 %, where first order starts to be rough.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rigdata.conditioning import Conditioned, lowpass
from rigdata.record import RigDataError
from rigdata.transducer import Transducer

SQRT3 = math.sqrt(3.0)
SQRT12 = math.sqrt(12.0)


def window_weights(t: np.ndarray, t_a: float, t_b: float) -> np.ndarray:
    """Trapezoid weights [s] of ``int_{t_a}^{t_b} y dt`` for samples ``y`` on the grid ``t``.

    The ends are interpolated linearly between the samples that bracket them, so the weights
    are exact for piecewise-linear ``y`` and the integral moves continuously with ``t_a, t_b``.
    """
    grid = np.concatenate([[t_a], t[(t > t_a) & (t < t_b)], [t_b]])
    half = 0.5 * np.diff(grid)
    w_grid = np.zeros(grid.size)
    w_grid[:-1] += half
    w_grid[1:] += half
    # spread each node's weight onto the two samples it is interpolated from
    k = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    frac = (grid - t[k]) / (t[k + 1] - t[k])
    weights = np.zeros(t.size)
    np.add.at(weights, k, w_grid * (1.0 - frac))
    np.add.at(weights, k + 1, w_grid * frac)
    return weights


def noise_level(raw: np.ndarray, filtered: np.ndarray) -> float:
    """Standard deviation of the noise [same unit]: robust (MAD) spread of raw - filtered."""
    r = np.asarray(raw) - np.asarray(filtered)
    return float(1.4826 * np.median(np.abs(r - np.median(r))))


@dataclass(frozen=True)
class Measured:
    """Measured efficiency over whole input revolutions, with its uncertainty.

    Attributes
    ----------
    efficiency : float
        ``W_out / W_in`` [-].
    u : float
        Combined standard uncertainty (GUM, first order) [-].
    budget : list of dict
        Per input quantity: ``quantity``, ``standard_uncertainty`` with ``unit``,
        ``sensitivity`` [-/unit] and ``contribution`` [-] (sensitivity x uncertainty).
    monte_carlo : dict
        ``samples``, ``std``, ``mean``, ``interval_95`` when Monte Carlo ran, else empty.
    summary : dict
        JSON-ready numbers: works, means, noise levels, window.
    instantaneous : dict of str to ndarray
        ``t`` [s], ``efficiency`` (P_out / P_in) and its standard uncertainty ``u`` [-].
    """

    efficiency: float
    u: float
    budget: list
    monte_carlo: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)
    instantaneous: dict = field(default_factory=dict)
    draws: dict = field(default_factory=dict, repr=False)

    def as_dict(self) -> dict:
        """The JSON summary: ``measured_efficiency`` and its ``_u``, the budget, Monte Carlo."""
        return {"measured_efficiency": self.efficiency, "measured_efficiency_u": self.u,
                **self.summary, "uncertainty_budget": self.budget, "monte_carlo": self.monte_carlo}


def _works(c: Conditioned, t_a: float, t_b: float, torque_in, torque_out) -> tuple[float, float]:
    w = window_weights(c.t, t_a, t_b)
    return float(w @ (torque_in * c.speed_in)), float(w @ (torque_out * c.speed_out))


MAX_DRAWS = 100_000
"""Most Monte Carlo draws of one measurement: its 95 % interval is settled long before (the
draws are held in memory, eight bytes each, and filtered in chunks of 200)."""


def check_draws(monte_carlo: object, seed: object) -> None:
    """``ValueError`` naming the argument unless ``monte_carlo`` is an integer in [0,
    :data:`MAX_DRAWS`] and ``seed`` one in [0, 2**63 - 1]."""
    for name, value, top in (("monte_carlo", monte_carlo, MAX_DRAWS), ("seed", seed, 2**63 - 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= top:
            raise ValueError(f"`{name}` must be an integer in [0, {top}], got {value!r:.40}")


def filtered_noise_factor(c: Conditioned, order: int, seed: int = 0) -> float:
    """Standard deviation of unit white noise after the conditioning low-pass [-]."""
    noise = np.random.default_rng(seed).standard_normal(c.t.size)
    return float(np.std(lowpass(noise, c.cutoff, 1.0 / c.dt, order)))


def measured_efficiency(c: Conditioned, transducers: tuple[Transducer, Transducer] | Transducer | None = None,
                        monte_carlo: int = 0, seed: int = 0) -> Measured:
    """Measured mean efficiency over ``c``'s whole-revolution window, with its uncertainty.

    Parameters
    ----------
    c : Conditioned
    transducers : Transducer or (input, output) pair
    monte_carlo : int
        Monte Carlo draws (0: GUM only).
    seed : int
    """
    check_draws(monte_carlo, seed)
    transducers = transducers or Transducer()
    tin, tout = transducers if isinstance(transducers, tuple) else (transducers, transducers)
    if not (isinstance(tin, Transducer) and isinstance(tout, Transducer)):
        raise TypeError(f"`transducers` must be a Transducer or a pair of them, got {transducers!r:.80}")
    t_a, t_b = c.window
    weights = window_weights(c.t, t_a, t_b)
    w_in, w_out = _works(c, t_a, t_b, c.torque_in, c.torque_out)
    if not w_in > 0:
        raise RigDataError(f"the input work over the window is {w_in:.3g} J (not positive): the "
                           "input torque or speed has the wrong sign or the joint is driven backwards",
                           channel="torque_in")
    eta = w_out / w_in
    angle_in, angle_out = float(weights @ c.speed_in), float(weights @ c.speed_out)
    span = c.t[-1] - c.t[0]
    ramp = (c.t - c.t[0]) / span
    sigma = {"in": noise_level(c.raw_torque_in, c.torque_in),
             "out": noise_level(c.raw_torque_out, c.torque_out)}
    p_in, p_out = c.torque_in * c.speed_in, c.torque_out * c.speed_out
    p_a = np.interp(t_a, c.t, p_out) - eta * np.interp(t_a, c.t, p_in)
    p_b = np.interp(t_b, c.t, p_out) - eta * np.interp(t_b, c.t, p_in)
    rows = [
        ("accuracy class, input torque", tin.accuracy_limit / SQRT3, "N m", -eta * angle_in / w_in),
        ("accuracy class, output torque", tout.accuracy_limit / SQRT3, "N m", angle_out / w_in),
        ("resolution (acquisition step), input torque", tin.adc_step / SQRT12, "N m",
         -eta * angle_in / w_in),
        ("resolution (acquisition step), output torque", tout.adc_step / SQRT12, "N m",
         angle_out / w_in),
        ("zero drift, input torque", tin.zero_drift / SQRT3, "N m",
         -eta * float(weights @ (c.speed_in * ramp)) / w_in),
        ("zero drift, output torque", tout.zero_drift / SQRT3, "N m",
         float(weights @ (c.speed_out * ramp)) / w_in),
        ("noise, input torque", sigma["in"], "N m",
         -eta * math.sqrt(float(np.sum((weights * c.speed_in) ** 2))) / w_in),
        ("noise, output torque", sigma["out"], "N m",
         math.sqrt(float(np.sum((weights * c.speed_out) ** 2))) / w_in),
        ("window start (edge timing)", c.dt / SQRT12, "s", -p_a / w_in),
        ("window end (edge timing)", c.dt / SQRT12, "s", p_b / w_in),
    ]
    budget = [{"quantity": q, "standard_uncertainty": u, "unit": unit, "sensitivity": s,
               "contribution": abs(s) * u} for q, u, unit, s in rows]
    u = math.sqrt(sum(b["contribution"] ** 2 for b in budget))
    duration = t_b - t_a
    summary = {
        "revolutions": int(c.revolutions), "window_s": [t_a, t_b],
        "input_work": w_in, "output_work": w_out,
        "mean_speed_in": angle_in / duration, "mean_speed_out": angle_out / duration,
        "mean_torque_in": w_in / angle_in, "mean_torque_out": w_out / angle_out,
        "noise_torque_in": sigma["in"], "noise_torque_out": sigma["out"],
        "relative_u_torque_in": math.hypot(tin.accuracy_limit / SQRT3, tin.zero_drift / SQRT3)
        / abs(w_in / angle_in),
        "relative_u_torque_out": math.hypot(tout.accuracy_limit / SQRT3, tout.zero_drift / SQRT3)
        / abs(w_out / angle_out),
        "transducer_in": tin.as_dict(), "transducer_out": tout.as_dict(),
    }
    mc, draws = _monte_carlo(c, (tin, tout), sigma, monte_carlo, seed) if monte_carlo else ({}, {})
    return Measured(eta, u, budget, mc, summary, _instantaneous(c, (tin, tout), sigma, ramp), draws)


def _instantaneous(c: Conditioned, transducers, sigma: dict, ramp: np.ndarray) -> dict:
    order = int(c.settings.get("filter_order", 4))
    factor = filtered_noise_factor(c, order)
    with np.errstate(divide="ignore", invalid="ignore"):
        p_in, p_out = c.torque_in * c.speed_in, c.torque_out * c.speed_out
        eta = p_out / p_in
        rel = np.zeros_like(eta)
        for (torque, shaft), tr in zip(((c.torque_in, "in"), (c.torque_out, "out")), transducers,
                                       strict=True):
            u_t2 = (tr.accuracy_limit / SQRT3) ** 2 + (tr.adc_step / SQRT12) ** 2 \
                + (tr.zero_drift * ramp / SQRT3) ** 2 + (factor * sigma[shaft]) ** 2
            rel = rel + u_t2 / torque ** 2
        u = np.abs(eta) * np.sqrt(rel)
    return {"t": c.t, "efficiency": eta, "u": u}


def _monte_carlo(c: Conditioned, transducers, sigma: dict, samples: int, seed: int) -> tuple[dict, dict]:
    """The same input distributions drawn ``samples`` times through filter and integrals.

    Returns the summary and the draws (``efficiency``, and ``offset_out``: the output torque
    offsets drawn, for quantities correlated with them)."""
    rng = np.random.default_rng(seed)
    order = int(c.settings.get("filter_order", 4))
    ramp = (c.t - c.t[0]) / (c.t[-1] - c.t[0])
    t_a, t_b = c.window
    values, offsets_out = np.empty(samples), np.empty(samples)
    chunk = 200
    for start in range(0, samples, chunk):
        m = min(chunk, samples - start)
        torques = []
        for torque, shaft, tr in ((c.torque_in, "in", transducers[0]),
                                  (c.torque_out, "out", transducers[1])):
            offset = rng.uniform(-1, 1, (m, 1)) * tr.accuracy_limit \
                + rng.uniform(-0.5, 0.5, (m, 1)) * tr.adc_step
            drift = rng.uniform(-1, 1, (m, 1)) * tr.zero_drift * ramp
            noise = lowpass(rng.standard_normal((m, c.t.size)) * sigma[shaft], c.cutoff, 1.0 / c.dt, order)
            torques.append(torque + offset + drift + noise)
            if shaft == "out":
                offsets_out[start:start + m] = offset[:, 0]
        shift = rng.uniform(-0.5, 0.5, (m, 2)) * c.dt
        for i in range(m):
            w = window_weights(c.t, t_a + shift[i, 0], t_b + shift[i, 1])
            values[start + i] = (w @ (torques[1][i] * c.speed_out)) / (w @ (torques[0][i] * c.speed_in))
    lo, hi = np.percentile(values, [2.5, 97.5])
    return {"samples": int(samples), "seed": int(seed), "mean": float(np.mean(values)),
            "std": float(np.std(values, ddof=1)), "interval_95": [float(lo), float(hi)]}, \
        {"efficiency": values, "offset_out": offsets_out}
