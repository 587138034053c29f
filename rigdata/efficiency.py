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
the data) and the timing of the window's ends (one sample interval, rectangular). Monte Carlo
(:mod:`rigdata.montecarlo`) propagates the same distributions through the filter and the
integrals as a check on the linearisation; at 0.2 N m the accuracy class makes the relative
uncertainty of each torque about 30 %, where first order starts to be rough.
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
    """Standard deviation of the noise: robust (MAD) spread of ``raw - filtered``.

    Parameters
    ----------
    raw : ndarray, shape (n,)
        The signal as measured.
    filtered : ndarray, shape (n,)
        The same signal low-passed.

    Returns
    -------
    float
        In the signals' unit.
    """
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
        ``samples``, ``seed``, ``std``, ``mean``, ``interval_95`` when Monte Carlo ran, else empty.
    summary : dict
        JSON-ready numbers: works, means, noise levels, window.
    draws : dict of str to ndarray
        The Monte Carlo draws (:func:`rigdata.montecarlo.monte_carlo`), else empty.
    band : callable or None
        Computes :attr:`instantaneous` when it is first read (only Figure 10 reads it).
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
        """``t`` [s], ``efficiency`` (``P_out / P_in``) [-] and its standard uncertainty ``u`` [-],
        each of shape (n,); empty without a :attr:`band`."""
        return self.band() if self.band is not None else {}

    def as_dict(self) -> dict:
        """The JSON summary: ``measured_efficiency`` and its ``_u``, the summary's numbers, the
        budget, Monte Carlo."""
        return {"measured_efficiency": self.efficiency, "measured_efficiency_u": self.u,
                **self.summary, "uncertainty_budget": self.budget, "monte_carlo": self.monte_carlo}


def filtered_noise_factor(c: Conditioned, order: int, seed: int = 0) -> float:
    """Standard deviation of unit white noise after the conditioning low-pass [-].

    Parameters
    ----------
    c : Conditioned
        Its grid and cut-off are read.
    order : int
        Butterworth order of one pass.
    seed : int
        Seed of the noise drawn.

    Returns
    -------
    float
        The standard deviation the low-pass leaves of unit white noise [-].
    """
    noise = np.random.default_rng(seed).standard_normal(c.t.size)
    return float(np.std(lowpass(noise, c.cutoff, 1.0 / c.dt, order)))


def instantaneous_efficiency(c: Conditioned, transducers: tuple[Transducer, Transducer], sigma: dict,
                             ramp: np.ndarray) -> dict:
    """The instantaneous efficiency ``P_out / P_in`` and its standard uncertainty at every sample.

    Each torque's variance: accuracy class and resolution (rectangular), the zero drift up to
    that instant (rectangular ramp) and the noise as the low-pass leaves it; speeds are exact.

    Parameters
    ----------
    c : Conditioned
        The conditioned signals.
    transducers : (Transducer, Transducer)
        Input and output transducers.
    sigma : dict
        Noise level of each torque (``"in"``, ``"out"``) before the low-pass [N m].
    ramp : ndarray, shape (n,)
        The drift's ramp, 0 at the first sample and 1 at the last [-].

    Returns
    -------
    dict of str to ndarray, shape (n,)
        ``t`` [s], ``efficiency`` [-], ``u`` [-].
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
    """Input and output transducers from one, a pair or None (the default :class:`Transducer`)."""
    transducers = transducers or Transducer()
    tin, tout = transducers if isinstance(transducers, tuple) else (transducers, transducers)
    if not (isinstance(tin, Transducer) and isinstance(tout, Transducer)):
        raise TypeError(f"`transducers` must be a Transducer or a pair of them, got {transducers!r:.80}")
    return tin, tout


def uncertainty_budget(c: Conditioned, transducers: tuple[Transducer, Transducer], eta: float,
                       w_in: float, sigma: dict, ramp: np.ndarray) -> list[dict]:
    """The GUM budget of the measured efficiency: one row per input quantity.

    Parameters
    ----------
    c : Conditioned
        The conditioned signals and window.
    transducers : (Transducer, Transducer)
        Input and output transducers.
    eta : float
        The measured efficiency [-].
    w_in : float
        Input work over the window [J].
    sigma : dict
        Noise level of each torque (``"in"``, ``"out"``) [N m].
    ramp : ndarray, shape (n,)
        The drift's ramp, 0 at the first sample and 1 at the last [-].

    Returns
    -------
    list of dict
        ``quantity``, ``standard_uncertainty`` in ``unit``, ``sensitivity`` [-/unit] and
        ``contribution`` [-] (|sensitivity| x uncertainty).
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
    return [{"quantity": q, "standard_uncertainty": u, "unit": unit, "sensitivity": s,
             "contribution": abs(s) * u} for q, u, unit, s in rows]


def _summary(c: Conditioned, transducers: tuple[Transducer, Transducer], w_in: float, w_out: float,
             sigma: dict) -> dict:
    """The JSON-ready numbers of a measurement: window, works [J], mean speeds [rad/s] and torques
    [N m], noise levels [N m], each torque's relative uncertainty from class and drift [-], the
    transducers."""
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
    """Measured mean efficiency over ``c``'s whole-revolution window, with its uncertainty.

    Parameters
    ----------
    c : Conditioned
        The conditioned signals and window.
    transducers : Transducer or (input, output) pair, optional
        Default: :class:`~rigdata.transducer.Transducer` for both.
    monte_carlo : int
        Monte Carlo draws (0: GUM only).
    seed : int
        Seed of the draws.

    Returns
    -------
    Measured
        The instantaneous efficiency and its band are computed when first read.

    Raises
    ------
    RigDataError
        Input work over the window not positive.
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
