"""The Exudyn side's friction law (pure functions, no Exudyn) against a hand calculation and
against the independent numpy law of the reference engine."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cardan_exudyn.model.friction_law import PairLaw, bdf2_weights, pair_loads, ramp_sign
from reference.physics.friction import pair_friction

SPIDER = PairLaw(cylindrical=True, f=0.42, d=0.005, lever=0.006)  # the paper's spider pairs


def test_hand_calculation_cylindrical():
    """|F| = 5 N, |M| = 0.05 N m on the spider pair: T = f d |M| / L + f d / 2 |F| and
    A = f (|F| + 2 |M| / L), opposing positive relative motion."""
    loads = pair_loads(SPIDER, 3.0, 4.0, 0.03, -0.04, omega_rel=10.0, slide_rel=1.0, band=1e-3)
    torque = 0.42 * 0.005 * 0.05 / 0.006 + 0.42 * 0.0025 * 5.0  # 0.0175 + 0.00525
    axial = 0.42 * (5.0 + 2.0 * 0.05 / 0.006)  # 9.1
    assert loads.torque == pytest.approx(-torque, rel=1e-14)
    assert loads.force == pytest.approx(-axial, rel=1e-14)
    assert loads.sliding_scale == pytest.approx(max(torque, 0.0025 * axial), rel=1e-14)


def test_revolute_has_no_axial_force():
    """A revolute pair resists rotation only, whatever the sliding speed passed in."""
    law = PairLaw(cylindrical=False, f=0.2, d=0.02, lever=0.01)
    loads = pair_loads(law, 10.0, 0.0, 0.0, 0.0, omega_rel=-5.0, slide_rel=3.0, band=0.0)
    assert loads.force == 0.0
    assert loads.torque == pytest.approx(0.2 * 0.01 * 10.0)  # opposes the negative rotation


@pytest.mark.parametrize("speed, band, expected", [
    (0.0, 0.0, 0.0), (2e-3, 0.0, 1.0), (-1e-9, 0.0, -1.0),
    (5e-4, 1e-3, 0.5), (-2e-3, 1e-3, -1.0), (1e-3, 1e-3, 1.0),
], ids=["zero-sharp", "positive-sharp", "tiny-negative-sharp", "inside-ramp", "below-ramp",
        "ramp-edge"])
def test_ramp_sign(speed, band, expected):
    """The regularised sign is the exact sign for band 0 and a clipped ramp otherwise."""
    assert ramp_sign(speed, band) == expected


finite = st.floats(-1e3, 1e3, allow_nan=False)


@given(fx=finite, fy=finite, mx=finite, my=finite, omega=st.floats(-100, 100), slide=st.floats(-1, 1),
       band=st.sampled_from([0.0, 1e-4, 1e-3]), slide_band=st.sampled_from([None, 0.0, 1e-6, 1e-2]),
       cylindrical=st.booleans())
def test_agrees_with_the_reference_law(fx, fy, mx, my, omega, slide, band, slide_band, cylindrical):
    """Same torque and force as reference.physics.friction.pair_friction, written independently, with
    the rotation's and the sliding's own bands."""
    from reference.scene.joint import Pair

    pair = Pair(friction_coefficient=0.42, journal_diameter=0.005, moment_lever=0.006)
    law = PairLaw(cylindrical, 0.42, 0.005, 0.006)
    ours = pair_loads(law, fx, fy, mx, my, omega, slide, band, slide_band)
    torque, force = pair_friction(pair, "cylindrical" if cylindrical else "revolute",
                                  fx, fy, mx, my, omega, slide, band, slide_band)
    scale = 1.0 + abs(float(torque)) + abs(float(force))
    assert ours.torque == pytest.approx(float(torque), rel=1e-12, abs=1e-12 * scale)
    assert ours.force == pytest.approx(float(force), rel=1e-12, abs=1e-12 * scale)


def test_sliding_has_its_own_band():
    """The axial force takes its sign ramp from ``slide_band`` (the torque from ``band``); without
    it, from ``band``."""
    own = pair_loads(SPIDER, 5.0, 0.0, 0.0, 0.0, omega_rel=0.2, slide_rel=1e-4, band=1e-3,
                     slide_band=4e-4)
    shared = pair_loads(SPIDER, 5.0, 0.0, 0.0, 0.0, omega_rel=0.2, slide_rel=1e-4, band=1e-3)
    axial = 0.42 * 5.0
    assert own.force == pytest.approx(-0.25 * axial, rel=1e-14)
    assert shared.force == pytest.approx(-0.1 * axial, rel=1e-14)
    # surface speed 0.2 * 0.0025 = 5e-4 m/s: half way up the 1e-3 m/s ramp in both
    assert own.torque == shared.torque == pytest.approx(-0.5 * 0.42 * 0.0025 * 5.0, rel=1e-14)


@pytest.mark.parametrize("h1, h2", [(0.1, 0.1), (0.1, 0.2), (0.03, 0.01)], ids=["uniform", "shrink", "grow"])
def test_bdf2_is_exact_for_quadratics(h1, h2):
    """(w1 (c_n - c_n-1) - w2 (c_n-1 - c_n-2)) / h1 is the derivative of a quadratic at t_n."""
    def c(t):
        return 2.0 + 3.0 * t - 1.5 * t * t

    t_n = 1.0
    t1, t2 = t_n - h1, t_n - h1 - h2
    w1, w2 = bdf2_weights(h1, h2)
    derivative = (w1 * (c(t_n) - c(t1)) - w2 * (c(t1) - c(t2))) / h1
    assert derivative == pytest.approx(3.0 - 3.0 * t_n, abs=1e-12)
    # and element-wise on arrays, as the post-processing uses it
    w1a, w2a = bdf2_weights(np.array([h1, h1]), np.array([h2, h2]))
    assert np.allclose(w1a, w1) and np.allclose(w2a, w2)


def test_law_is_odd_in_the_motion():
    """Reversing the relative motion reverses the friction, same magnitude (Coulomb)."""
    a = pair_loads(SPIDER, 1.0, 2.0, 0.01, 0.02, 7.0, 0.3, 1e-3)
    b = pair_loads(SPIDER, 1.0, 2.0, 0.01, 0.02, -7.0, -0.3, 1e-3)
    assert (a.torque, a.force) == (-b.torque, -b.force)
    assert math.copysign(1.0, a.torque) == -1.0
