"""reference.engine.crossings and reference.engine.periodic: the breakpoint scan's brackets (sign changes and
grazing crossings between two samples) and the summary-only table built from its first period
(a reference package test: it calls the engine directly, as tests/test_architecture.py allows)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.engine.crossings import (
    distinct_instants,
    grazing_brackets,
    grazing_candidates,
    sign_change_brackets,
)
from reference.engine.periodic import period_rows, repeat_period
from reference.engine.solve import run
from reference.paper.scenes import named_scene, rig_scene
from reference.scene.mapping import replace


def _dip(t):
    """A speed that dips below zero for 0.2 of a cell around t = 0.503 (no sample inside)."""
    return (np.asarray(t) - 0.503) ** 2 - 1e-6


def test_sign_changes_are_bracketed():
    grid = np.linspace(0.0, 1.0, 11)
    values = np.column_stack([np.cos(2 * math.pi * grid), grid - 0.33])
    brackets = sign_change_brackets(grid, values, np.array([0.0, 0.0]))
    found = sorted((b[4], b[0], b[1]) for b in brackets)
    assert [(col, lo <= root <= hi) for (col, lo, hi), root in zip(found, (0.25, 0.75, 0.33), strict=True)] \
        == [(0, True), (0, True), (1, True)]


def test_a_grazing_crossing_between_two_samples_is_found():
    grid = np.linspace(0.0, 1.0, 11)  # samples 0.5 and 0.6 are both above zero
    values = _dip(grid)[:, None]
    levels = np.zeros(1)
    assert sign_change_brackets(grid, values, levels) == []
    candidates = grazing_candidates(grid, values, levels)
    assert len(candidates) == 1 and abs(candidates[0][0] - 0.503) < 1e-12  # a parabola is exact
    brackets = grazing_brackets(grid, values, levels, candidates, _dip([candidates[0][0]]))
    assert len(brackets) == 2
    for t_a, t_b, f_a, f_b, _, _ in brackets:
        assert f_a * f_b < 0
        assert _dip(t_a) * _dip(t_b) < 0  # each holds one of the two true roots
    roots = (0.503 - 1e-3, 0.503 + 1e-3)
    assert all(b[0] <= r <= b[1] for b, r in zip(sorted(brackets), roots, strict=True))


def test_a_grazing_candidate_that_stays_on_its_side_is_dropped():
    grid = np.linspace(0.0, 1.0, 11)
    values = _dip(grid)[:, None]
    candidates = grazing_candidates(grid, values, np.zeros(1))
    assert grazing_brackets(grid, values, np.zeros(1), candidates, np.array([1e-9])) == []


def test_no_candidates_without_an_extremum_near_the_level():
    grid = np.linspace(0.0, 1.0, 11)
    values = np.column_stack([np.cos(2 * math.pi * grid) + 3.0, grid])
    assert grazing_candidates(grid, values, np.zeros(2)) == []


def test_crossings_a_few_ulp_apart_are_one():
    t = np.array([0.3, 0.25011515372109666, 0.1, 0.2501151537210966, 0.25011515372109666])
    assert distinct_instants(t, 1.0).tolist() == [0.1, 0.2501151537210966, 0.3]
    assert distinct_instants(np.array([0.1, 0.1 + 1e-9]), 1.0).size == 2  # distinct crossings stay


def test_period_rows():
    t = np.linspace(0.0, 2.0, 721)
    assert period_rows(t, 2 * math.pi) == 360
    assert period_rows(t, -2 * math.pi) == 360
    assert period_rows(np.linspace(0.0, 2.0, 700), 2 * math.pi) is None  # rows off the angles
    assert period_rows(np.linspace(0.0, 0.5, 91), 2 * math.pi) is None  # less than a period


def test_repeat_period_advances_time_and_angles_only():
    t = np.linspace(0.0, 3.0, 31)
    first = {"t": t[:10], "theta_in": -2 * math.pi * t[:10], "torque_in": np.arange(10.0)}
    table = repeat_period(first, t, -2 * math.pi)
    assert np.array_equal(table["t"], t)
    assert np.allclose(table["theta_in"], -2 * math.pi * t, atol=1e-14)
    assert np.array_equal(table["torque_in"], np.arange(31.0) % 10)


@pytest.mark.parametrize("scene", [named_scene("paper-literal-35deg"),
                                   rig_scene(parameters="matched", errors=True)], ids=["ideal", "errors"])
def test_summary_only_run_repeats_the_first_period(scene):
    """A summary-only run (its table from the first period) gives the recorded run's summary."""
    recorded = run(scene).summary
    summary = run(replace(scene, **{"record.timeseries": False})).summary
    assert summary.status == recorded.status
    for key in ("mean_efficiency", "input_work", "loss_work", "mean_torque_in", "max_friction_loop_gain"):
        expected = getattr(recorded, key)
        assert expected is not None, key
        assert getattr(summary, key) == pytest.approx(expected, rel=1e-12, abs=1e-14), key
    assert summary.power_reversals == recorded.power_reversals
    assert summary.extras["self_locking_samples"] == recorded.extras["self_locking_samples"]


def test_summary_only_run_evaluates_one_period(monkeypatch):
    import reference.engine.table as engine

    sizes, columns_at = [], engine.columns_at
    monkeypatch.setattr(engine, "columns_at", lambda s, m, t: sizes.append(np.size(t)) or columns_at(s, m, t))
    scene = replace(named_scene("paper-literal-10deg"), **{"record.timeseries": False})
    assert scene.revolutions == 2
    run(scene)
    assert sizes[0] == 360  # the table: the first revolution of its 721 rows (then the quadrature)
