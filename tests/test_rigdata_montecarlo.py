"""The measurement's Monte Carlo: projected through the adjoint low-pass, it draws what filtering each
draw would (same seed, same numbers), holds a bounded block of noise, and its analytic noise matches
sampling.
"""

from __future__ import annotations

import io
import math
import tracemalloc

import numpy as np
import pytest

from rigdata import montecarlo, synthetic
from rigdata.conditioning import condition, lowpass, lowpass_adjoint, window_weights
from rigdata.efficiency import noise_level, transducer_pair
from rigdata.transducer import Transducer


@pytest.fixture(scope="module")
def case():
    record, _ = synthetic.record(synthetic.RigSettings(revolutions=2.5, rate=2000.0))
    c = condition(record, math.radians(15.0))
    sigma = {"in": noise_level(c.raw_torque_in, c.torque_in),
             "out": noise_level(c.raw_torque_out, c.torque_out)}
    return c, sigma


def _per_draw(c, transducers, sigma, samples, seed):
    """The Monte Carlo by definition: every draw's torques filtered and integrated over its own window."""
    rng = np.random.default_rng(seed)
    ramp = (c.t - c.t[0]) / (c.t[-1] - c.t[0])
    order = int(c.settings["filter_order"])
    values = np.empty(samples)
    for start in range(0, samples, montecarlo.CHUNK):
        m = min(montecarlo.CHUNK, samples - start)
        torques = []
        for torque, shaft, tr in ((c.torque_in, "in", transducers[0]), (c.torque_out, "out", transducers[1])):
            offset = rng.uniform(-1, 1, (m, 1)) * tr.accuracy_limit \
                + rng.uniform(-0.5, 0.5, (m, 1)) * tr.adc_step
            drift = rng.uniform(-1, 1, (m, 1)) * tr.zero_drift * ramp
            noise = lowpass(rng.standard_normal((m, c.t.size)) * sigma[shaft], c.cutoff, 1.0 / c.dt, order)
            torques.append(torque + offset + drift + noise)
        shift = rng.uniform(-0.5, 0.5, (m, 2)) * c.dt
        for i in range(m):
            w = window_weights(c.t, c.window[0] + shift[i, 0], c.window[1] + shift[i, 1])
            values[start + i] = (w @ (torques[1][i] * c.speed_out)) / (w @ (torques[0][i] * c.speed_in))
        for shaft, tr, power in (("in", transducers[0], -1.0), ("out", transducers[1], 1.0)):
            if c.speed_sources.get(shaft, {}).get("kind") == "channel":
                values[start:start + m] *= (1.0 + rng.uniform(-1, 1, m) * tr.speed_accuracy) ** power
    return values


@pytest.mark.parametrize(("n", "order", "cutoff"), [(200, 4, 30.0), (57, 3, 100.0), (40, 4, 600.0)])
def test_lowpass_adjoint_is_the_transpose_of_lowpass(n, order, cutoff):
    matrix = lowpass(np.eye(n), cutoff, 1000.0, order)  # row k: lowpass of unit sample k, so L.T
    v = np.random.default_rng(1).standard_normal((3, n))
    np.testing.assert_allclose(lowpass_adjoint(v, cutoff, 1000.0, order), v @ matrix.T, atol=1e-13)


@pytest.mark.parametrize("speed_channel", ["pulses", "rpm"])
def test_exact_noise_equals_filtering_every_draw(speed_channel):
    settings = synthetic.RigSettings(revolutions=2.5, rate=2000.0, speed_channel=speed_channel)
    record, _ = synthetic.record(settings)
    c = condition(record, math.radians(15.0))
    sigma = {"in": noise_level(c.raw_torque_in, c.torque_in),
             "out": noise_level(c.raw_torque_out, c.torque_out)}
    pair = transducer_pair(None)
    _, draws = montecarlo.monte_carlo(c, pair, sigma, 450, 7, exact_noise=True)
    np.testing.assert_allclose(draws["efficiency"], _per_draw(c, pair, sigma, 450, 7), rtol=1e-12, atol=0)


def test_analytic_noise_matches_sampling(case):
    """Noise and window timing alone (no offsets or drift): the two spreads of 2000 draws agree within
    sampling (each std known to about 1.6 %, their ratio to 2.2 %: 10 % is over four of those).
    """
    c, sigma = case
    quiet = (Transducer(accuracy_class=0.0, zero_drift=0.0, adc_bits=32),) * 2
    analytic, _ = montecarlo.monte_carlo(c, quiet, sigma, 2000, 3)
    sampled, _ = montecarlo.monte_carlo(c, quiet, sigma, 2000, 4, exact_noise=True)
    assert analytic["std"] == pytest.approx(sampled["std"], rel=0.10)
    assert analytic["mean"] == pytest.approx(sampled["mean"], abs=4 * sampled["std"] / math.sqrt(1000))


def test_noise_is_held_in_blocks_not_draws_times_samples(case, monkeypatch):
    c, sigma = case
    n = c.t.size
    monkeypatch.setattr(montecarlo, "BLOCK", 2 * n)
    tracemalloc.start()
    try:
        montecarlo.monte_carlo(c, transducer_pair(None), sigma, 400, 0, exact_noise=True)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 60 * n * 8  # a chunk of draws x samples would be 200 * n * 8 bytes


def test_progress_on_a_terminal_only(case, monkeypatch):
    c, sigma = case
    monkeypatch.setattr(montecarlo, "PROGRESS_AFTER", 0.0)
    for terminal in (True, False):
        err = io.StringIO()
        err.isatty = lambda terminal=terminal: terminal
        monkeypatch.setattr("sys.stderr", err)
        montecarlo.monte_carlo(c, transducer_pair(None), sigma, 400, 0)
        assert ("Monte Carlo" in err.getvalue()) is terminal
