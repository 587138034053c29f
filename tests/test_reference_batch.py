"""reference.engine.batch.solve: many constant-speed scenes in one pass give the single engine's results
(a reference package test: it calls the engine directly, as tests/test_architecture.py allows)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from reference.engine.batch.solve import batch_key, run_batch
from reference.engine.options import ReferenceOptions
from reference.engine.solve import run
from reference.paper.scenes import named_scene, rig_scene
from reference.results.summary import OptionsError, Status
from reference.scene.drives import TorqueDrive
from reference.scene.mapping import replace
from reference.scene.validation import SceneError

# Same samples, same arithmetic per sample: the tables agree to rounding. The works are sums of
# the same panel integrals in another order, and a panel at its closing threshold may split
# differently, so the mean efficiency agrees within the quadrature's own acceptance: rtol
# (1e-9) of the input work over the window, i.e. about 1e-9 in efficiency (input and lost work
# each within it). Observed: 5e-16.
EFFICIENCY_ATOL = 2 * ReferenceOptions().quadrature_rtol
WORK_RTOL = 2 * ReferenceOptions().quadrature_rtol


def _rig(**changes):
    base = replace(rig_scene(parameters="matched", errors=True), **{"record.timeseries": False})
    return replace(base, **changes)


@pytest.fixture(scope="module")
def mixed():
    """Ordinary, sliding, locking, failing and frictionless members of one rig batch, and two
    paper scenes (ideal joint, another key)."""
    scenes = [
        _rig(**{"joint.errors.a1_mm": 0.3}),  # ordinary: the pairs slide (axial friction works)
        _rig(**{"joint.errors.a2_mm": -0.4, "joint.errors.alpha3_deg": 0.005}),
        _rig(**{"joint.errors.alpha2_deg": -80.0}),  # the loop does not close
        _rig(**{"joint.errors.alpha1_deg": -80.0}),  # it closes, but not as a double crank
        _rig(**{"joint.pairs.frame_input.friction_coefficient": 3.0,  # friction self-locks
                "joint.pairs.output_frame.friction_coefficient": 3.0}),
        _rig(**{"joint.errors.a1_mm": 40.0}),  # a large offset: self-locks everywhere
        _rig(**{f"joint.pairs.{p}.friction_coefficient": 0.0  # frictionless, mounting errors
                for p in ("frame_input", "input_spider", "spider_output", "output_frame")}),
        replace(named_scene("paper-literal-10deg"), **{"record.timeseries": True}),
        _rig(**{"joint.errors.a3_mm": 0.2, "record.timeseries": True}),
        replace(named_scene("paper-matched-35deg"), **{"record.timeseries": False}),
        replace(named_scene("paper-35deg-500rpm"), **{"record.timeseries": False}),  # levers from geometry
        # code paths and per-scene settings: resultant-slip law, uncoupled friction, a partial
        # revolution skipped, reversed speed and a table at numerics.dt
        _rig(**{"friction.law": "resultant", "joint.errors.a2_mm": -0.3}),
        _rig(**{"friction.coupling": "uncoupled", "joint.errors.a1_mm": 0.2}),
        _rig(**{"record.skip_revolutions": 0.5, "revolutions": 2.5, "joint.errors.a3_mm": 0.1,
                "drive.speed": -6.0, "numerics.dt": 1e-3}),
    ]
    return scenes, run_batch(scenes), [run(s) for s in scenes]


def test_statuses_and_reasons_match(mixed):
    """Every member gets the single engine's status and reason, in order."""
    scenes, batch, single = mixed
    assert len(batch) == len(scenes)
    for b, s in zip(batch, single, strict=True):
        assert (b.summary.status, b.summary.reason) == (s.summary.status, s.summary.reason)
        assert b.summary.scene == s.summary.scene  # order kept: each result is its own scene's
    statuses = [r.summary.status for r in single]
    assert statuses[2] is statuses[3] is Status.LOOP_DOES_NOT_CLOSE
    assert statuses[4] is statuses[5] is Status.SELF_LOCKING
    assert statuses.count(Status.OK) == 10


