"""Monte Carlo (GUM Supplement 1) of the measured efficiency: the first-order budget's distributions
pushed through the filter and window integrals, a check on the linearisation.

The low-pass and the window integral are linear, so a draw's filtered noise enters each work only
through a few projections ``lowpass_adjoint(weights) @ noise`` (the nominal window and each sample a
shifted end can touch). They are Gaussian with covariance ``G @ G.T``, drawn from it directly; with
``exact_noise`` every noise sample is drawn instead (the numbers filtering each draw would use, in the
same order) and projected block by block, never filtered or held whole.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from rigdata.conditioning import Conditioned, lowpass_adjoint, window_weights
from rigdata.transducer import Transducer

__all__ = ["MAX_DRAWS", "CHUNK", "BLOCK", "PROGRESS_AFTER", "check_draws", "monte_carlo"]

MAX_DRAWS = 100_000
"""Most Monte Carlo draws of one measurement: its 95 % interval is settled long before."""
CHUNK = 200
"""Draws whose random numbers are drawn together (it fixes the order of the stream, so the draws of a
seed)."""
BLOCK = 2**22
"""Most noise samples held at once (8 bytes each): a chunk's noise is drawn in blocks of whole rows."""
PROGRESS_AFTER = 2.0
"""Seconds of drawing before a progress bar appears (on stderr, when it is a terminal)."""
_REACH = (-2, 4)
"""Samples around a window end, relative to the first at or after it, whose weights a shift of the end by
up to half a sample can change (the last one is the fixed anchor of the difference)."""


