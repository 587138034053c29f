"""``cardan bench``: error measures, configurations, the cheapest run at the scene's accuracy,
a scene of the user's, result files, bad input.

The bench's numbers are measurements, not test assertions; these tests check that the bench
measures what it says (errors against independent yardsticks, the cheapest configuration at a
level) and that its files and exit codes are right. The speed targets are
``tests/benchmarks/test_targets.py``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cardan_exudyn import engines
from cardan_exudyn.cli import main
from cardan_exudyn.studies.bench.configs import (
    EXUDYN_TUNED,
    SCENES,
    BenchError,
    Config,
    bench_scene,
    configurations,
    fixed_scenes,
)
from cardan_exudyn.studies.bench.ladders import run_errors, yardstick
from cardan_exudyn.studies.bench.report import bench_command
from cardan_exudyn.studies.bench.result import BenchResult, at_accuracy, cheapest, check_inputs
from reference.paper import named_scene
from reference.results.result import Result
from reference.results.summary import Status, Summary
from reference.scene import replace


def tuned_errors(scene, steps) -> list[dict]:
    """The bench's errors of Exudyn (tuned) on ``scene`` at each of ``steps`` per revolution,
    against the reference's yardstick."""
    yard = yardstick(scene)
    out = []
    for n in steps:
        config = Config("exudyn", "exudyn tuned", n, EXUDYN_TUNED)
        s = config.scene(scene)
        out.append(run_errors(s, config.run(s), yard))
    return out


def test_run_errors_follow_the_integrators_order():
    """Halving Exudyn's step divides the speed-ratio and drive-torque errors (after the start-up
    revolution) by about four: the errors are measured against the exact reference, not against
    a run of the same engine."""
    errs = tuned_errors(named_scene("paper-literal-35deg-frictionless"), (100, 200))
    for key in ("speed_ratio_error", "torque_in_error_steady"):
        assert 3.3 < errs[0][key] / errs[1][key] < 4.7, (key, errs)
    assert errs[1]["speed_ratio_error"] < 2e-4
    assert math.isnan(errs[0]["mean_efficiency_error"])  # frictionless: no efficiency error
    assert errs[1]["mean_torque_in_error"] < 1e-3


def test_run_errors_of_a_failed_run_are_nan():
    scene = named_scene("paper-literal-10deg-frictionless")
    failed = Result(None, Summary(Status.INTEGRATION_FAILURE, "solver failed"))
    errs = run_errors(scene, failed, yardstick(scene))
    assert all(math.isnan(v) for v in errs.values())