def test_means_match_within_quadrature_tolerance(mixed):
    """Mean efficiency within the quadrature tolerance; works, the sliding losses included."""
    _, batch, single = mixed
    for b, s in zip(batch, single, strict=True):
        if not s.summary.success:
            continue
        assert abs(b.summary.mean_efficiency - s.summary.mean_efficiency) <= EFFICIENCY_ATOL
        for key in ("input_work", "output_work", "loss_work"):
            scale = abs(s.summary.input_work)
            assert abs(getattr(b.summary, key) - getattr(s.summary, key)) <= WORK_RTOL * scale, key
        for pair, w in s.summary.pair_sliding_loss_work.items():
            assert abs(b.summary.pair_sliding_loss_work[pair] - w) <= WORK_RTOL * abs(s.summary.input_work)


def test_sliding_member_slides(mixed):
    """The sliding member's axial friction does work (the batch covers the loop's slides)."""
    _, batch, _ = mixed
    assert batch[0].summary.pair_sliding_loss_work["input_spider"] > 1e-4


def test_summary_keys_and_extras_match(mixed):
    """Same summary keys, quadrature diagnostics and self-locking counts as the single run."""
    _, batch, single = mixed
    for b, s in zip(batch, single, strict=True):
        db, ds = b.summary.to_dict(), s.summary.to_dict()
        assert db.keys() == ds.keys()
        eb, es = b.summary.extras, s.summary.extras
        assert eb.keys() == es.keys()
        if "quadrature" in es:
            assert eb["quadrature"].keys() == es["quadrature"].keys()
            for key in ("nodes_per_panel", "sign_breakpoints", "knots", "revolutions_integrated", "rtol"):
                assert eb["quadrature"][key] == es["quadrature"][key], key
        for key in ("self_locking_samples", "sign_bands_m_s"):
            assert eb.get(key) == es.get(key), key
        assert db["steps"] == ds["steps"] and db["dt"] == ds["dt"]
        if ds["max_friction_loop_gain"] is not None:
            assert db["max_friction_loop_gain"] == pytest.approx(ds["max_friction_loop_gain"], rel=1e-9)


def test_time_tables_match_to_rounding(mixed):
    """The time table only where ``record.timeseries`` is on, equal to rounding."""
    scenes, batch, single = mixed
    for scene, b, s in zip(scenes, batch, single, strict=True):
        if not scene.record.timeseries or s.table is None:
            assert b.table is None
            continue
        assert list(b.table.columns) == list(s.table.columns)
        for c in s.table.columns:
            want = np.asarray(s.table[c], float)
            # rounding of ~1e-13 relative to the column's size (sums of products of O(1) terms)
            np.testing.assert_allclose(np.asarray(b.table[c], float), want, rtol=0,
                                       atol=1e-11 * (1.0 + np.nanmax(np.abs(want))), err_msg=c)


def test_batch_keys():
    """Constant-speed scenes share a key by joint kind and friction slots; a torque drive runs alone."""
    a, b = _rig(**{"joint.errors.a1_mm": 0.1}), _rig(**{"joint.errors.a2_mm": 0.2})
    assert batch_key(a) == batch_key(b) is not None
    assert batch_key(named_scene("paper-10deg")) != batch_key(a)
    assert batch_key(named_scene("paper-10deg-frictionless")) != batch_key(named_scene("paper-10deg"))
    torque = dataclasses.replace(named_scene("paper-10deg"), drive=TorqueDrive(5.0, 2 * math.pi))
    assert batch_key(torque) is None


def test_invalid_input_raises_with_index():
    """A non-scene names its index; bad options are refused; nothing runs."""
    with pytest.raises((TypeError, SceneError), match=r"scenes\[1\]"):
        run_batch([_rig(), "not a scene"])
    with pytest.raises(OptionsError, match="options"):
        run_batch([_rig()], options={"quadrature_rtol": 1e-9})
    assert run_batch([]) == []
    too_long = replace(_rig(), **{"numerics.dt": 1e-12})  # beyond the engine's step limit
    with pytest.raises(SceneError, match=r"scenes\[1\].*steps"):
        run_batch([_rig(), too_long])
