"""The modules ``cardan run`` walks through (``tests/benchmarks/walk.py``): each entered from the
modules above it only, no call back into a module further up the stack."""

from __future__ import annotations

import pytest
from benchmarks.walk import runs_the_command, walk


@pytest.mark.parametrize("coupling", ["extrapolated", "converged", "lagged"])
def test_cardan_run_has_no_trip_back(coupling):
    """``cardan run --name paper-10deg``: the accuracy module plans, then solves; the coupling
    schemes call down into the shared coupling, never the other way."""
    recorder = walk(["run", "--name", "paper-10deg", "--coupling", coupling, "--revolutions", "1"])
    trips = [path for path in recorder.trips if any(map(runs_the_command, path))]
    assert trips == []
    order = [m for m in recorder.first if m.startswith("cardan_exudyn.model.")]
    assert order.index("cardan_exudyn.model.accuracy") < order.index("cardan_exudyn.model.stepsize")
    assert order.index("cardan_exudyn.model.stepsize") < order.index("cardan_exudyn.model.solve")
    assert recorder.first["cardan_exudyn.model.solve"] == "cardan_exudyn.model.accuracy"
    assert f"cardan_exudyn.model.{coupling}" in recorder.first
