"""The skip audit (``python tests/benchmarks targets``' audit): pairs of runs side by side,
and the engine's own solve with a tweak."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from benchmarks.audit import skip_audit, solution_file, solve_only
from cardan_exudyn import engines
from cardan_exudyn.studies.bench.configs import EXUDYN_TUNED
from reference.paper import named_scene
from reference.scene import replace


def test_skip_audit_measures_each_item_side_by_side():
    """Each item's two runs, timed in CPU time (blind to the other load of a shared machine) as
    the median of 3 rounds; the item with the largest effect shows it."""
    audit = skip_audit(repeats=3, steps=100, revolutions=1, fast_module=False, clock=time.process_time)
    assert len(audit) == 8
    assert (audit["with_s"] > 0).all() and (audit["without_s"] > 0).all()
    np.testing.assert_allclose(audit["with_over_without"], audit["with_s"] / audit["without_s"])
    # Exudyn's coordinates file written every step (text formatting, CPU work) is the one item
    # whose effect is far above timing noise at this size: with / without measured 1.21 to 1.64
    # (median 1.37) over 40 such audits on 2 loaded cores, while items of no effect ranged 0.95 to
    # 1.16 (5-95 %); in wall time (the default clock) they ranged 0.46 to 2.0 there. The Python
    # drive function measures 1.10 to 1.14 (medians; histories evaluate in plain floats, about
    # 1 us, reference.scene.histories): within the noise.
    row = audit[audit["item"] == "solution file"].iloc[0]
    assert row["with_over_without"] > 1.1


def test_solve_only_is_the_engine_solve_with_the_tweak(tmp_path):
    """The audit's build-and-solve runs are the engine's one solve sequence (the same step as a
    full run), with the tweak applied once before the solver starts: the solution-file item
    really writes Exudyn's coordinates file."""
    scene = replace(named_scene("paper-literal-10deg-frictionless"),
                    **{"numerics.dt": 2 * math.pi / 209.44 / 100, "revolutions": 1,
                       "record.timeseries": False})
    steps = []

    def tweak(model, settings):
        ti = settings.timeIntegration
        steps.append((ti.endTime - ti.startTime) / ti.numberOfSteps)
        solution_file(str(tmp_path))(model, settings)

    assert solve_only(scene, EXUDYN_TUNED, tweak) > 0
    assert (tmp_path / "solution.txt").stat().st_size > 0
    assert steps == [pytest.approx(engines.run(scene, "exudyn", EXUDYN_TUNED).summary.dt, rel=1e-12)]
