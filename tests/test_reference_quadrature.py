"""The window integral across friction's sign jumps (reference/results/quadrature.py) and the
reference engine's adaptive panels (reference/engine/gauss.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.engine.gauss import adaptive_gauss, initial_panels
from reference.engine.options import ReferenceOptions
from reference.engine.solve import run
from reference.paper.scenes import named_scene
from reference.results.means import whole_revolution_window, window_integral
from reference.results.quadrature import jump_breaks, segment_integrals
from reference.scene.mapping import replace


def _columns(t, w, y):
    return {"t": t, "omega_in": np.ones_like(t), "input_spider_omega_rel": w,
            "input_spider_friction_torque": np.sign(w), "y": y}


def test_a_jump_inside_a_step_is_integrated_exactly():
    t = np.linspace(0.0, 1.0, 11)
    t_star = 0.437  # 0.37 of the way through the fifth step
    w = t_star - t
    y = np.where(t < t_star, 2.0, -1.0)  # piecewise constant: exact on each side
    breaks = jump_breaks(_columns(t, w, y))
    assert len(breaks) == 1
    exact = 2.0 * t_star - (1.0 - t_star)
    assert segment_integrals(y, t, breaks).sum() == pytest.approx(exact, abs=1e-14)
    # the trapezoid puts the jump in the step's middle: off by (0.5 - 0.37) of a step times the jump
    assert segment_integrals(y, t).sum() - exact == pytest.approx(0.13 * 0.1 * 3.0)


@pytest.mark.parametrize("offset", [0.0, 0.1, 0.9, 1e-12])
def test_a_row_at_or_near_the_crossing_is_left_out(offset):
    """A row in the sign ramp holds neither side's value (here the ramp's middle, 0.5)."""
    t = np.linspace(0.0, 1.0, 11)
    t_star = 0.5 + 0.1 * offset
    w = t_star - t
    y = np.where(np.abs(w) < 1e-9 + 0.1 * min(offset, 1 - offset) * 0.5, 0.5,
                 np.where(t < t_star, 1.0, 0.0))
    breaks = jump_breaks(_columns(t, w, y))
    assert len(breaks) == 1
    a, b, ts = breaks[0]
    assert ts == pytest.approx(t_star)
    assert b - a == 2  # the row next to the crossing is skipped
    assert segment_integrals(y, t, breaks).sum() == pytest.approx(t_star, abs=1e-12)


def test_speeds_that_scatter_around_zero_give_no_breaks():
    """A straight joint's spider pairs do not turn: their speeds are the solver's residue."""
    t = np.linspace(0.0, 1.0, 101)
    w = 1e-9 * np.cos(40.0 * t)
    cols = _columns(t, w, np.ones_like(t))
    cols["input_spider_friction_torque"] = 1e-7 * np.sign(w)
    assert jump_breaks(cols) == []
    cols["input_spider_omega_rel"] = 1e5 * w  # the same shape as real motion: reversals
    assert len(jump_breaks(cols)) == 13


def test_pairs_without_friction_give_no_breaks():
    t = np.linspace(0.0, 1.0, 11)
    cols = _columns(t, 0.5 - t + 0.03, np.ones(11))
    cols["input_spider_friction_torque"] = np.zeros(11)
    assert jump_breaks(cols) == []


@pytest.mark.parametrize("steps", [200, 400])
def test_exact_rows_of_a_reversing_joint(steps):
    """On the reference engine's own (exact) rows of paper-literal-10deg, whose spider pairs
    reverse four times per revolution, the trapezoid's error in the mean efficiency is first
    order (1.1e-3, 5.3e-4 at 200, 400 steps per revolution); across the jumps it is 1.1e-4 and
    3.7e-5 (measured). The reference's own quadrature is the truth."""
    scene = named_scene("paper-literal-10deg")
    truth = run(replace(scene, **{"record.timeseries": False})).summary.mean_efficiency
    table = run(scene, ReferenceOptions(samples_per_revolution=steps)).table
    cols = {c: table[c].to_numpy() for c in table.columns}
    t, theta = cols["t"], cols["theta_in"]
    theta_0, theta_1, n = whole_revolution_window(theta, scene.record.skip_revolutions)
    assert n >= 1

    def efficiency(breaks):
        w_in = window_integral(cols["power_in"], t, theta, theta_0, theta_1, breaks)
        w_loss = window_integral(cols["power_loss"], t, theta, theta_0, theta_1, breaks)
        return 1.0 - w_loss / w_in

    trapezoid = abs(efficiency(()) - truth)
    jumps = abs(efficiency(jump_breaks(cols)) - truth)
    assert trapezoid > 0.2 * 2 * math.pi / steps * 0.01  # first order: the test has teeth
    assert jumps < 0.15 * trapezoid


