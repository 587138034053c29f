"""The one engine dispatch and the one typed result: options travel through it, every engine
returns a Summary with the same fields, bugs are raised, not reported as physics."""

from __future__ import annotations

import json
import math

import pytest

import cardan_exudyn
from cardan_exudyn import engines
from cardan_exudyn.model import coupling
from reference import named_scene, replace
from reference.results.summary import RECORD_FIELDS, SCHEMA_VERSION, OptionsError, Status, Summary

SHORT = {"revolutions": 1.0}


@pytest.fixture(scope="module")
def frictionless():
    return replace(named_scene("paper-literal-10deg-frictionless"), **SHORT)


@pytest.mark.parametrize("engine", ["exudyn", "reference", "mujoco"])
def test_every_engine_fills_the_same_summary(frictionless, engine):
    """Same fields for every engine (comparing is a join), cost counters next to the solution."""
    result = cardan_exudyn.run(frictionless, engine)
    assert result.success, result.message
    assert result.status is Status.OK and result.summary.engine == engine
    data = result.summary.to_dict()
    assert data["schema_version"] == SCHEMA_VERSION
    reference = cardan_exudyn.run(frictionless, "reference").summary
    # every key but the engine's own: its extras and typed records (Exudyn's accuracy, the
    # reference's quadrature, ...)
    fields = set(data) - set(result.summary.extras) - set(RECORD_FIELDS)
    assert fields == set(reference.to_dict()) - set(reference.extras) - set(RECORD_FIELDS)
    assert {"mean_efficiency", "input_work", "steps", "wall_time_s", "dt", "status"} <= fields
    assert result.summary.steps > 0 and math.isfinite(result.mean_efficiency)


def test_options_travel_through_the_dispatch(frictionless):
    """Options given as an object or as keywords reach the engine and are recorded."""
    by_keyword = cardan_exudyn.run(frictionless, "exudyn", node_type="EP")
    by_object = cardan_exudyn.run(frictionless, options=cardan_exudyn.ExudynOptions(node_type="EP"))
    assert by_keyword.summary.options["node_type"] == by_object.summary.options["node_type"] == "EP"
    assert by_keyword.summary.engine == by_object.summary.engine == "exudyn"
    reference = cardan_exudyn.run(frictionless, "reference", samples_per_revolution=36)
    assert reference.summary.steps == 36


@pytest.mark.parametrize("call, message", [
    (lambda s: cardan_exudyn.run(s, "warp"), "`engine` must be one of"),
    (lambda s: cardan_exudyn.run(s, "exudyn", warp_speed=9), "unknown option"),
    (lambda s: cardan_exudyn.run(s, "reference", options=cardan_exudyn.ExudynOptions()),
     "not the options of engine 'reference'"),
    (lambda s: cardan_exudyn.run(s, "exudyn", options=cardan_exudyn.ExudynOptions(), node_type="EP"),
     "not both"),
    (lambda s: cardan_exudyn.run(s, "exudyn", spectral_radius=1.5), "spectral_radius"),
    (lambda s: cardan_exudyn.run(s, "reference", quadrature_rtol=-1.0), "quadrature_rtol"),
], ids=["unknown-engine", "unknown-option", "wrong-options-class", "options-twice",
        "exudyn-range", "reference-range"])
def test_bad_engine_input_is_refused(frictionless, call, message):
    """Each mistake gets a ValueError naming what is wrong, before anything runs."""
    with pytest.raises(ValueError, match=message):
        call(frictionless)


def test_option_errors_have_one_type():
    """Every engine's options raise OptionsError (a ValueError)."""
    for engine, values in (("exudyn", {"node_type": "X"}), ("reference", {"gauss_nodes": 0}),
                           ("mujoco", {"integrator": "X"})):
        with pytest.raises(OptionsError):
            engines.make_options(engine, **values)


def test_mujoco_refuses_friction():
    """An engine that cannot express a scene says so (EngineUnavailable), no result."""
    with pytest.raises(engines.EngineUnavailable, match="friction"):
        cardan_exudyn.run(replace(named_scene("paper-literal-10deg"), **SHORT), "mujoco")


def test_summary_round_trips_through_json(frictionless):
    """to_dict is the JSON shape on disk; from_dict reads it back to an equal Summary."""
    summary = cardan_exudyn.run(frictionless, "reference").summary
    data = json.loads(json.dumps(summary.to_dict()))
    again = Summary.from_dict(data)
    assert again.to_dict() == data
    assert again.status is Status.OK and again.pair_loss_work == summary.pair_loss_work


def test_a_failed_run_has_no_means():
    """A self-locking run (the reference's 50 deg case) carries its reason and no efficiency."""
    result = cardan_exudyn.run(replace(named_scene("paper-literal-50deg"), **SHORT), "reference")
    assert result.status is Status.SELF_LOCKING and not result.success
    assert result.message and result.mean_efficiency is None
    assert result.summary.to_dict()["mean_efficiency"] is None


def test_a_bug_in_the_friction_update_is_raised(monkeypatch):
    """A Python error inside Exudyn's post-Newton callback is raised, not reported as an
    integration failure of the joint."""
    calls = {"n": 0}
    real = coupling.FrictionCoupling.evaluate

    def evaluate(self, t):
        calls["n"] += 1
        if calls["n"] > 20:
            raise TypeError("a bug in the friction update")
        return real(self, t)

    monkeypatch.setattr(coupling.FrictionCoupling, "evaluate", evaluate)
    with pytest.raises(TypeError, match="a bug in the friction update"):
        cardan_exudyn.run(replace(named_scene("paper-literal-10deg"), **SHORT))


def test_uncoupled_friction_without_the_table():
    """``uncoupled`` friction is evaluated on the recorded reactions afterwards, so a
    summary-only run records them too and gives the same efficiency as a run with the table
    (it ended 'diverged' on NaN reactions before)."""
    scene = replace(named_scene("paper-literal-10deg"), revolutions=1.0, **{"friction.coupling": "uncoupled"})
    with_table = cardan_exudyn.run(scene)
    summary_only = cardan_exudyn.run(replace(scene, **{"record.timeseries": False}))
    assert with_table.success and summary_only.success, summary_only.message
    assert summary_only.mean_efficiency == with_table.mean_efficiency
