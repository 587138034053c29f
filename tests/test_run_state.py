"""The run's state as typed records on the summary: ``summary.accuracy`` (RunAccuracy) and
``summary.friction`` (FrictionDiagnostics), their tables in ``summary.json`` and the reading of
tables written by other versions."""

from __future__ import annotations

import json

import pytest

import cardan_exudyn
from cardan_exudyn.model.options import ExudynOptions
from reference.paper.scenes import named_scene
from reference.results.accuracy import CompanionRun, PilotRun, RunAccuracy
from reference.results.friction_diagnostics import FrictionDiagnostics
from reference.results.summary import Status, Summary
from reference.scene.mapping import replace

SHORT = {"revolutions": 1.0, "record.timeseries": False}


@pytest.fixture(scope="module")
def given_step():
    """An Exudyn run with friction at a given step: companion, estimate and coupling counters."""
    scene = replace(named_scene("paper-literal-10deg"), **SHORT, **{"numerics.dt": 2e-4})
    return cardan_exudyn.run(scene).summary


def test_the_records_are_typed_and_round_trip_through_json(given_step):
    """An Exudyn summary carries both records; on disk they are the ``accuracy`` and ``friction``
    tables, and ``from_dict`` reads them back to an equal summary."""
    s = given_step
    assert isinstance(s.accuracy, RunAccuracy) and isinstance(s.friction, FrictionDiagnostics)
    assert "accuracy" not in s.extras and "friction" not in s.extras
    assert s.accuracy.companion.dt == 4e-4 and s.accuracy.target == 1e-3
    assert s.friction.loop_gain_estimate_max == s.max_friction_loop_gain
    data = json.loads(json.dumps(s.to_dict()))
    assert data["accuracy"]["companion_dt"] == 4e-4 and data["friction"]["coupling"] == "extrapolated"
    again = Summary.from_dict(data)
    assert again == s
    assert list(again.to_dict()) == list(data)


def test_accuracy_table_keys_in_order():
    """The companion's fields flattened as ``companion_<field>``, unset fields left out, the pilot
    nested: the table's shape before the record existed."""
    record = RunAccuracy(target=1e-3, order=2, loss_fraction=0.5, steps_per_revolution=200.0,
                         model=1e-4, companion=CompanionRun(4e-4, "ok", 0.49, 0.1),
                         richardson=2e-5, method="Richardson",
                         pilot=PilotRun(4e-4, 0.49, 0.1, True))
    assert list(record.to_dict()) == [
        "target", "order", "loss_fraction", "steps_per_revolution", "model", "companion_dt",
        "companion_status", "companion_mean_efficiency", "companion_wall_time_s", "richardson",
        "method", "pilot"]
    assert RunAccuracy.from_dict(record.to_dict()) == record
    assert RunAccuracy(pilot=PilotRun(1e-3, None, 0.2, False)).to_dict() == {
        "pilot": {"dt": 1e-3, "mean_efficiency": None, "wall_time_s": 0.2, "is_companion": False}}


@pytest.mark.parametrize("options, keys", [
    (None, {"target", "method"}),
    (ExudynOptions(error_estimate=False), None),
], ids=["frictionless", "given-step-without-estimate"])
def test_what_each_kind_of_run_records(options, keys):
    """A frictionless run records its target and method; a given step without the estimate
    records no accuracy at all."""
    name = "paper-literal-10deg-frictionless" if keys else "paper-literal-10deg"
    scene = replace(named_scene(name), **SHORT, **{"numerics.dt": 2e-4})
    s = cardan_exudyn.run(scene, options=options).summary
    assert s.status is Status.OK
    assert (None if s.accuracy is None else set(s.accuracy.to_dict())) == keys


def test_an_older_friction_table_reads_with_what_it_has():
    """A table without the newer keys (``gain_probes``) is read into the record, the missing
    fields None."""
    old = {"coupling": "converged", "sign_bands_m_s": {"input_spider": [1e-3, 1e-6, 1e-3]},
           "pairs_with_friction": ["input_spider"], "tolerance": 1e-9,
           "mean_iterations_per_step": 5.5, "max_iterations_in_a_step": 8, "unconverged_steps": 0,
           "loop_gain_estimate": 0.6, "loop_gain_estimate_max": 0.8}
    s = Summary.from_dict({"schema_version": 3, "status": "ok", "friction": old})
    assert s.friction.gain_probes is None and s.friction.sign_bands_m_s["input_spider"] == (1e-3, 1e-6, 1e-3)
    assert s.to_dict()["friction"] == {**old, "escalated_to_converged_at": None,
                                       "steps_iterated_at_reversals": None, "gain_probes": None}


def test_a_table_of_unknown_shape_is_kept_as_it_was():
    """A table with keys this version does not know stays in ``extras`` and is written back
    unchanged."""
    data = {"schema_version": 3, "status": "ok", "accuracy": {"target": 1e-3, "fallback": "model"},
            "friction": {"coupling": "converged", "stall_ratio": 0.1}}
    s = Summary.from_dict(data)
    assert s.accuracy is None and s.friction is None
    assert s.extras == {"accuracy": data["accuracy"], "friction": data["friction"]}
    out = s.to_dict()
    assert out["accuracy"] == data["accuracy"] and out["friction"] == data["friction"]
