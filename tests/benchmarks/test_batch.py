"""The batched reference engine's measurements (``python tests/benchmarks batch``)."""

from __future__ import annotations

from benchmarks.batch.measure import torque_drive
from benchmarks.batch.targets import TORQUE_TARGET_S, batch_targets
from reference.results.summary import Status


def test_batch_bench_reports_the_torque_drive_target():
    """The torque-drive target: the reference engine's torque-driven
    paper scene runs to status ok with the friction losses of a 10 deg joint, and the target row
    compares the measured time with its limit (the time itself is a benchmark, not asserted)."""
    torque = torque_drive(repeats=1)
    assert torque["status"] == Status.OK and 0.9 < torque["mean_efficiency"] < 1.0
    paper = {"wall_s": 1.0, "failed": 0, "scenes": 11, "walls_s": [1.0], "max_difference": 0.0}
    row, = [r for r in batch_targets({"paper": paper, "torque": torque}) if r["target"] == "torque_drive"]
    assert row["measured"] == torque["per_revolution_s"] and row["limit"] == TORQUE_TARGET_S
    assert row["met"] is (torque["per_revolution_s"] <= TORQUE_TARGET_S)
