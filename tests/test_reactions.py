"""Pair reactions of the Exudyn model against hand calculations; pins sign and frame conventions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import B_IN, B_OUT, M_IN, M_OUT, M_SPIDER, balanced_scene

from cardan_exudyn import run

G = 9.81
LOAD = 1.5


def hand_reactions(theta: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Statics of the balanced joint at shaft angle 0, as force and moment of body a on body b.

    At 0 deg and constant speed every body turns rigidly about x with centres of mass on the axis
    and principal axes aligned, so there are no inertial loads: each pair carries gravity and the
    transmitted torque only. Worked in the rotating body frames, where gravity is
    ``w = Rx(theta)^T g``; the spider hangs on the input pair in its z and on the output pair in its
    y; each shaft bearing sits at its shaft's centre of mass. frame_input's frame belongs to the
    ground, so its values are turned back by Rx(theta).
    """
    w_y, w_z = -G * np.sin(theta), -G * np.cos(theta)
    zero = np.zeros_like(theta)
    t = np.full_like(theta, LOAD)
    # canonical (rotating) components, then into each pair frame (columns x, y, z of the frame)
    f_fi = np.stack([zero, -M_IN * w_y, -(M_IN + M_SPIDER) * w_z], 1)
    m_fi = np.stack([zero, B_IN * M_SPIDER * w_z, zero], 1)
    c, s = np.cos(theta), np.sin(theta)

    def to_ground(v):  # Rx(theta) v
        return np.stack([v[:, 0], c * v[:, 1] - s * v[:, 2], s * v[:, 1] + c * v[:, 2]], 1)

    def frame_fi(v):  # pair frame [e_y, e_z, e_x]
        return v[:, [1, 2, 0]]

    return {
        "frame_input": (frame_fi(to_ground(f_fi)), frame_fi(to_ground(m_fi))),
        "input_spider": (np.stack([-M_SPIDER * w_z, zero, zero], 1),   # frame [e_z, e_x, e_y]
                         np.stack([zero, t, zero], 1)),
        "spider_output": (np.stack([zero, M_SPIDER * w_y, zero], 1),   # frame [e_x, e_y, e_z]
                          np.stack([t, zero, zero], 1)),
        "output_frame": (np.stack([(M_SPIDER + M_OUT) * w_y, M_OUT * w_z, zero], 1),  # [e_y, e_z, e_x]
                         np.stack([zero, -B_OUT * M_SPIDER * w_y, zero], 1)),
    }


@pytest.fixture(scope="module")
def static_run():
    return run(balanced_scene(0.0, rpm=60.0, load=LOAD, revolutions=1.0))


@pytest.mark.parametrize("pair", ["frame_input", "input_spider", "spider_output", "output_frame"])
def test_reactions_match_statics_at_zero_angle(static_run, pair):
    """Each pair's force and moment equal the hand calculation, sign and frame included."""
    table = static_run.table.iloc[1:]  # the initial row holds no reactions yet
    force, moment = hand_reactions(table["theta_in"].to_numpy())[pair]
    got_f = table[[f"{pair}_fx", f"{pair}_fy", f"{pair}_fz"]].to_numpy()
    got_m = table[[f"{pair}_mx", f"{pair}_my", f"{pair}_mz"]].to_numpy()
    # Exact statics (no discretisation error at 0 deg): only the Newton tolerance (1e-10
    # relative) and rounding remain; 1e-7 N / N m is far below the 0.5-9 N loads.
    np.testing.assert_allclose(got_f, force, rtol=0, atol=1e-7)
    np.testing.assert_allclose(got_m, moment, rtol=0, atol=1e-7)


def test_drive_torque_equals_load_at_zero_angle(static_run):
    """With no inertial loads the drive torque equals the resisting torque."""
    np.testing.assert_allclose(static_run.table["torque_in"].iloc[1:], LOAD, rtol=1e-9)


@pytest.mark.parametrize("beta_deg", [20.0, 45.0])
def test_quasi_static_torque_ratio(beta_deg):
    """At very low speed the drive torque is the load torque times the speed ratio (virtual work)."""
    scene = balanced_scene(beta_deg, rpm=0.01, load=LOAD, gravity=(0.0, 0.0, 0.0), accuracy=1e-5)
    table = run(scene).table.iloc[1:]
    expected = LOAD * table["omega_out"] / table["omega_in"]
    # inertial torque ~ J * omega^2 * (ratio variation) ~ 4e-3 * (1e-3)^2: negligible; the
    # remaining error is the O(h^2) discretisation of the speed ratio, <= accuracy (1e-5) * LOAD
    np.testing.assert_allclose(table["torque_in"], expected, rtol=0, atol=3e-5 * LOAD)


def test_secondary_moment_on_output_bearing():
    """The output bearing carries the Cardan secondary couple T tan(beta) at input angle 0 and 180."""
    beta = math.radians(30.0)
    table = run(balanced_scene(30.0, rpm=0.01, load=LOAD, gravity=(0, 0, 0))).table.iloc[1:]
    theta = np.mod(table["theta_in"].to_numpy(), np.pi)
    at_zero = np.minimum(theta, np.pi - theta) < 1e-9
    assert at_zero.sum() >= 1
    bending = np.hypot(table["output_frame_mx"], table["output_frame_my"]).to_numpy()[at_zero]
    # at input angle 0 the output yoke is normal to the shaft plane and the spider transmits a
    # moment normal to the output yoke: its component off the output axis is T tan(beta)... times
    # the speed ratio there (1/cos beta), i.e. T sin(beta)/cos^2(beta) * cos(beta) = T tan(beta)
    np.testing.assert_allclose(bending, LOAD * math.tan(beta), rtol=1e-4)
