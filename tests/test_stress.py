"""`cardan stress`: cell classification, real cells on both sides of the self-locking boundary,
the node-type step model the map measured, a joint of the user's, and the quick command end to
end."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cardan_exudyn import ExudynOptions
from cardan_exudyn.cli import main
from cardan_exudyn.engines import run
from cardan_exudyn.model.stepsize import error_coefficient
from cardan_exudyn.studies.stress import classify as stress_classify
from cardan_exudyn.studies.stress import panels as stress_panels
from cardan_exudyn.studies.stress.cell import measure_cell
from cardan_exudyn.studies.stress.classify import classify, efficiency_promise
from cardan_exudyn.studies.stress.map import CELL_FUNCTION, sweep_specs
from cardan_exudyn.studies.stress.panels import BASE_SCENE, Panel, base_scene
from reference.paper import named_scene, paper_errors
from reference.physics.kinematics import speed_ratio
from reference.scene.mapping import replace


def record(**changes):
    """A measured cell where both engines are ok and agree (frictionless-like numbers)."""
    base = {"status": "ok", "ref_status": "ok", "ref_reason": "", "ref_efficiency": 0.6,
            "ref_loop_gain_max": 0.4, "exu_status": "ok", "exu_reason": "", "exu_efficiency": 0.6001,
            "exu_efficiency_half": 0.60005, "half_status": "ok", "exu_loop_gain_max": 0.4,
            "ratio_error": 1e-6, "ratio_promise": 1e-5, "constraint_violation_m": 1e-12,
            "constraint_violation_rad": 1e-12}
    return {**base, **changes}


def test_promise_is_the_step_halving_estimate_with_a_floor():
    r = record(exu_efficiency=0.61, exu_efficiency_half=0.60)
    assert efficiency_promise(r) == pytest.approx(3.0 * 4.0 / 3.0 * 0.01 + stress_classify.EFFICIENCY_FLOOR)
    assert math.isnan(efficiency_promise(record(half_status="self_locking")))
    # the lagged coupling is first order: error(h) = 2 |eta_h - eta_h/2|
    lagged = record(exu_efficiency=0.61, exu_efficiency_half=0.60, coupling="lagged")
    assert efficiency_promise(lagged) == pytest.approx(3.0 * 2.0 * 0.01 + stress_classify.EFFICIENCY_FLOOR)


@pytest.mark.parametrize("changes, cls, agrees, category", [
    ({}, "converged", True, "agree: ok"),
    ({"ratio_error": 2e-5}, "drift", False, "wrong answer with status ok"),
    ({"exu_efficiency": 0.7, "exu_efficiency_half": 0.7}, "drift", False, "wrong answer with status ok"),
    ({"exu_efficiency": -0.001, "ref_efficiency": -0.001}, "drift", False,
     "wrong answer with status ok"),
    ({"constraint_violation_m": 1e-3}, "drift", False, "wrong answer with status ok"),
    ({"exu_status": "self_locking"}, "self_locking", False, "Exudyn locks, the reference does not"),
    ({"exu_status": "integration_failure"}, "integration_failure", False,
     "numerical failure in a physically valid cell"),
    ({"ref_status": "self_locking", "exu_status": "self_locking"}, "self_locking", True,
     "agree: self-locking"),
    ({"ref_status": "self_locking", "exu_status": "integration_failure"}, "integration_failure",
     True, "agree: fails where the joint locks"),
    ({"ref_status": "self_locking", "ref_efficiency": None}, "drift", False,
     "runs on through a physical self-lock"),
    ({"status": "error", "reason": "ValueError: boom"}, "error", False, "harness error"),
])
def test_classify_every_category(changes, cls, agrees, category):
    out = classify(record(**changes))
    assert (out["cell_class"], out["agrees"], out["category"]) == (cls, agrees, category)
    if not agrees:
        assert out["explanation"]


def test_nan_measurements_never_count_as_within_promise():
    """A missing speed-ratio error or efficiency is a failed check, not a pass (NaN <= x is
    False, and the comparisons are written so that it stays so)."""
    assert classify(record(ratio_error=None))["cell_class"] == "drift"
    assert classify(record(exu_efficiency=float("nan")))["cell_class"] == "drift"


def _cell(panel: Panel, angle: float, x: float) -> dict:
    scene = replace(base_scene(), **panel.overrides(angle, x))
    measured = measure_cell(scene, panel.node_type)
    return {**measured, **classify({"status": "ok", "coupling": panel.coupling, **measured})}


def test_cells_either_side_of_the_self_locking_boundary():
    """At 10 deg and 2000 rpm the reference self-locks between f = 0.42 and 0.6 (loop gain 0.78
    at 0.42): converged coupling agrees on both sides; the lagged scheme, which never iterates the
    friction fixed point, runs on through the lock, to an efficiency outside [0, 1] (-2.3e-5 on
    4e6 J of input work) that the engine reports as status unphysical."""
    converged = Panel("friction", "", "friction", (), ())
    lagged = Panel("lagged", "", "friction", (), (), coupling="lagged")
    inside = _cell(converged, 10.0, 0.42)
    assert inside["cell_class"] == "converged", inside
    # the reference's largest gain over its samples to the two digits stated
    assert abs(inside["ref_loop_gain_max"] - 0.78) <= 0.005, inside["ref_loop_gain_max"]
    locked = _cell(converged, 10.0, 0.6)
    assert (locked["ref_status"], locked["cell_class"], locked["agrees"]) == (
        "self_locking", "self_locking", True)
    runs_on = _cell(lagged, 10.0, 0.6)
    assert runs_on["ref_status"] == "self_locking"
    assert runs_on["exu_status"] == "unphysical"
    assert runs_on["category"] == "agree: fails where the joint locks"


@pytest.mark.parametrize("node_type", ["EP", "RotVecLG"])
@pytest.mark.parametrize("angle", [0.0, 35.0])
def test_auto_step_meets_the_accuracy_with_every_node_type(node_type, angle):
    """The map found Euler parameters 18x over the requested speed-ratio accuracy at 0 deg with
    the Rxyz step model (K = 0 there); the node-type model now picks the step for each."""
    accuracy = 2e-5
    scene = replace(base_scene(), **{"joint.geometry.shaft_angle": math.radians(angle),
                                     "numerics.accuracy": accuracy})
    scene = replace(scene, **{f"joint.pairs.{p}.friction_coefficient": 0.0
                              for p in ("frame_input", "input_spider", "spider_output", "output_frame")})
    result = run(scene, options=ExudynOptions(node_type=node_type))
    t = result.table
    err = np.max(np.abs(t["omega_out"] / t["omega_in"]
                        - speed_ratio(t["theta_in"].to_numpy(), scene.joint.geometry.shaft_angle)))
    assert err <= accuracy, (err, result.summary.dt_choice)
    if error_coefficient(scene.joint.geometry.shaft_angle, node_type) > 0:
        assert err > accuracy / 10  # the step is not wastefully small either


def test_quick_command_writes_the_report_atomically(tmp_path, capsys):
    """`cardan stress --quick`: report, cells, plot; the sweep records are kept in OUT/runs, and a
    second invocation reuses every cell."""
    out = tmp_path / "stress"
    code = main(["stress", "--quick", "--out", str(out), "--workers", "2"])
    assert code == 0, capsys.readouterr().err
    cells = pd.read_csv(out / "map_cells.csv")
    assert len(cells) == sum(len(p.angles) * len(p.x_values) for p in stress_panels.panels(quick=True))
    assert set(cells["cell_class"]) <= set(stress_classify.CLASSES)
    assert "error" not in set(cells["cell_class"])
    # the quick map holds both boundary verdicts and the lagged scheme's run-on cell, whose
    # efficiency outside [0, 1] is status unphysical
    assert {"agree: ok", "agree: self-locking", "agree: fails where the joint locks"} <= set(
        cells["category"])
    assert "unphysical" in set(cells["exu_status"])
    report = (out / "report.md").read_text()
    # no disagreement in the quick map: the lagged run-on cell is unphysical
    assert cells["agrees"].all(), cells.loc[~cells["agrees"], ["panel", "angle_deg", "x", "category"]]
    assert "## Stability map" in report and "; 0 disagreements." in report
    assert "### Every disagreement" not in report
    assert (out / "stability_map.png").stat().st_size > 10_000
    summary = json.loads((out / "stress.json").read_text())
    assert summary["map"]["cells"] == len(cells) and summary["map"]["scene"] == BASE_SCENE
    assert not list(tmp_path.glob(".*"))  # no temporary folder left next to OUT
    assert f"report: {out}/report.md" in capsys.readouterr().out
    code = main(["stress", "--quick", "--out", str(out), "--json"])
    assert code == 0
    again = json.loads(capsys.readouterr().out)
    assert all(s["run_now"] == 0 for s in again["map"]["sweeps"].values())


@pytest.mark.parametrize("argv, word", [
    (["--angle", "20"], "unrecognized arguments: --angle"),
    (["--dt", "1e-4"], "unrecognized arguments: --dt"),
    (["--coupling", "lagged"], "unrecognized arguments: --coupling"),
    (["--name", "paper-nothing"], "paper-nothing"),
    (["--workers", "0"], "--workers"),
])
def test_bad_stress_options_exit_2(tmp_path, capsys, argv, word):
    """An option every cell sets itself (not offered), an unknown scene, zero workers: exit 2 with
    one line, nothing written."""
    try:
        code = main(["stress", "--out", str(tmp_path / "o"), *argv])
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and word in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_help_says_what_it_maps(capsys):
    """`cardan stress --help` says what the map covers and that it takes the scene options."""
    with pytest.raises(SystemExit) as exc:
        main(["stress", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert exc.value.code == 0
    assert "Stability map of Exudyn against the reference" in out and "--scene FILE" in out
    assert "default paper- literal-10deg-2000rpm, literal set" in out and "--angle" not in out


def test_the_map_of_a_users_joint_is_built_on_it():
    """`cardan stress --name NAME`: every sweep's base scene is the named joint (its inertia, load,
    mounting errors), one revolution, each cell's overrides on top; the default is the paper's."""
    joint = replace(named_scene("paper-physical-10deg-2000rpm"), **paper_errors())
    specs = sweep_specs(quick=True, scene=joint)
    for spec in specs.values():
        assert spec.scene == base_scene(joint) and spec.function == CELL_FUNCTION
        assert spec.scene.joint.errors == joint.joint.errors and spec.scene.revolutions == 1.0
    assert all(s.scene.name == BASE_SCENE for s in sweep_specs(quick=True).values())


def test_a_cell_with_mounting_errors_measures_the_speed_ratio_against_the_exact_one():
    """With mounting errors Hooke's law is not the joint's: the cell's speed-ratio error is
    against the reference's RCCC ratio, so it is within the step's promise (against Hooke it
    would be the tolerances' own 2.7e-5, far above it at 400 steps per revolution)."""
    joint = replace(named_scene("paper-physical-10deg-2000rpm-frictionless"), **paper_errors())
    panel = Panel("steps", "", "steps", (), (), friction=0.0)
    cell = measure_cell(replace(base_scene(joint), **panel.overrides(10.0, 400.0)), "Rxyz")
    assert cell["exu_status"] == cell["ref_status"] == "ok"
    assert cell["ratio_error"] <= cell["ratio_promise"] < 2e-5, cell
    assert classify({"status": "ok", "coupling": "converged", **cell})["cell_class"] == "converged"
