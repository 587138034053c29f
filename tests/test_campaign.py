"""A campaign end to end on short synthetic recordings of a known joint: calibration, V&V 20 budget,
verdicts, journal and resume, a recording the model cannot run.

The recordings are written once per module from a stated truth (friction 0.12 in every pair); their
seeds are fixed, so each assertion is deterministic. The statistical check (intervals covering at the
stated rate over many seeds) is ``python tests/benchmarks campaign-coverage``.
"""

from __future__ import annotations

import json
import math
import os
import signal

import pytest
from processes import start, wait_for

from rigdata.campaign import campaign
from rigdata.campaign.journal import JOURNAL_FILE
from rigdata.synthetic import RigSettings, write
from rigdata.transducer import Transducer

TRUTH = 0.12
FRICTION_KEYS = [f"joint.pairs.{p}.friction_coefficient"
                 for p in ("frame_input", "input_spider", "spider_output", "output_frame")]
POINTS = [("c1", 10, 6.0, 1.0, "calibration"), ("c2", 25, 6.0, 2.0, "calibration"),
          ("v1", 15, 8.0, 1.5, "validation"), ("v2", 30, 5.0, 2.5, "validation")]


def campaign_text(points=POINTS, parameters=True, extra="") -> str:
    """A campaign file over ``points`` (reference engine, 200 draws)."""
    lines = ['engines = ["reference"]', "monte_carlo = 200", extra]
    if parameters:
        lines += ["[parameters.f]", f"keys = {FRICTION_KEYS}", "initial = 0.2", "bounds = [0.0, 0.6]"]
    lines += ["[transducers]", "full_scale = 5.0", "accuracy_class = 0.0005"]
    for name, angle, _, _, use in points:
        lines += ["[[recording]]", f'file = "{name}.csv"', f"shaft_angle_deg = {angle}", f'use = "{use}"']
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The four recordings and the campaign file."""
    path = tmp_path_factory.mktemp("campaign")
    transducer = Transducer(full_scale=5.0, accuracy_class=5e-4)
    for seed, (name, angle, speed, torque, _) in enumerate(POINTS, start=1):
        settings = RigSettings(shaft_angle_deg=angle, speed=speed, input_torque=torque, friction=TRUTH,
                               revolutions=2.5, noise=0.002, seed=seed)
        write(path / f"{name}.csv", "csv", settings, transducer)
    (path / "campaign.toml").write_text(campaign_text())
    return path


@pytest.fixture(scope="module")
def result(folder):
    """The campaign, journalled in ``folder/out``."""
    return campaign(folder / "campaign.toml", folder / "out", workers=1)


def test_calibration_recovers_the_truth_within_its_uncertainty(result):
    (estimate,) = result.calibration.estimates
    assert estimate.identifiable
    assert 0.0 < estimate.standard_uncertainty < 0.05
    assert abs(estimate.value - TRUTH) < 2.0 * estimate.standard_uncertainty
    assert result.calibration.dof == 1


def test_validation_recordings_have_unresolvable_model_error(result):
    """The model is the truth's: no validation recording resolves a model error."""
    assert [r.label for r in result.validation] == ["v1.csv", "v2.csv"]
    for r in result.validation:
        assert r.status == "ok"
        assert r.resolvable is False
        assert abs(r.first.comparison_error) <= r.k * r.first.u_val


def test_budget_adds_up_per_vv20(result):
    """u_val^2 = u_num^2 + u_input^2 + u_D^2 - 2 cov(S, D); u_input from its four parts; k for 95 %."""
    for r in result.recordings:
        b = r.budget
        u_num = r.first.u_num
        assert r.first.u_val == pytest.approx(
            math.sqrt(u_num**2 + b.u_input**2 + b.u_D**2 - 2 * b.covariance_SD), rel=1e-12)
        assert b.u_input == pytest.approx(
            math.sqrt(b.u_parameters**2 + b.u_inputs**2 + b.u_load**2 + b.u_phase**2), rel=1e-12)
        assert b.u_D == r.u_D
        assert r.first.comparison_error == r.first.simulated - r.measured
        assert r.k == pytest.approx(1.959964, abs=1e-6)


