"""The accuracy grid (``python tests/benchmarks accuracy``): the run's own estimate against the
reference at tight settings on cells off the paper's, and (slow) the whole grid's verdict."""

from __future__ import annotations

import pytest

from benchmarks.accuracy.grid import REFERENCE_TIGHT, grid_cells, run_cell, run_cell_limited
from benchmarks.accuracy.verdict import honesty

# small grid off the paper's: (angle deg, rpm, friction, errors, drive)
SMALL_GRID = [dict(angle_deg=25.0, rpm=500.0, friction=0.3, errors=False, drive="speed"),
              dict(angle_deg=0.0, rpm=3000.0, friction=0.4, errors=False, drive="speed"),
              dict(angle_deg=40.0, rpm=50.0, friction=0.1, errors=False, drive="speed"),
              dict(angle_deg=20.0, rpm=1500.0, friction=0.2, errors=False, drive="angle")]


@pytest.mark.parametrize("cell", SMALL_GRID, ids=lambda c: f"{c['angle_deg']:g}deg-{c['rpm']:g}rpm-"
                                                           f"f{c['friction']:g}-{c['drive']}")
def test_estimate_bounds_the_true_error(cell):
    """At the default accuracy the true error (against the reference at tight settings) is within
    the target and within 3 times the run's own estimate (the honesty criterion of the grid)."""
    row = run_cell(cell, 1e-3)
    assert row["status"] == "ok/ok"
    assert row["true_error"] <= 1e-3
    assert row["true_error"] <= 3.0 * row["estimate"]
    assert row["met"] is True


def test_reference_settings_are_tight():
    """The grid's reference is far tighter than any accuracy it judges (1e-11 quadrature)."""
    assert REFERENCE_TIGHT["quadrature_rtol"] <= 1e-10


@pytest.fixture(scope="module")
def full_grid() -> dict:
    """The full grid (``python tests/benchmarks accuracy``, 384 cells; hours on 2 cores), each
    cell stopped after 10 minutes (torque drives starting at 1 rpm take longer in the reference
    engine)."""
    return honesty([run_cell_limited(cell, 1e-3, timeout=600.0) for cell in grid_cells()])


@pytest.mark.slow
def test_accuracy_grid_is_honest(full_grid):
    """Within the target in >= 95 % of the cells compared, the true error within 3 times the
    estimate in >= 95 %."""
    assert full_grid["within_target"] >= 0.95
    assert full_grid["true_within_3x_estimate"] >= 0.95


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="target not reached: the estimate is within a factor 3 of "
                   "the true error both ways in 58 % of the friction cells of a 24-cell sample (it "
                   "over-reads: the first-order model's floor, docs/accuracy.md)")
def test_estimate_is_within_a_factor_3_both_ways(full_grid):
    assert full_grid["estimate_within_3x"] >= 0.95