def check_draws(monte_carlo: object, seed: object) -> None:
    """ValueError unless ``monte_carlo`` is an integer in [0, MAX_DRAWS] and ``seed`` in [0, 2**63 - 1]."""
    for name, value, top in (("monte_carlo", monte_carlo, MAX_DRAWS), ("seed", seed, 2**63 - 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= top:
            raise ValueError(f"`{name}` must be an integer in [0, {top}], got {value!r:.40}")


@dataclass(frozen=True)
class _Ends:
    """Samples near the window ends (:attr:`index`) and how shifting the ends changes their weights."""

    t: np.ndarray
    window: tuple
    start: np.ndarray
    end: np.ndarray

    @classmethod
    def of(cls, c: Conditioned) -> _Ends:
        """The end samples of ``c``'s window."""
        spans = []
        for edge in c.window:
            first = int(np.searchsorted(c.t, edge))
            spans.append(np.arange(max(first + _REACH[0], 0), min(first + _REACH[1], c.t.size)))
        return cls(c.t, tuple(c.window), spans[0], spans[1])

    @property
    def index(self) -> np.ndarray:
        """Sample indices of both ends, shape (k,)."""
        return np.concatenate([self.start, self.end])

    def changes(self, shift: np.ndarray) -> np.ndarray:
        """Weight changes [s] at :attr:`index`, shape (m, k), for end shifts ``shift`` [s], shape (m, 2)."""
        t_a, t_b = self.window
        ta_loc = self.t[self.start]
        tb_loc = self.t[self.end]
        base_a = window_weights(ta_loc, t_a, ta_loc[-1])
        base_b = window_weights(tb_loc, tb_loc[0], t_b)
        out = np.empty((shift.shape[0], self.start.size + self.end.size))
        for i, (s_a, s_b) in enumerate(shift):
            out[i, :self.start.size] = window_weights(ta_loc, t_a + s_a, ta_loc[-1]) - base_a
            out[i, self.start.size:] = window_weights(tb_loc, tb_loc[0], t_b + s_b) - base_b
        return out


@dataclass(frozen=True)
class _Shaft:
    """One shaft's work as a linear function of its draw: integrals over the nominal window, their end
    terms, and the noise projections (rows: nominal window, then one per end sample).
    """

    torque: float
    speed: float
    ramp: float
    local: np.ndarray
    projections: np.ndarray

    @classmethod
    def of(cls, c: Conditioned, torque: np.ndarray, speed: np.ndarray, ramp: np.ndarray,
           ends: _Ends) -> _Shaft:
        """The terms of the work ``int torque * speed dt`` of one shaft of ``c``."""
        weights = window_weights(c.t, *c.window)
        order = int(c.settings.get("filter_order", 4))
        index = ends.index
        rows = [lowpass_adjoint(weights * speed, c.cutoff, 1.0 / c.dt, order)]
        for j in index:
            unit = np.zeros(c.t.size)
            unit[j] = 1.0
            rows.append(lowpass_adjoint(unit, c.cutoff, 1.0 / c.dt, order))
        local = np.stack([torque[index] * speed[index], speed[index], ramp[index] * speed[index]])
        return cls(float(weights @ (torque * speed)), float(weights @ speed), float(weights @ (ramp * speed)),
                   local, np.stack(rows))

    def work(self, changes: np.ndarray, offset: np.ndarray, drift: np.ndarray, noise: np.ndarray,
             sigma: float) -> np.ndarray:
        """Works [J], shape (m,), of draws with end ``changes`` (m, k), ``offset`` and ``drift`` [N m] (m,),
        ``noise`` projections (m, 1 + k), noise level ``sigma`` [N m].
        """
        at_ends = changes @ self.local.T
        filtered = noise[:, 0] + np.sum(changes * self.local[1] * noise[:, 1:], axis=1)
        return self.torque + at_ends[:, 0] + offset * (self.speed + at_ends[:, 1]) \
            + drift * (self.ramp + at_ends[:, 2]) + sigma * filtered


def _projected_noise(rng: np.random.Generator, m: int, projections: np.ndarray) -> np.ndarray:
    """``m`` rows of unit white noise drawn from ``rng`` (as one ``(m, n)`` draw would) times
    ``projections.T`` (n, p), at most :data:`BLOCK` samples held at once; shape (m, p).
    """
    n = projections.shape[1]
    rows = max(1, BLOCK // n)
    out = np.empty((m, projections.shape[0]))
    for start in range(0, m, rows):
        k = min(rows, m - start)
        out[start:start + k] = rng.standard_normal((k, n)) @ projections.T
    return out


def _gaussian_noise(rng: np.random.Generator, m: int, projections: np.ndarray) -> np.ndarray:
    """``m`` draws of ``projections @ z`` (shape (m, p)) for unit white noise ``z``, from their covariance."""
    values, vectors = np.linalg.eigh(projections @ projections.T)
    factor = vectors * np.sqrt(np.clip(values, 0.0, None))
    return rng.standard_normal((m, factor.shape[1])) @ factor.T


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
                samples: int, seed: int, exact_noise: bool = False) -> tuple[dict, dict]:
    """The measured efficiency drawn ``samples`` times through the filter and integrals.

    Per draw and transducer: constant offset (class, resolution), drift ramp, white noise ``sigma`` [N m]
    low-passed, a speed channel's gain; each window end shifted up to one sample. Returns ``summary``
    (``samples``, ``seed``, ``mean``, ``std``, ``interval_95`` [-]) and ``draws`` (``efficiency`` [-],
    ``offset_out`` [N m]).
    ``exact_noise``: draw every noise sample (the draws of filtering each record; about 10 ns a sample),
    else the noise's projections from their covariance (same distribution, other numbers). Memory:
    :data:`BLOCK` noise samples and a few copies of the record, whatever ``samples``. Progress
    on stderr when it is a terminal, after :data:`PROGRESS_AFTER`.
    """
    rng = np.random.default_rng(seed)
    ramp = (c.t - c.t[0]) / (c.t[-1] - c.t[0])
    ends = _Ends.of(c)
    shafts = {"in": _Shaft.of(c, c.torque_in, c.speed_in, ramp, ends),
              "out": _Shaft.of(c, c.torque_out, c.speed_out, ramp, ends)}
    noise = _projected_noise if exact_noise else _gaussian_noise
    values = np.empty(samples)
    offsets_out = np.empty(samples)
    with tqdm(total=samples, desc="Monte Carlo", unit="draw", file=sys.stderr, disable=None,
              delay=PROGRESS_AFTER, leave=False) as bar:
        for start in range(0, samples, CHUNK):
            m = min(CHUNK, samples - start)
            drawn = {}
            for shaft, tr in zip(("in", "out"), transducers, strict=True):
                offset = rng.uniform(-1, 1, m) * tr.accuracy_limit \
                    + rng.uniform(-0.5, 0.5, m) * tr.adc_step
                drift = rng.uniform(-1, 1, m) * tr.zero_drift
                drawn[shaft] = (offset, drift, noise(rng, m, shafts[shaft].projections))
            changes = ends.changes(rng.uniform(-0.5, 0.5, (m, 2)) * c.dt)
            works = {s: shafts[s].work(changes, *drawn[s], sigma[s]) for s in shafts}
            values[start:start + m] = works["out"] / works["in"] * _speed_gains(c, transducers, rng, m)
            offsets_out[start:start + m] = drawn["out"][0]
            bar.update(m)
    lo, hi = np.percentile(values, [2.5, 97.5])
    summary = {"samples": int(samples), "seed": int(seed), "mean": float(np.mean(values)),
               "std": float(np.std(values, ddof=1)), "interval_95": [float(lo), float(hi)]}
    return summary, {"efficiency": values, "offset_out": offsets_out}