def test_a_ramp_the_steps_partly_resolve_is_integrated_as_its_middle():
    """Friction on a linear sign ramp 3 steps wide, symmetric about the crossing: its rows are
    left out, and the jump at the middle integrates the ramp exactly (the trapezoid does not:
    the rows miss the ramp's corners)."""
    t = np.linspace(0.0, 1.0, 21)
    t_star, half = 0.523, 0.07
    w = t_star - t
    f = np.clip(w / half, -1.0, 1.0)
    cols = {"t": t, "omega_in": np.ones_like(t), "input_spider_omega_rel": w,
            "input_spider_friction_torque": f}
    (a, b, ts), = jump_breaks(cols)
    assert abs(f[a]) == 1.0 and abs(f[b]) == 1.0 and b - a > 2
    exact = t_star - (1.0 - t_star)  # the ramp's two halves cancel
    assert segment_integrals(f, t, [(a, b, ts)]).sum() == pytest.approx(exact, abs=1e-12)
    assert abs(segment_integrals(f, t).sum() - exact) > 1e-4


def test_rounding_noise_in_a_sliver_does_not_split_the_panels_forever():
    """Noise on a panel 1e-9 of the window wide: it closes at the rounding level, within the estimate."""
    # a friction ramp narrower than the speed's resolution, between its two edges (breakpoints):
    # its friction is the speed's last digits, which halving the panel does not smooth
    def integrand(t):
        sliver = (t >= 0.3) & (t <= 0.3 + 1e-9)
        return (1.0 + np.where(sliver, 1e-6 * np.sin(1e15 * t), 0.0))[:, None]

    lo, hi = initial_panels(np.array([0.0, 0.3, 0.3 + 1e-9, 1.0]), 0.125)
    value, info = adaptive_gauss(integrand, lo, hi, 8, 1e-9)
    assert info["evaluations"] < 1000
    assert abs(value[0] - 1.0) <= info["error_estimate"][0] + 1e-15


def _piecewise(integrand, time, value, lo, hi, nodes=8, cuts=()):
    """The integral of ``integrand(t, L(t))`` over [lo, hi] by ``nodes``-point Gauss between
    consecutive samples and ``cuts`` (L linear in between): the samples as panel edges."""
    edges = np.unique(np.concatenate([[lo, hi], time[(time > lo) & (time < hi)], cuts]))
    edges = edges[(edges >= lo) & (edges <= hi)]
    x, w = np.polynomial.legendre.leggauss(nodes)
    half = 0.5 * np.diff(edges)
    t = (edges[:-1] + half)[:, None] + half[:, None] * x
    f = integrand(t.ravel(), np.interp(t.ravel(), time, value)).reshape(t.shape + (-1,))
    return np.einsum("sqk,q,s->k", f, w, half)


def _noisy_load(n, mean):
    t = np.linspace(0.0, 2.0, n)
    return t, mean + 0.2 * np.sin(15.0 * t) + 0.01 * np.random.default_rng(2).standard_normal(n)


def test_load_history_rule_costs_the_same_at_any_number_of_samples():
    """f(t, L) of degree 4 in the load: 2000 or 20,000 samples, the same evaluations, exact."""
    def integrand(t, load):
        return np.stack([np.cos(3 * t) * load, np.exp(-t) * load ** 3 + t * load ** 4], -1)

    lo, hi = initial_panels(np.array([0.1, 1.9]), 0.2)
    evaluations = {}
    for n in (2000, 20_000):
        time, value = _noisy_load(n, 1.0)
        got, info = adaptive_gauss(integrand, lo, hi, 8, 1e-9, history=(time, value))
        np.testing.assert_allclose(got, _piecewise(integrand, time, value, 0.1, 1.9), rtol=1e-13, atol=0)
        evaluations[n] = info["evaluations"]
    assert evaluations[20_000] == evaluations[2000] < 2000


def test_load_history_rule_cuts_at_the_samples_where_the_load_is_not_smooth():
    """sqrt(L^2 + 1e-6) with L through zero under noise: cut at the samples, exact to the estimate."""
    def integrand(t, load):
        return np.sqrt(load ** 2 + 1e-6)[:, None] * (1.0 + t[:, None])

    time, value = _noisy_load(20_000, 0.0)
    lo, hi = initial_panels(np.array([0.1, 1.9]), 0.2)
    got, info = adaptive_gauss(integrand, lo, hi, 8, 1e-9, history=(time, value))
    crossing = np.nonzero(np.sign(value[:-1]) * np.sign(value[1:]) < 0)[0]
    zeros = time[crossing] - value[crossing] * np.diff(time)[crossing] / np.diff(value)[crossing]
    exact = _piecewise(integrand, time, value, 0.1, 1.9, nodes=16, cuts=zeros)
    assert info["cut_panels"] > 0
    assert abs(got[0] - exact[0]) <= info["error_estimate"][0] + 1e-14 * abs(exact[0])
