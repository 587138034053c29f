"""Long runs (issue 8, ``cardan_exudyn.studies.longrun``): drift over thousands of revolutions with friction,
and energy conservation of the free-spinning frictionless joint.

The fast tests run the quick variant once (20 revolutions with friction for Rxyz and EP nodes;
20 free-spinning revolutions at 35 deg with a step ladder and a spectral-radius ladder; the
reference engine for 2 revolutions) and check real properties against the module's stated
tolerances (``longrun.TOLERANCES``, ``DISSIPATION_MODEL``: measured values with a margin and a
reason, see the module). The slow test runs the full study (2000 / 1000 revolutions).
"""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np
import pandas as pd
import pytest

from cardan_exudyn.studies import longrun
from cardan_exudyn.studies.longrun import (
    DEFAULT_RHO,
    DISSIPATION_MARGIN,
    TOLERANCES,
    LongRuns,
    algorithmic_damping,
    damping_coefficient,
    long_runs,
    markdown,
    model_loss,
    write_long,
)


@pytest.fixture(scope="module")
def quick() -> LongRuns:
    messages: list[str] = []
    result = long_runs(quick=True, progress=messages.append)
    assert messages, "progress was never called"
    return result


def _cases(result: LongRuns, engine: str = "exudyn") -> list[dict]:
    return [c for c in result.summary["energy"]["cases"] if c["engine"] == engine]


# ------------------------------------------------------------------ helpers, no simulation


def test_algorithmic_damping_is_third_order_and_vanishes_at_rho_one():
    """Generalized-alpha on x'' = -x: damping ratio c(rho) (Omega h)^3; trapezoidal at rho = 1."""
    for rho in (0.0, 0.3, 0.6, 0.9):
        ratio = algorithmic_damping(0.04, rho) / algorithmic_damping(0.02, rho)
        assert 7.8 < ratio < 8.2, (rho, ratio)
    assert abs(damping_coefficient(0.0) - 0.5) < 0.01  # rho = 0: xi = (Omega h)^3 / 2
    assert abs(algorithmic_damping(0.05, 1.0)) < 1e-12
    c = [damping_coefficient(r) for r in (0.0, 0.3, 0.6, 0.8, 0.9, 0.95)]
    assert all(a > b > 0 for a, b in pairwise(c))  # less damping as rho grows


def test_revolution_helpers():
    theta = np.linspace(0.0, 3 * 2 * math.pi, 31)  # 10 steps per revolution
    index = longrun.revolution_index(theta, 3)
    assert index[0] == 1 and index[10] == 1 and index[11] == 2 and index[-1] == 3
    values = np.arange(31.0)
    np.testing.assert_array_equal(longrun.per_revolution_max(values, index, 3), [10, 20, 30])
    np.testing.assert_allclose(longrun.at_revolutions(values, theta, 3), [0, 10, 20, 30])
    trend = longrun.linear_trend(np.arange(10), 2.0 + 0.5 * np.arange(10))
    assert abs(trend["slope"] - 0.5) < 1e-12 and trend["scatter"] < 1e-12


# ------------------------------------------------------------------ quick variant


def test_quick_variant_shape_and_settings(quick):
    s = quick.summary
    st = s["settings"]
    assert st["quick"] and st["drift_scene"] == "paper-10deg-2000rpm"
    assert st["drift_steps_per_revolution"] == 156  # the scene's automatic step at 10 deg
    assert st["spectral_radius"] == DEFAULT_RHO
    assert set(quick.drift["node_type"]) == set(longrun.QUICK_NODE_TYPES)
    assert len(quick.drift) == len(longrun.QUICK_NODE_TYPES) * longrun.QUICK_DRIFT_REVOLUTIONS
    for node_type, info in s["drift"].items():
        assert info["status"] == "ok", (node_type, info["reason"])
    assert {"case", "engine", "revolution", "relative_energy_deviation"} <= set(quick.energy.columns)
    assert all(c["status"] == "ok" for c in s["energy"]["cases"]), s["energy"]["cases"]
    failed = [c for c in s["checks"] if not c["pass"]]
    assert not failed, failed
    assert s["wall_time_s"]["total"] < 120  # about 15-30 s on 2 shared cores


def test_constraints_hold_and_do_not_drift(quick):
    """Positions stay on the constraint manifold to rounding; the O(h^2) velocity residuals of
    index-3 integration are periodic, the same in the last revolutions as in the first."""
    for node_type, info in quick.summary["drift"].items():
        m = info["measures"]
        assert m["position_violation_m"]["max_abs"] <= TOLERANCES["position_violation_m"][0]
        assert m["angle_violation_rad"]["max_abs"] <= TOLERANCES["angle_violation_rad"][0]
        for key in ("velocity_violation_m_s", "angular_velocity_violation_rad_s"):
            assert m[key]["growth_ratio"] <= TOLERANCES["velocity_growth_ratio"][0], (node_type, key)
            assert 0 < m[key]["last_window_max_abs"] < 0.1  # real, small residuals


def test_euler_parameter_norm_bounded(quick):
    rows = quick.drift[quick.drift["node_type"] == "EP"]
    assert rows["ep_norm_error"].notna().all()
    assert rows["ep_norm_error"].max() <= TOLERANCES["ep_norm_error"][0]
    assert rows["orthogonality_error"].max() <= TOLERANCES["orthogonality_error"][0]
    assert quick.drift.loc[quick.drift["node_type"] == "Rxyz", "ep_norm_error"].isna().all()