def test_parameter_uncertainty_propagates_by_its_sensitivity(result):
    """u_parameters = |dS/df| u_f for one parameter."""
    u_f = math.sqrt(result.calibration.covariance[0, 0])
    for r in result.recordings:
        assert r.budget.u_parameters == pytest.approx(abs(r.budget.sensitivities["f"]) * u_f, rel=1e-9)
        assert r.budget.sensitivities["f"] < 0  # more friction, less efficiency


def test_json_names_are_the_interface(result):
    s = result.as_dict()
    rec = s["recordings"][2]
    for key in ("file", "use", "simulated", "measured", "comparison_error", "u_num", "u_input", "u_D",
                "u_val", "k", "model_error_interval", "resolvable", "by_engine"):
        assert key in rec
    assert set(s["parameters"][0]) >= {"name", "value", "standard_uncertainty", "identifiable"}
    assert set(s["calibration"]) >= {"chi_square", "dof", "p_value", "rejected"}
    assert s["correlation"] == [[1.0]]


def test_second_run_reuses_every_model_run(folder, result):
    again = campaign(folder / "campaign.toml", folder / "out", workers=1)
    assert again.timing["model_runs"] == 0
    assert again.calibration.values == result.calibration.values
    assert [r.first.simulated for r in again.recordings] == [r.first.simulated for r in result.recordings]


def test_a_line_cut_by_a_crash_is_dropped_and_rerun(folder, result, tmp_path):
    """The journal's last line cut short (a kill mid-write): that run alone is made again."""
    out = tmp_path / "out"
    out.mkdir()
    text = (folder / "out" / JOURNAL_FILE).read_bytes()
    (out / JOURNAL_FILE).write_bytes(text[:-20])
    again = campaign(folder / "campaign.toml", out, workers=1)
    assert again.timing["model_runs"] == 1
    assert again.calibration.values == result.calibration.values


def test_a_changed_campaign_never_reuses_a_different_model(folder, tmp_path):
    """Changing the conditioning changes the measured drive: no run is taken from the journal."""
    out = tmp_path / "out"
    (folder / "cutoff.toml").write_text(campaign_text(extra="[conditioning]\ncutoff_harmonics = 12.0"))
    campaign(folder / "cutoff.toml", out, workers=1)
    (folder / "cutoff.toml").write_text(campaign_text())
    changed = campaign(folder / "cutoff.toml", out, workers=1)
    assert changed.timing["model_runs"] > 0


def test_a_recording_the_model_cannot_run_is_reported_and_the_rest_go_on(folder, tmp_path):
    """At 85 deg with friction 0.6 the joint self-locks: that recording says so; the others compare."""
    points = [*POINTS[2:], ("c1", 85, 6.0, 1.0, "validation")]
    text = campaign_text(points, parameters=False)
    text = text.replace('engines = ["reference"]',
                        'engines = ["reference"]\nscene = "locking.toml"')
    pairs = "\n".join(f"[joint.pairs.{p}]\nfriction_coefficient = 0.6"
                      for p in ("frame_input", "input_spider", "spider_output", "output_frame"))
    (folder / "locking.toml").write_text(f'base = "rig"\n{pairs}\n')
    (folder / "locking-campaign.toml").write_text(text)
    result = campaign(folder / "locking-campaign.toml", None, workers=1)
    statuses = {r.label: r.status for r in result.recordings}
    assert statuses == {"v1.csv": "ok", "v2.csv": "ok", "c1.csv": "model"}
    (locked,) = result.failed
    assert "self_locking" in locked.reason
    assert locked.resolvable is None
    assert result.calibration is None


