"""Monte Carlo (GUM Supplement 1) of the measured efficiency: the first-order budget's distributions
pushed through the filter and window integrals, a check on the linearisation.
"""

from __future__ import annotations

import numpy as np

from rigdata.conditioning import Conditioned, lowpass, window_weights
from rigdata.transducer import Transducer

__all__ = ["MAX_DRAWS", "CHUNK", "check_draws", "monte_carlo"]

MAX_DRAWS = 100_000
"""Most Monte Carlo draws of one measurement: its 95 % interval is settled long before (the
draws are held in memory, eight bytes each, and filtered in chunks of :data:`CHUNK`)."""
CHUNK = 200
"""Draws filtered together (one 2-D low-pass): memory ``CHUNK x samples`` floats per torque."""


def check_draws(monte_carlo: object, seed: object) -> None:
    """ValueError unless ``monte_carlo`` is an integer in [0, MAX_DRAWS] and ``seed`` in [0, 2**63 - 1]."""
    for name, value, top in (("monte_carlo", monte_carlo, MAX_DRAWS), ("seed", seed, 2**63 - 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= top:
            raise ValueError(f"`{name}` must be an integer in [0, {top}], got {value!r:.40}")


def _drawn_torques(c: Conditioned, transducers: tuple[Transducer, Transducer], sigma: dict,
                   rng: np.random.Generator, m: int, ramp: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """``m`` draws of both torques [N m], shape (m, n) each: offset (class and resolution), drift
    ramp and low-passed noise added to the conditioned torque; and the output offsets drawn [N m]."""
    order = int(c.settings.get("filter_order", 4))
    torques = []
    offsets_out = None
    for torque, shaft, tr in ((c.torque_in, "in", transducers[0]), (c.torque_out, "out", transducers[1])):
        offset = rng.uniform(-1, 1, (m, 1)) * tr.accuracy_limit \
            + rng.uniform(-0.5, 0.5, (m, 1)) * tr.adc_step
        drift = rng.uniform(-1, 1, (m, 1)) * tr.zero_drift * ramp
        noise = lowpass(rng.standard_normal((m, c.t.size)) * sigma[shaft], c.cutoff, 1.0 / c.dt, order)
        torques.append(torque + offset + drift + noise)
        if shaft == "out":
            offsets_out = offset[:, 0]
    return torques, offsets_out


def _speed_gains(c: Conditioned, transducers: tuple[Transducer, Transducer], rng: np.random.Generator,
                 m: int) -> np.ndarray:
    """``m`` draws of ``(1 + g_out) / (1 + g_in)`` [-]: each speed channel's gain error, uniform within
    its limit; 1 for speeds from pulses or angles.
    """
    factor = np.ones(m)
    for shaft, tr, power in (("in", transducers[0], -1.0), ("out", transducers[1], 1.0)):
        if c.speed_sources.get(shaft, {}).get("kind") == "channel":
            factor *= (1.0 + rng.uniform(-1, 1, m) * tr.speed_accuracy) ** power
    return factor


def monte_carlo(c: Conditioned, transducers: tuple[Transducer, Transducer], sigma: dict,
                samples: int, seed: int) -> tuple[dict, dict]:
    """The measured efficiency drawn ``samples`` times through the filter and integrals.

    Per draw and transducer: constant offset (class, resolution), drift ramp, white noise ``sigma`` [N m]
    low-passed, a speed channel's gain; each window end shifted up to one sample. Returns ``summary``
    (``samples``, ``seed``, ``mean``, ``std``, ``interval_95`` [-]) and ``draws`` (``efficiency`` [-],
    ``offset_out`` [N m]).
    """
    rng = np.random.default_rng(seed)
    ramp = (c.t - c.t[0]) / (c.t[-1] - c.t[0])
    t_a, t_b = c.window
    values = np.empty(samples)
    offsets_out = np.empty(samples)
    for start in range(0, samples, CHUNK):
        m = min(CHUNK, samples - start)
        torques, drawn_offsets = _drawn_torques(c, transducers, sigma, rng, m, ramp)
        offsets_out[start:start + m] = drawn_offsets
        shift = rng.uniform(-0.5, 0.5, (m, 2)) * c.dt
        for i in range(m):
            w = window_weights(c.t, t_a + shift[i, 0], t_b + shift[i, 1])
            values[start + i] = (w @ (torques[1][i] * c.speed_out)) / (w @ (torques[0][i] * c.speed_in))
        values[start:start + m] *= _speed_gains(c, transducers, rng, m)
    lo, hi = np.percentile(values, [2.5, 97.5])
    summary = {"samples": int(samples), "seed": int(seed), "mean": float(np.mean(values)),
               "std": float(np.std(values, ddof=1)), "interval_95": [float(lo), float(hi)]}
    return summary, {"efficiency": values, "offset_out": offsets_out}
