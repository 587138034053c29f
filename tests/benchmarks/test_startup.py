"""The import cost of ``cardan run`` (``tests/benchmarks/startup.py``): parsing ``python -X
importtime``'s output and one measured run."""

from __future__ import annotations

import pytest

from benchmarks.startup import SCENE_MARKER, import_cost, parse_importtime

SAMPLE = f"""import time: self [us] | cumulative | imported package
import time:       100 |        100 |   _io
import time:       900 |       1000 | site
import time:       500 |      50000 |   numpy
import time:       200 |      60000 | cardan_exudyn.cli
{SCENE_MARKER}
import time:       300 |       7000 |     reference.physics.rccc
import time:       400 |      12000 | reference.engine.solve
import time:        50 |         50 | numpy.ma
"""


def test_parse_importtime_sums_top_level_entries_per_phase():
    """Only indent-0 entries count (their cumulative time holds the nested ones), split at the
    marker; the header line is skipped."""
    before, after = parse_importtime(SAMPLE)
    assert before == {"site": 1000, "cardan_exudyn.cli": 60000}
    assert after == {"reference.engine.solve": 12000, "numpy.ma": 50}
    assert parse_importtime(SAMPLE.replace(SCENE_MARKER, "other line"))[1] == {}


def test_import_cost_measures_cardan_run():
    """One measured run: the phases, their largest imports and the numpy floor are reported."""
    cost = import_cost(1)
    assert cost["import_ms"] == cost["runs_ms"][0] > 0
    assert "cardan_exudyn.cli" in [name for name, _ in cost["top"]]
    # a named scene is data: building it imports no engine
    assert not [name for name, _ in cost["scene_top"] if name.startswith("reference.engine")]
    assert cost["baseline_ms"] > 0
    assert cost["through_scene_ms"] >= cost["import_ms"]  # equal when the scene imports nothing
    assert cost["target_ms"] == 150.0 and cost["repeats"] == 1


@pytest.mark.parametrize("repeats", [0, -1, 1.5, True])
def test_import_cost_refuses_bad_repeats(repeats):
    with pytest.raises(ValueError, match="`repeats` must be a positive integer"):
        import_cost(repeats)