@pytest.mark.slow
def test_a_dask_cluster_gives_the_local_results(folder, result):
    """On a two-process LocalCluster the campaign's numbers equal the in-process run's."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        remote = campaign(folder / "campaign.toml", None, scheduler=cluster.scheduler_address)
    assert remote.calibration.values == result.calibration.values
    assert [r.first.u_val for r in remote.recordings] == [r.first.u_val for r in result.recordings]


def test_the_monte_carlo_checks_each_measured_uncertainty(result):
    """Each recording carries its Monte Carlo draws' spread, an independent propagation of the same
    measurement model as the GUM u_D (200 draws: about 5 % sampling error)."""
    for r in result.recordings:
        mc = r.as_dict()["measured_monte_carlo"]
        assert mc["samples"] == 200
        assert mc["std"] == pytest.approx(r.u_D, rel=0.3)


def test_an_unreadable_recording_leaves_no_journal(folder, tmp_path):
    """Bad data are found before any model runs: nothing is written."""
    from rigdata.record import RigDataError

    (tmp_path / "bad.csv").write_text("not,a\nrig,file\n")
    text = campaign_text().replace(f'file = "{POINTS[3][0]}.csv"', f'file = "{tmp_path / "bad.csv"}"')
    (tmp_path / "campaign.toml").write_text(text.replace('file = "', f'file = "{folder}/', 3))
    with pytest.raises(RigDataError, match=r"\[\[recording\]\] 4"):
        campaign(tmp_path / "campaign.toml", tmp_path / "out", workers=1)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("signum", [signal.SIGINT, pytest.param(signal.SIGTERM, marks=pytest.mark.slow)])
def test_an_interrupted_campaign_keeps_its_runs_and_resumes(folder, tmp_path, signum):
    """A signal to the whole process group once some model runs are journalled: exit 128 + signal with one
    line saying how to resume, the journal's lines intact; the same command finishes, reusing them."""
    out = tmp_path / "out"
    journal = out / JOURNAL_FILE
    argv = ["rig", "campaign", str(folder / "campaign.toml"), "--out", str(out), "--workers", "2"]
    proc = start(argv, tmp_path)
    wait_for(lambda: journal.is_file() and journal.read_bytes().count(b"\n") >= 3, proc)
    os.killpg(proc.pid, signum)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signum, stderr
    assert "rerun the same command to resume" in stderr.splitlines()[-1] and "Traceback" not in stderr
    kept = journal.read_bytes().count(b"\n")
    assert kept >= 3
    again = start(argv + ["--json"], tmp_path)
    stdout, stderr = again.communicate(timeout=300)
    assert again.returncode == 0, stderr
    timing = json.loads(stdout)["timing"]
    assert timing["model_runs_reused"] >= kept


def test_the_command_prints_the_calibration_and_a_line_per_recording(folder, result, capsys):
    """``cardan rig campaign`` (journal reused): the estimate with two significant digits of its
    uncertainty, the test's verdict, a verdict per recording, and the report files."""
    from cardan_exudyn.cli import main

    status = main(["rig", "campaign", str(folder / "campaign.toml"), "--out", str(folder / "out"),
                   "--workers", "1"])
    lines = capsys.readouterr().out.splitlines()
    (estimate,) = result.calibration.estimates
    u = f"{estimate.standard_uncertainty:#.2g}"
    assert status == 0
    assert lines[0] == f"parameter f = {estimate.value:.4g} +- {u}"
    assert lines[1].startswith("calibration: chi-square ")
    assert [line.rsplit(": ", 1)[-1] for line in lines[2:]] == ["calibration", "calibration",
                                                              "not resolvable", "not resolvable"]
    assert all((folder / "out" / name).is_file() for name in ("report.html", "report.md", "results.json",
                                                             "results.csv", "model_error.png"))


def test_a_full_disk_is_one_line_and_the_rerun_resumes(folder, tmp_path):
    """The journal's disk full (a file-size limit) mid-calibration: exit 2, one line naming the journal;
    the runs written before are reused by the rerun."""
    import resource

    def small_files() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (3000, 3000))

    out = tmp_path / "out"
    argv = ["rig", "campaign", str(folder / "campaign.toml"), "--out", str(out), "--workers", "1"]
    proc = start(argv, tmp_path, preexec_fn=small_files)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2, stderr
    expected = f"cardan rig campaign: error: cannot write '{out / JOURNAL_FILE}': File too large"
    assert stderr.splitlines()[-1] == expected
    again = start([*argv, "--json"], tmp_path)
    stdout, stderr = again.communicate(timeout=120)
    assert again.returncode == 0, stderr
    assert json.loads(stdout)["timing"]["model_runs_reused"] > 0