def test_efficiency_per_revolution_is_stationary(quick):
    """After the start-up revolution the per-revolution efficiency has no trend beyond its
    scatter, and its level is the paper scene's (about 0.4758 under the plain reading)."""
    for node_type, info in quick.summary["drift"].items():
        e = info["efficiency"]
        assert 0.47 < e["mean"] < 0.48
        assert e["scatter"] < 1e-6
        assert abs(e["last_minus_first"]) <= max(4 * e["difference_stderr"], 1e-9), (node_type, e)
        assert abs(e["trend_over_run"]) <= TOLERANCES["efficiency_drift"][0]
        assert abs(e["last_minus_first"]) <= TOLERANCES["efficiency_drift"][0]


def test_energy_drift_of_default_settings_below_tolerance(quick):
    (default,) = [c for c in _cases(quick) if c["dt_choice"] != "given"]
    assert default["spectral_radius"] == DEFAULT_RHO
    angle = default["shaft_angle_deg"]
    allowed = (DISSIPATION_MARGIN * model_loss(angle, DEFAULT_RHO, default["steps_per_revolution"])
               * default["completed_revolutions"])
    assert default["relative_drift"] < 0  # numerical damping loses energy, never gains
    assert abs(default["relative_drift"]) <= allowed, (default["relative_drift"], allowed)
    (reference,) = _cases(quick, "reference")
    per_rev = abs(reference["relative_drift"]) / reference["completed_revolutions"]
    assert per_rev <= TOLERANCES["reference_drift_per_revolution"][0]


def test_dissipation_scales_with_step_cubed(quick):
    """Energy lost per revolution at rho 0.6 against steps per revolution: order 3 (the
    damping ratio of generalized-alpha is c(rho) (Omega h)^3)."""
    ladder = sorted((c for c in _cases(quick) if c["spectral_radius"] == DEFAULT_RHO),
                    key=lambda c: c["steps_per_revolution"])
    assert len(ladder) >= 3
    for a, b in pairwise(ladder):
        order = (math.log(a["loss_per_revolution"] / b["loss_per_revolution"])
                 / math.log(b["steps_per_revolution"] / a["steps_per_revolution"]))
        assert abs(order - 3.0) <= TOLERANCES["dissipation_order"][0], (a["case"], b["case"], order)


def test_dissipation_follows_spectral_radius_theory(quick):
    at_200 = {c["spectral_radius"]: c["loss_per_revolution"] for c in _cases(quick)
              if c["nominal_steps_per_revolution"] == longrun.RHO_LADDER_STEPS}
    assert len(at_200) >= 3
    for rho, loss in at_200.items():
        measured = loss / at_200[DEFAULT_RHO]
        theory = damping_coefficient(rho) / damping_coefficient(DEFAULT_RHO)
        factor = max(measured / theory, theory / measured)
        assert factor <= TOLERANCES["rho_dependence_factor"][0], (rho, measured, theory)


def test_write_long_and_markdown(quick, tmp_path):
    names = write_long(quick, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)
    for name in names:
        assert (tmp_path / name).stat().st_size > 0
    back = pd.read_csv(tmp_path / "longrun_drift.csv")
    assert len(back) == len(quick.drift)
    text = markdown(quick)
    assert text.startswith("## Long runs")
    for needle in ("Drift", "Energy", "Tolerances and checks", "All checks passed: yes",
                   f"{quick.summary['drift']['EP']['efficiency']['mean']:.7f}"):
        assert needle in text, needle


# ------------------------------------------------------------------ full variant


@pytest.mark.slow
def test_full_long_runs():
    """2000 revolutions with friction for every node type, 1000 free-spinning revolutions at
    10 and 35 deg with the step and spectral-radius ladders, the reference for 20: every check
    within its tolerance, except the measured RotVecLG failure (pinned here: if a later Exudyn
    resolves rotations near the identity, this test says so and the module's account must change)."""
    result = long_runs(quick=False)
    s = result.summary
    assert s["settings"]["drift_revolutions"] == 2000
    assert set(s["drift"]) == {"Rxyz", "EP", "RotVecLG"}
    for node_type in ("Rxyz", "EP"):
        info = s["drift"][node_type]
        assert info["status"] == "ok" and info["completed_revolutions"] == 2000, info
    failed = [c for c in s["checks"] if not c["pass"] and c["subject"] != "RotVecLG"]
    assert not failed, failed

    # RotVecLG: stops near revolution 268 (measured 267.99, with and without friction)
    rv = s["drift"]["RotVecLG"]
    assert rv["status"] == "integration_failure" and 200 <= rv["completed_revolutions"] <= 400, rv
    rows = result.drift[result.drift["node_type"] == "RotVecLG"]
    assert rows["position_violation_m"].max() <= TOLERANCES["position_violation_m"][0]
    # the axis misalignment before the failure is the input angle's rounding drift, which the
    # identity step cannot follow (module docstring)
    late = rows.tail(50)
    worst = late["angle_violation_rad"].max()
    assert abs(worst / late["input_angle_error_rad"].abs().max() - 1.0) < 0.1  # measured 1.0000
    assert worst > TOLERANCES["angle_violation_rad"][0]  # measured 1.3e-9 rad
    assert any(f.startswith("RotVecLG") for f in s["findings"])

    # energy: every case up to rho 0.95 runs 1000 revolutions; rho 0.99 fails early
    for c in s["energy"]["cases"]:
        if c["engine"] == "exudyn" and c["spectral_radius"] >= 0.99:
            assert c["status"] != "ok" and c["completed_revolutions"] < 50, c
        else:
            assert c["status"] == "ok", c