def test_quick_bench_cli_writes_files_with_the_environment_header(tmp_path, capsys):
    out = tmp_path / "bench"
    code = main(["bench", "--quick", "--scenes", "frictionless-10deg", "--engines", "exudyn,reference",
                 "--out", str(out), "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    env = summary["environment"]
    for key in ("python", "platform", "cpu", "cpu_count", "packages", "commit", "date"):
        assert key in env
    assert env["packages"]["exudyn"]
    assert sorted(p.name for p in out.iterdir()) == ["bench.csv", "bench.json", "report.md",
                                                     "work_precision.png"]
    lines = (out / "bench.csv").read_text().splitlines()
    assert lines[0].startswith("# cardan bench") and any(li.startswith("# cpu") for li in lines[:5])
    table = pd.read_csv(out / "bench.csv", comment="#")
    assert set(table["engine"]) == {"exudyn", "reference"}
    assert (table["status"] == "ok").all()
    ex = table[table["config"] == "exudyn tuned"].sort_values("steps_per_revolution")
    assert np.all(np.diff(ex["speed_ratio_error"]) < 0)  # finer steps, smaller error
    assert (table["wall_per_simulated_s"] > 0).all()
    # Richardson (two runs at h and h/2, extrapolated) improves the steady drive torque of the
    # projected run at the same steps per revolution
    projected = table[table["config"] == "exudyn tuned + projection"].set_index("steps_per_revolution")
    richardson = table[table["config"] == "exudyn tuned + projection + richardson"].set_index(
        "steps_per_revolution")
    assert len(richardson) == 2
    assert (richardson["torque_in_error_steady"] < projected["torque_in_error_steady"]).all()
    report = (out / "report.md").read_text()
    assert "cardan bench --quick --repeats 1 --scenes frictionless-10deg --engines exudyn,reference" in report
    # every configuration reaches the default accuracy (1e-3) on the speed ratio at 10 deg
    best = {c["config"]: c for c in summary["configurations"]}
    assert best["exudyn tuned"]["steps_per_revolution"] == 50 and best["exudyn tuned"]["accuracy"] == 1e-3
    assert best["exudyn tuned"]["error"] == pytest.approx(ex["speed_ratio_error"].iloc[0], rel=1e-5)


@pytest.mark.parametrize("args, message", [
    (["--scenes", "frictionless-90deg"], "--scenes"),
    (["--engines", "ode"], "--engines"),
    (["--repeats", "0"], "--repeats"),
    (["--name", "paper-10deg", "--scenes", "friction-10deg"], "--scenes"),
    (["--name", "paper-10deg", "--dt", "1e-4"], "unrecognized arguments: --dt"),
    (["--name", "paper-10deg", "--coupling", "lagged"], "unrecognized arguments: --coupling"),
    (["--angle", "20"], "--angle applies to the scene of --scene or --name"),
    (["--name", "no-such-scene"], "no-such-scene"),
    (["--only", "batch"], "unrecognized arguments"),
])
def test_bad_input_is_exit_2_with_one_line(args, message, capsys, tmp_path):
    try:
        code = main(["bench", "--quick", "--out", str(tmp_path / "b"), *args])
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert message in err[-1]
    assert not any("Traceback" in line for line in err)
    assert not (tmp_path / "b").exists()


def test_configurations_cover_the_issue_dimensions():
    """Every coupling with friction, the projection and Richardson without, MuJoCo only on the
    frictionless ideal joint, the reference engine's resolution in its options."""
    full = configurations(bench_scene("friction-35deg"), quick=False)
    couplings = {c.label: c.coupling for c in full if c.engine == "exudyn"}
    # every friction configuration names its coupling, whatever the scene's default
    assert couplings["exudyn default"] == couplings["exudyn tuned"] == "converged"
    assert couplings["exudyn tuned extrapolated"] == "extrapolated"
    assert couplings["exudyn tuned lagged"] == "lagged"
    assert any(c.engine == "reference" for c in full)
    assert not any(c.engine == "mujoco" for c in full)  # MuJoCo has no reaction friction
    free = configurations(bench_scene("frictionless-35deg"), quick=False)
    assert any("projection" in c.label for c in free)
    scene = free[0].scene(named_scene("paper-literal-35deg-frictionless"))
    assert scene.numerics.dt == pytest.approx(2 * math.pi / scene.drive.speed / free[0].steps)
    for config in full:
        if config.coupling is not None:
            assert config.scene(named_scene("paper-literal-35deg")).friction.coupling == config.coupling
    # the reference engine's resolution is its table samples, in its options, not a time step
    reference = [c for c in full if c.engine == "reference"]
    base = named_scene("paper-literal-35deg")
    assert all(c.options.samples_per_revolution == c.steps for c in reference)
    assert all(c.scene(base).numerics.dt == base.numerics.dt for c in reference)


def test_a_configuration_carries_any_scene_changes():
    """Richardson is a scene change (``numerics.richardson``) on top of the projection option;
    changes are stored hashable and reported in the row."""
    free = configurations(bench_scene("frictionless-35deg"), quick=True, engines=("exudyn",))
    richardson = [c for c in free if c.label == "exudyn tuned + projection + richardson"]
    assert [c.steps for c in richardson] == [50, 200]
    scene = richardson[0].scene(bench_scene("frictionless-35deg"))
    assert scene.numerics.richardson is True
    assert richardson[0].options.velocity_projection
    assert richardson[0].describe()["scene_changes"] == "numerics.richardson=True"
    config = Config("exudyn", "x", 100, EXUDYN_TUNED, {"friction.coupling": "lagged", "load.torque": 1.5})
    assert hash(config) == hash(Config("exudyn", "x", 100, EXUDYN_TUNED,
                                       [("load.torque", 1.5), ("friction.coupling", "lagged")]))
    changed = config.scene(named_scene("paper-literal-10deg"))
    assert (changed.load.torque, changed.friction.coupling) == (1.5, "lagged")


def test_sliding_pair_scenes_have_the_papers_tolerances_and_the_reference_solves_them():
    """The sliding-pair scene and its twin: Section 4.2's offsets and twists on the 10 deg joint;
    the reference engine solves it (ok, no self-locking) with the cylindrical pairs sliding, and
    the sliding friction lowers the efficiency below the ideal joint's."""
    scene = bench_scene("friction-errors-10deg")
    twin = bench_scene("frictionless-errors-10deg")
    assert scene.joint.errors == twin.joint.errors and scene.joint.errors.a1 == pytest.approx(5e-4)
    assert scene.has_friction and not twin.has_friction
    assert not any(c.engine == "mujoco" for c in configurations(twin))
    options = engines.make_options("reference", samples_per_revolution=36)
    result = engines.run(scene, "reference", options)
    assert result.success, result.message
    slide = max(float(np.max(np.abs(result.table[f"{p}_slide_rel"])))
                for p in ("input_spider", "spider_output", "output_frame"))
    assert slide > 1e-3  # [m/s]; the ideal joint's pairs do not slide at all
    ideal = replace(scene, **{f"joint.errors.{k}{i}": 0.0 for k in ("a", "alpha") for i in (1, 2, 3)})
    ideal = engines.run(ideal, "reference", options)
    assert ideal.success
    assert result.summary.mean_efficiency < ideal.summary.mean_efficiency - 0.01


def test_speed_ratio_error_with_mounting_errors_is_against_the_exact_ratio():
    """Hooke's law is the ideal joint's; with mounting errors the speed-ratio error is measured
    against the reference's exact RCCC ratio, so it still falls with the integrator's order
    (against Hooke it would stay at the tolerances' own 2.7e-5)."""
    runs = tuned_errors(bench_scene("frictionless-errors-10deg"), (100, 200))
    errs = [e["speed_ratio_error"] for e in runs]
    assert 3.3 < errs[0] / errs[1] < 4.7, errs
    assert errs[1] < 1e-5


def test_exudyn_tuned_options_do_not_change_the_answer():
    """Modified Newton with one Jacobian per step and tolerance 1e-8: same mean efficiency as the
    defaults to 1e-7 on a friction scene (the bench's 'tuned' is a cost change only)."""
    scene = replace(named_scene("paper-literal-10deg"), **{"numerics.dt": 2 * math.pi / 209.44 / 200,
                                                    "revolutions": 1})
    a = engines.run(scene, "exudyn")
    b = engines.run(scene, "exudyn", EXUDYN_TUNED)
    assert a.success and b.success
    assert abs(a.summary.mean_efficiency - b.summary.mean_efficiency) < 1e-7




def test_the_cheapest_run_reads_every_level_and_never_a_nan():
    """The ok row of least wall time per simulated second within every level; a NaN error or a
    failed run never qualifies."""
    rows = pd.DataFrame([
        {"status": "ok", "speed_ratio_error": 1e-3, "torque_in_error_steady": 1e-4,
         "wall_per_simulated_s": 0.1},
        {"status": "ok", "speed_ratio_error": 1e-5, "torque_in_error_steady": 1e-3,
         "wall_per_simulated_s": 0.2},
        {"status": "ok", "speed_ratio_error": 1e-6, "torque_in_error_steady": 1e-5,
         "wall_per_simulated_s": 0.4},
        {"status": "ok", "speed_ratio_error": float("nan"), "torque_in_error_steady": 0.0,
         "wall_per_simulated_s": 0.01},
        {"status": "integration_failure", "speed_ratio_error": 0.0, "torque_in_error_steady": 0.0,
         "wall_per_simulated_s": 0.01},
    ])
    assert cheapest(rows, {"speed_ratio_error": 2e-5})["wall_per_simulated_s"] == 0.2
    both = cheapest(rows, {"speed_ratio_error": 2e-5, "torque_in_error_steady": 1e-4})
    assert both["wall_per_simulated_s"] == 0.4
    assert cheapest(rows, {"speed_ratio_error": 1e-9}) is None


def test_at_accuracy_reads_each_scenes_own_measure_and_level():
    """With friction the mean-efficiency error at the scene's ``numerics.accuracy``, without the
    speed-ratio error; a configuration no step of which reaches it says so (None)."""
    friction = replace(named_scene("paper-literal-10deg"), **{"numerics.accuracy": 1e-4})
    free = named_scene("paper-literal-10deg-frictionless")
    rows = pd.DataFrame([
        {"scene": "f", "config": "a", "steps_per_revolution": 100, "status": "ok",
         "mean_efficiency_error": 3e-4, "speed_ratio_error": 1e-9, "wall_per_simulated_s": 1.0},
        {"scene": "f", "config": "a", "steps_per_revolution": 200, "status": "ok",
         "mean_efficiency_error": 5e-5, "speed_ratio_error": 1e-9, "wall_per_simulated_s": 2.0},
        {"scene": "f", "config": "b", "steps_per_revolution": 100, "status": "ok",
         "mean_efficiency_error": 2e-4, "speed_ratio_error": 1e-9, "wall_per_simulated_s": 0.5},
        {"scene": "g", "config": "a", "steps_per_revolution": 50, "status": "ok",
         "mean_efficiency_error": float("nan"), "speed_ratio_error": 5e-4, "wall_per_simulated_s": 0.3},
    ])
    result = BenchResult(rows, {"f": friction, "g": free}, environment={})
    best = {(c["scene"], c["config"]): c for c in at_accuracy(result)}
    assert best[("f", "a")]["steps_per_revolution"] == 200 and best[("f", "a")]["error"] == 5e-5
    assert best[("f", "a")]["measure"] == "mean_efficiency_error" and best[("f", "a")]["accuracy"] == 1e-4
    assert best[("f", "b")]["steps_per_revolution"] is None
    assert best[("f", "b")]["fastest_wall_per_simulated_s"] == 0.5
    assert best[("g", "a")]["measure"] == "speed_ratio_error" and best[("g", "a")]["error"] == 5e-4


def test_a_scene_of_the_users_is_benched_with_its_own_configurations(tmp_path, capsys):
    """`cardan bench --name NAME` (any scene option): that scene alone, under its name, with the
    configurations of its kind (here with friction: every coupling), errors against the
    reference on it; the report names the command and the scene."""
    out = tmp_path / "mine"
    code = main(["bench", "--quick", "--name", "paper-literal-0deg", "--revolutions", "1",
                 "--engines", "exudyn,reference", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0
    table = pd.read_csv(out / "bench.csv", comment="#")
    name = "paper-literal-0deg-2000rpm+revolutions=1"
    assert set(table["scene"]) == {name}
    assert {"exudyn tuned lagged", "exudyn tuned extrapolated"} <= set(table["config"])
    assert (table["status"] == "ok").all() and table["mean_efficiency_error"].notna().all()
    assert "steps/rev: error" in text and name in text
    report = (out / "report.md").read_text()
    assert "--name paper-literal-0deg --revolutions 1" in report


def test_a_command_leaves_out_the_scene_options_it_sets_itself():
    """``add_scene_options(leave_out=...)``: the options are not offered and read as None, so the
    scene builds as without them; only options a command can set itself can be left out."""
    import argparse

    from cardan_exudyn.scene_options import add_scene_options, scene_from_args

    p = argparse.ArgumentParser()
    add_scene_options(p, leave_out=("dt", "coupling"))
    args = p.parse_args(["--name", "paper-literal-10deg"])
    assert args.dt is None and args.coupling is None
    assert scene_from_args(args) == named_scene("paper-literal-10deg")
    with pytest.raises(SystemExit):
        p.parse_args(["--dt", "1e-4"])
    with pytest.raises(ValueError, match="leave_out"):
        add_scene_options(argparse.ArgumentParser(), leave_out=("name",))


def test_the_default_scenes_are_the_fixed_set():
    """Without a scene option the bench runs the fixed set (``--scenes`` a subset of it, in the
    order given); an unknown key is refused."""
    assert list(fixed_scenes()) == list(SCENES)
    assert list(fixed_scenes(["friction-35deg", "frictionless-10deg"])) == ["friction-35deg",
                                                                           "frictionless-10deg"]
    with pytest.raises(BenchError, match="--scenes"):
        fixed_scenes(["friction-90deg"])
    assert check_inputs(["exudyn"], None, True) == (["exudyn"], 1)
    assert bench_command({"quick": True, "repeats": 1, "scenes": ["friction-10deg"],
                          "engines": ["exudyn"]}) == (
        "cardan bench --quick --repeats 1 --scenes friction-10deg --engines exudyn")
