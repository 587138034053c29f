"""Measured efficiency and its standard uncertainty.

``eta = W_out / W_in`` with ``W = int T omega dt`` over whole input revolutions (kinetic energy
returns, so also 1 - lost work / input work); instantaneous ``P_out / P_in``. Uncertainty by the GUM
(first order, uncorrelated): accuracy class, resolution, zero drift (ramp), noise, window-end timing.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from rigdata import montecarlo
from rigdata.conditioning import Conditioned, lowpass, window_weights
from rigdata.record import RigDataError
from rigdata.transducer import Transducer

__all__ = ["SQRT3", "SQRT12", "noise_level", "Measured", "transducer_pair", "filtered_noise_factor",
           "instantaneous_efficiency", "uncertainty_budget", "measured_efficiency"]

SQRT3 = math.sqrt(3.0)
"""A rectangular distribution of half width ``a`` has standard deviation ``a / SQRT3``."""
SQRT12 = math.sqrt(12.0)
"""A rectangular distribution of full width ``a`` has standard deviation ``a / SQRT12``."""


def noise_level(raw: np.ndarray, filtered: np.ndarray) -> float:
    """Noise standard deviation: robust (MAD) spread of ``raw - filtered``, in the signals' unit."""
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
        Per input quantity: ``quantity``, ``standard_uncertainty``, ``unit``, ``sensitivity``,
        ``contribution`` [-].
    monte_carlo : dict
        ``samples``, ``seed``, ``std``, ``mean``, ``interval_95``; empty without Monte Carlo.
    summary : dict
        JSON-ready numbers: works, means, noise levels, window.
    draws : dict of str to ndarray
        Monte Carlo draws, else empty.
    band : callable or None
        Computes :attr:`instantaneous` on first read.
    """

    efficiency: float
    u: float
    budget: list
    monte_carlo: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)
    draws: dict = field(default_factory=dict, repr=False)
    band: Callable[[], dict] | None = field(default=None, repr=False, compare=False)

    @functools.cached_property
    def instantaneous(self) -> dict:
        """``t`` [s], ``efficiency`` ``P_out / P_in`` [-] and its ``u`` [-], shape (n,); empty without
        :attr:`band`.
        """
        return self.band() if self.band is not None else {}

    def as_dict(self) -> dict:
        """JSON summary: ``measured_efficiency`` and ``_u``, summary numbers, budget, Monte Carlo."""
        return {"measured_efficiency": self.efficiency, "measured_efficiency_u": self.u,
                **self.summary, "uncertainty_budget": self.budget, "monte_carlo": self.monte_carlo}


def filtered_noise_factor(c: Conditioned, order: int, seed: int = 0) -> float:
    """Standard deviation [-] unit white noise keeps after ``c``'s low-pass (Butterworth ``order``, noise
    ``seed``).
    """
    noise = np.random.default_rng(seed).standard_normal(c.t.size)
    return float(np.std(lowpass(noise, c.cutoff, 1.0 / c.dt, order)))


def instantaneous_efficiency(c: Conditioned, transducers: tuple[Transducer, Transducer], sigma: dict,
                             ramp: np.ndarray) -> dict:
    """``t`` [s], ``efficiency`` ``P_out / P_in`` [-] and its ``u`` [-] at every sample of ``c``.

    Torque variance: class and resolution, drift up to the instant (``ramp`` 0..1), noise ``sigma``
    [N m] as the low-pass leaves it; speeds exact.
    """
    order = int(c.settings.get("filter_order", 4))
    factor = filtered_noise_factor(c, order)
    with np.errstate(divide="ignore", invalid="ignore"):
        p_in = c.torque_in * c.speed_in
        p_out = c.torque_out * c.speed_out
        eta = p_out / p_in
        rel = np.zeros_like(eta)
        for (torque, shaft), tr in zip(((c.torque_in, "in"), (c.torque_out, "out")), transducers,
                                       strict=True):
            u_t2 = (tr.accuracy_limit / SQRT3) ** 2 + (tr.adc_step / SQRT12) ** 2 \
                + (tr.zero_drift * ramp / SQRT3) ** 2 + (factor * sigma[shaft]) ** 2
            rel = rel + u_t2 / torque ** 2
        u = np.abs(eta) * np.sqrt(rel)
    return {"t": c.t, "efficiency": eta, "u": u}


def transducer_pair(transducers: tuple[Transducer, Transducer] | Transducer | None
                    ) -> tuple[Transducer, Transducer]:
    """Input and output transducers from one, a pair or None (default :class:`Transducer`)."""
    transducers = transducers or Transducer()
    tin, tout = transducers if isinstance(transducers, tuple) else (transducers, transducers)
    if not (isinstance(tin, Transducer) and isinstance(tout, Transducer)):
        raise TypeError(f"`transducers` must be a Transducer or a pair of them, got {transducers!r:.80}")
    return tin, tout


def uncertainty_budget(c: Conditioned, transducers: tuple[Transducer, Transducer], eta: float,
                       w_in: float, sigma: dict, ramp: np.ndarray) -> list[dict]:
    """GUM budget rows of efficiency ``eta`` [-] from input work ``w_in`` [J], noise ``sigma`` [N m] and
    drift ``ramp``: ``quantity``, ``standard_uncertainty``, ``unit``, ``sensitivity``, ``contribution``
    [-].
    """
    tin, tout = transducers
    t_a, t_b = c.window
    weights = window_weights(c.t, t_a, t_b)
    angle_in = float(weights @ c.speed_in)
    angle_out = float(weights @ c.speed_out)
    p_in = c.torque_in * c.speed_in
    p_out = c.torque_out * c.speed_out
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
    # a speed channel's gain scales that shaft's power: d eta / d gain = +-eta (pulse counts: no gain)
    for shaft, tr, sign in (("in", tin, -1.0), ("out", tout, 1.0)):
        if c.speed_sources.get(shaft, {}).get("kind") == "channel":
            rows.append((f"speed gain, {shaft}put speed", tr.speed_accuracy / SQRT3, "-", sign * eta))
    return [{"quantity": q, "standard_uncertainty": u, "unit": unit, "sensitivity": s,
             "contribution": abs(s) * u} for q, u, unit, s in rows]


def _summary(c: Conditioned, transducers: tuple[Transducer, Transducer], w_in: float, w_out: float,
             sigma: dict) -> dict:
    """JSON-ready numbers: window, works [J], mean speeds [rad/s] and torques [N m], noise [N m], relative
    uncertainties, transducers.
    """
    tin, tout = transducers
    t_a, t_b = c.window
    weights = window_weights(c.t, t_a, t_b)
    angle_in = float(weights @ c.speed_in)
    angle_out = float(weights @ c.speed_out)
    duration = t_b - t_a
    return {
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


def measured_efficiency(c: Conditioned, transducers: tuple[Transducer, Transducer] | Transducer | None = None,
                        monte_carlo: int = 0, seed: int = 0) -> Measured:
    """Measured mean efficiency over ``c``'s window with its uncertainty (``monte_carlo`` draws, 0: GUM only).

    RigDataError when the input work over the window is not positive.
    """
    montecarlo.check_draws(monte_carlo, seed)
    pair = transducer_pair(transducers)
    t_a, t_b = c.window
    weights = window_weights(c.t, t_a, t_b)
    w_in = float(weights @ (c.torque_in * c.speed_in))
    w_out = float(weights @ (c.torque_out * c.speed_out))
    if not w_in > 0:
        raise RigDataError(f"the input work over the window is {w_in:.3g} J (not positive): the "
                           "input torque or speed has the wrong sign or the joint is driven backwards",
                           channel="torque_in")
    eta = w_out / w_in
    ramp = (c.t - c.t[0]) / (c.t[-1] - c.t[0])
    sigma = {"in": noise_level(c.raw_torque_in, c.torque_in),
             "out": noise_level(c.raw_torque_out, c.torque_out)}
    budget = uncertainty_budget(c, pair, eta, w_in, sigma, ramp)
    u = math.sqrt(sum(b["contribution"] ** 2 for b in budget))
    mc, draws = montecarlo.monte_carlo(c, pair, sigma, monte_carlo, seed) if monte_carlo else ({}, {})
    return Measured(eta, u, budget, mc, _summary(c, pair, w_in, w_out, sigma), draws,
                    band=functools.partial(instantaneous_efficiency, c, pair, sigma, ramp))
