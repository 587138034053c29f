"""The sweep runner: expansion, records, failures, resume after a real kill, CLI, Dask."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cardan_exudyn.cli import main
from cardan_exudyn.sweep import (
    Distribution,
    RandomSpec,
    SweepError,
    SweepSpec,
    expand_cases,
    load_spec,
    make_plan,
    read_records,
    run_sweep,
    spec_from_mapping,
    summary_outputs,
)
from reference.scene.validation import SceneError

TESTS = Path(__file__).parent
# the reference engine at one revolution without a time table: ~0.05 s per case
BASE = {"scene": "paper-literal-10deg", "engine": "reference",
        "fixed": {"revolutions": 1, "record.timeseries": False}}
TIMING = ["case_wall_s", "wall_time_s"]


# Case functions: top level, so that worker processes import them as `test_sweep:<name>`.

def cheap_case(scene, engine):
    """A microsecond case: fails for load torque 13, reports a non-ok status for 7."""
    torque = scene.load.torque
    if torque == 13:
        raise ValueError("unlucky torque")
    if torque == 7:
        return {"status": "self_locking", "reason": "test", "torque": torque}
    return {"torque": torque, "square": torque**2, "engine": engine}


def scaled_case(scene, engine, factor=1.0, label="none"):
    """A case function with keyword arguments (the spec's `function_args`)."""
    return {"scaled": scene.load.torque * factor, "label": label, "pid": os.getpid()}


def dying_case(scene, engine):
    """The reference summary, but the process dies at the load torque named by SWEEP_TEST_DIE_AT,
    and each case sleeps SWEEP_TEST_SLEEP seconds."""
    time.sleep(float(os.environ.get("SWEEP_TEST_SLEEP", "0")))
    if str(scene.load.torque) == os.environ.get("SWEEP_TEST_DIE_AT"):
        os._exit(17)
    return summary_outputs(scene, engine)


def torque_spec(values, function="test_sweep:cheap_case", **extra):
    return {**BASE, "function": function, "grid": {"load.torque": list(values)}, **extra}


def table(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "results.csv")


def assert_same_results(a: Path, b: Path) -> None:
    """The two result tables agree in every column except the wall times."""
    ta, tb = table(a), table(b)
    pd.testing.assert_frame_equal(ta.drop(columns=TIMING, errors="ignore"),
                                  tb.drop(columns=TIMING, errors="ignore"))


def cardan_sweep(*args: str, env: dict | None = None, **kwargs) -> subprocess.Popen:
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(TESTS.parent)]),
                   **(env or {})}
    return subprocess.Popen([sys.executable, "-m", "cardan_exudyn.cli", "sweep", *args],
                            env=environment, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kwargs)


def write_spec(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path




def test_grid_is_the_cartesian_product_last_path_fastest():
    """A grid of a list, a linspace and engines gives every combination, in order, with ids."""
    spec = spec_from_mapping({**BASE, "grid": {"joint.geometry.shaft_angle_deg": [0, 10],
                                               "drive.speed_rpm": {"linspace": [500, 2000, 3]},
                                               "engine": ["reference", "exudyn"]}})
    cases = expand_cases(spec)
    assert len(cases) == 12
    assert [c.id for c in cases[:2]] == ["0000", "0001"]
    assert [c.engine for c in cases[:4]] == ["reference", "exudyn", "reference", "exudyn"]
    assert cases[2].overrides == {"joint.geometry.shaft_angle_deg": 0, "drive.speed_rpm": 1250.0}
    assert cases[-1].overrides == {"joint.geometry.shaft_angle_deg": 10, "drive.speed_rpm": 2000.0}


def test_unquoted_dotted_keys_and_explicit_cases():
    """TOML's unquoted dotted keys mean the dotted path; explicit cases keep their ids and engines."""
    nested = spec_from_mapping({**BASE, "grid": {"joint": {"geometry": {"shaft_angle_deg": [1, 2]}}}})
    assert expand_cases(nested)[1].overrides == {"joint.geometry.shaft_angle_deg": 2}
    spec = spec_from_mapping({**BASE, "cases": [{"id": "a", "load.torque": 1.0},
                                                {"engine": "exudyn", "load.torque": 2.0}]})
    assert [(c.id, c.engine, c.overrides) for c in expand_cases(spec)] == [
        ("a", "reference", {"load.torque": 1.0}), ("0001", "exudyn", {"load.torque": 2.0})]


RANDOM = {
    "uniform": Distribution("uniform", low=2.0, high=5.0),
    "normal": Distribution("normal", mean=0.4, std=0.05),
    "truncated": Distribution("normal", mean=0.4, std=0.05, low=0.35, high=0.5),
    "loguniform": Distribution("loguniform", low=1e-4, high=1e-2),
}


@pytest.mark.parametrize("method", ["random", "lhs"])
def test_random_samples_are_reproducible_and_follow_their_distributions(method):
    """Same seed, same samples; each marginal matches its distribution (KS test at 1e-3), bounds hold;
    a Latin hypercube puts exactly one sample in each of the N equal-probability strata."""
    from scipy import stats

    n = 400
    spec = RandomSpec(n, 7, dict(RANDOM), method)
    points = spec.points()
    assert points == RandomSpec(n, 7, dict(RANDOM), method).points()
    assert points != RandomSpec(n, 8, dict(RANDOM), method).points()
    x = {k: np.array([p[k] for p in points]) for k in RANDOM}
    cdfs = {"uniform": stats.uniform(2.0, 3.0).cdf, "normal": stats.norm(0.4, 0.05).cdf,
            "truncated": stats.truncnorm(-1.0, 2.0, loc=0.4, scale=0.05).cdf,
            "loguniform": stats.loguniform(1e-4, 1e-2).cdf}
    for key, cdf in cdfs.items():
        assert stats.kstest(x[key], cdf).pvalue > 1e-3, key
    assert x["truncated"].min() >= 0.35 and x["truncated"].max() <= 0.5
    assert 2.0 <= x["uniform"].min() and x["uniform"].max() < 5.0
    if method == "lhs":
        for key, cdf in cdfs.items():
            strata = np.floor(cdf(x[key]) * n).astype(int)
            assert sorted(strata) == list(range(n)), key


def test_grid_times_random_gives_every_sample_at_every_grid_point():
    """With both, each grid point takes the same N samples (common random numbers)."""
    spec = spec_from_mapping({**BASE, "grid": {"joint.geometry.shaft_angle_deg": [5, 15]},
                              "random": {"samples": 3, "seed": 1, "parameters": {
                                  "load.torque": {"dist": "uniform", "low": 1, "high": 3}}}})
    cases = expand_cases(spec)
    assert len(cases) == 6
    first = [c.overrides["load.torque"] for c in cases[:3]]
    assert first == [c.overrides["load.torque"] for c in cases[3:]]
    assert [c.overrides["joint.geometry.shaft_angle_deg"] for c in cases] == [5, 5, 5, 15, 15, 15]


def _random(**param):
    return {**BASE, "random": {"samples": 4, "seed": 0, "parameters": {"load.torque": param}}}


BAD_SPECS = [
    (_random(dist="gamma", low=0, high=1), SweepError, "`dist` must be one of"),
    (_random(dist="normal", mean=1, std=-0.1), SweepError, "`std` must be positive, got -0.1"),
    (_random(dist="uniform", low=2, high=1), SweepError, "`low` must be below `high`"),
    (_random(dist="uniform", low=0), SweepError, "'uniform' needs \\['low', 'high'\\]"),
    (_random(low=0, high=1), SweepError, "needs `dist`"),
    (_random(dist="uniform", low=0, high=1, std=1), SweepError, "`std` is not a parameter of 'uniform'"),
    ({**BASE, "random": {"samples": 4, "parameters": {"load.torque": {"dist": "uniform", "low": 0,
                                                                      "high": 1}}}},
     SweepError, "`seed` is required"),
    ({**BASE, "grid": {"load.torque": []}}, SweepError, "is an empty list"),
    ({**BASE, "grid": {"load.torque": {"linspace": [0, 1]}}}, SweepError, "needs \\[start, stop, num\\]"),
    ({**BASE, "grid": {"load.torque": {"linspce": [0, 1, 3]}}}, SceneError,
     "unknown scene field 'load.torque.linspce'"),
    ({**BASE, "grid": {"load.torque": {"linspace": [0, 1, 3], "num": 1}}}, SweepError,
     "must be a list or one of"),
    ({**BASE, "grid": {}}, SweepError, "nothing to sweep"),
    ({**BASE, "grid": {"load.torque": [1]}, "cases": [{}]}, SweepError, "either `cases` or"),
    ({**BASE, "grid": {"load.torque": [1]}, "wat": 1}, SweepError, "unknown key\\(s\\) \\['wat'\\]"),
    ({**BASE, "fixed": {"load.torque": 1}, "grid": {"load.torque": [1]}}, SweepError, "in both"),
    ({**BASE, "grid": {"load.torque": [1]}, "function": "math:nope"}, SweepError, "cannot be imported"),
    ({**BASE, "grid": {"load.torque": [1]}, "function": lambda s, e: {}}, SweepError, "top-level"),
    ({**BASE, "engine": "warp", "grid": {"load.torque": [1]}}, ValueError, "must be one of"),
    ({**BASE, "scene": "nope", "grid": {"load.torque": [1]}}, SceneError, "unknown scene name"),
    ({**BASE, "grid": {"joint.geometry.shaft_angel_deg": [1]}}, SceneError,
     "case 0000: .*unknown key\\(s\\) \\['shaft_angel_deg'\\]"),
    ({**BASE, "grid": {"joint.geometry.shaft_angle_deg": [10, 95]}}, SceneError,
     "value 95: .*must be in \\[0, 90\\) deg"),
    ({**BASE, "random": {"samples": 4, "seed": 0, "parameters": {
        "joint.pairs.input_spider.friction_coefficient": {"dist": "normal", "mean": 0.05, "std": 0.02}}}},
     SceneError, "1e-09 quantile .*truncate"),
    ({**BASE, "grid": {"load.torque": [1]}, "function_args": [1]}, SweepError,
     "`function_args` must be a table"),
    ({**BASE, "grid": {"load.torque": [1]}, "function_args": {"engine": "reference"}}, SweepError,
     "cannot set `engine`"),
    ({**BASE, "grid": {"load.torque": [1]}, "function_args": {"x": object()}}, SweepError,
     "must hold JSON values"),
]


@pytest.mark.parametrize("data, error, match", BAD_SPECS, ids=[m for _, _, m in BAD_SPECS])
def test_bad_specs_are_refused_up_front(data, error, match):
    """Every invalid spec raises before any case runs, naming the key."""
    with pytest.raises(error, match=match):
        make_plan(data)




def test_reference_sweep_records_the_summary_and_writes_the_table(tmp_path):
    """Each record carries the engine's scalar summary (equal to a direct run); the table has the
    parameters as columns and sweep.json the statistics over the cases."""
    from cardan_exudyn import engines
    from reference.paper.scenes import named_scene
    from reference.scene.mapping import replace

    angles = [0, 10, 20]
    summary = run_sweep({**BASE, "grid": {"joint.geometry.shaft_angle_deg": angles}}, tmp_path, workers=1)
    assert (summary["cases"], summary["ok"], summary["failed"]) == (3, 3, 0)
    t = table(tmp_path)
    assert list(t.columns[:4]) == ["id", "engine", "joint.geometry.shaft_angle_deg", "status"]
    assert t["joint.geometry.shaft_angle_deg"].tolist() == angles
    assert "scene" not in t and "quadrature.evaluations" in t
    direct = engines.run(replace(named_scene("paper-literal-10deg"), revolutions=1,
                                 **{"record.timeseries": False, "joint.geometry.shaft_angle_deg": 20}),
                         "reference").summary
    assert t["mean_efficiency"].iloc[2] == direct.mean_efficiency
    stats = json.loads((tmp_path / "sweep.json").read_text())["statistics"]["mean_efficiency"]
    eta = t["mean_efficiency"].to_numpy()
    assert stats["n"] == 3 and stats["mean"] == pytest.approx(eta.mean(), rel=1e-15)
    assert stats["std"] == pytest.approx(eta.std(ddof=1), rel=1e-12) and stats["max"] == eta.max()


def test_failing_cases_are_recorded_while_the_others_complete(tmp_path):
    """An exception and a non-ok status are recorded with their reason; the rest run; a retry
    reruns only the failed ones."""
    summary = run_sweep(torque_spec([1, 13, 2, 7, 3]), tmp_path, workers=1)
    assert summary["failed"] == 2 and summary["failed_ids"] == ["0001", "0003"]
    assert summary["status_counts"] == {"ok": 3, "error": 1, "self_locking": 1}
    records = read_records(tmp_path / "cases.jsonl")
    assert records["0001"]["error_type"] == "ValueError" and records["0001"]["error"] == "unlucky torque"
    assert "cheap_case" in records["0001"]["traceback"]
    assert (records["0003"]["status"], records["0003"]["reason"]) == ("self_locking", "test")
    assert [records[i]["square"] for i in ("0000", "0002", "0004")] == [1, 4, 9]
    again = run_sweep(torque_spec([1, 13, 2, 7, 3]), tmp_path, workers=1, retry_failed=True)
    assert again["run_now"] == 2 and again["failed"] == 2
    assert len((tmp_path / "cases.jsonl").read_text().splitlines()) == 7


def test_a_crashing_worker_is_recorded_and_the_pool_goes_on(tmp_path):
    """Two processes; a case that kills its process (os._exit) is recorded as WorkerCrash, every
    other case completes with the same results as in-process."""
    spec = torque_spec([1.0, 2.0, 3.0, 4.0, 5.0], function="test_sweep:dying_case")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SWEEP_TEST_DIE_AT", "3.0")
        summary = run_sweep(spec, tmp_path / "pool", workers=2)
    assert summary["executor"] == {"kind": "processes", "workers": 2}
    assert summary["failed_ids"] == ["0002"]
    assert read_records(tmp_path / "pool" / "cases.jsonl")["0002"]["error_type"] == "WorkerCrash"
    local = run_sweep(torque_spec([1.0, 2.0, 4.0, 5.0], function="test_sweep:dying_case"),
                      tmp_path / "local", workers=1)
    assert local["ok"] == 4
    pool = read_records(tmp_path / "pool" / "cases.jsonl")
    for a, b in zip((pool[i] for i in ("0000", "0001", "0003", "0004")),
                    read_records(tmp_path / "local" / "cases.jsonl").values(), strict=True):
        assert {k: v for k, v in a.items() if k not in ("id", *TIMING)} == {
            k: v for k, v in b.items() if k not in ("id", *TIMING)}


def _wait_for_records(path: Path, count: int, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists() and path.read_bytes().count(b"\n") >= count:
            return
        if proc.poll() is not None:
            raise AssertionError(f"the sweep ended before {count} records: {proc.stderr.read()}")
        time.sleep(0.01)
    raise AssertionError(f"no {count} records after {timeout} s")


def test_resume_after_kill_runs_only_the_missing_cases(tmp_path):
    """SIGKILL the driver and its two workers after three records; the same command resumes,
    runs only the missing cases, and the table equals an uninterrupted run's."""
    spec = write_spec(tmp_path / "spec.toml", """
scene = "paper-literal-10deg"
engine = "reference"
function = "test_sweep:dying_case"
[fixed]
revolutions = 1
"record.timeseries" = false
[grid]
"joint.geometry.shaft_angle_deg" = [0, 5, 10, 15]
"load.torque" = [1, 2, 3]
""")
    out = tmp_path / "out"
    proc = cardan_sweep(str(spec), "--out", str(out), "--workers", "2",
                        env={"SWEEP_TEST_SLEEP": "0.15"}, start_new_session=True)
    try:
        _wait_for_records(out / "cases.jsonl", 3, proc)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    before = set(read_records(out / "cases.jsonl"))
    assert 3 <= len(before) < 12 and not (out / "results.csv").exists()
    proc = cardan_sweep(str(spec), "--out", str(out), "--workers", "1", "--json")
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    assert json.loads(stdout)["run_now"] == 12 - len(before)
    lines = (out / "cases.jsonl").read_text().splitlines()
    new_ids = [json.loads(line)["id"] for line in lines[len(before):]]
    assert sorted(new_ids) == sorted({f"{i:04d}" for i in range(12)} - before)
    assert main(["sweep", str(spec), "--out", str(tmp_path / "whole"), "--workers", "1", "--quiet"]) == 0
    assert_same_results(out, tmp_path / "whole")


def test_resume_after_the_driver_dies_mid_case(tmp_path):
    """In-process, the process dies (os._exit) during the fourth case: exactly three records
    survive, and the rerun runs the other cases only."""
    spec = write_spec(tmp_path / "spec.toml", """
scene = "paper-literal-10deg"
engine = "reference"
function = "test_sweep:dying_case"
fixed = { revolutions = 1 }
grid = { "load.torque" = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0] }
""")
    proc = cardan_sweep(str(spec), "--out", str(tmp_path / "out"), "--workers", "1",
                        env={"SWEEP_TEST_DIE_AT": "4.0"})
    proc.communicate(timeout=120)
    assert proc.returncode == 17
    assert sorted(read_records(tmp_path / "out" / "cases.jsonl")) == ["0000", "0001", "0002"]
    summary = run_sweep(load_spec(spec), tmp_path / "out", workers=1)
    assert summary["run_now"] == 3 and summary["ok"] == 6


def test_a_torn_last_line_is_dropped_on_resume(tmp_path):
    """A record cut short by a kill (no newline) is ignored and cut off; its case runs again and the
    file is valid JSON lines afterwards."""
    spec = torque_spec([1, 2, 3, 4])
    run_sweep(spec, tmp_path, workers=1)
    path = tmp_path / "cases.jsonl"
    lines = path.read_bytes().splitlines(keepends=True)
    path.write_bytes(b"".join(lines[:2]) + lines[2][:25])
    assert sorted(read_records(path)) == ["0000", "0001"]
    summary = run_sweep(spec, tmp_path, workers=1)
    assert summary["run_now"] == 2 and summary["done"] == 4
    ids = [json.loads(line)["id"] for line in path.read_text().splitlines()]
    assert ids == ["0000", "0001", "0002", "0003"]
    assert table(tmp_path)["square"].tolist() == [1, 4, 9, 16]


def test_a_different_spec_is_refused_on_resume(tmp_path):
    """Another grid, function or base scene in the same folder is refused (nothing touched);
    --restart starts over."""
    run_sweep(torque_spec([1, 2, 3]), tmp_path, workers=1)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    for spec, match in ((torque_spec([1, 2, 4]), "case 0002"),
                        (torque_spec([1, 2]), "3 cases then, 2 now"),
                        ({**torque_spec([1, 2, 3]), "fixed": {"revolutions": 2}}, "the base scene differs"),
                        (torque_spec([1, 2, 3], function="test_sweep:dying_case"), "case function")):
        with pytest.raises(SweepError, match=f"holds a different sweep \\({match}"):
            run_sweep(spec, tmp_path, workers=1)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    summary = run_sweep(torque_spec([1, 2, 4]), tmp_path, workers=1, restart=True)
    assert summary["run_now"] == 3 and table(tmp_path)["square"].tolist() == [1, 4, 16]


def test_function_args_reach_the_case_function_in_worker_processes(tmp_path):
    """`function_args` are keyword arguments of the case function, in spawned worker processes
    too; they are part of the plan (another value is refused on resume, the same resumes) and of
    sweep.json's spec."""
    spec = torque_spec([1, 2, 3], function="test_sweep:scaled_case",
                       function_args={"factor": 10, "label": "ten"})
    summary = run_sweep(spec, tmp_path, workers=2)
    t = table(tmp_path)
    assert t["scaled"].tolist() == [10, 20, 30] and set(t["label"]) == {"ten"}
    assert os.getpid() not in set(t["pid"])
    assert summary["spec"]["function_args"] == {"factor": 10, "label": "ten"}
    assert json.loads((tmp_path / "plan.json").read_text())["function_args"] == {"factor": 10, "label": "ten"}
    with pytest.raises(SweepError, match="holds a different sweep \\(case function arguments"):
        run_sweep({**spec, "function_args": {"factor": 2}}, tmp_path, workers=1)
    assert run_sweep(spec, tmp_path, workers=1)["run_now"] == 0


def test_the_default_function_by_either_name_is_one_plan(tmp_path):
    """The default case function named by the public face (the default) or passed as the
    function object (named by its module) is the same plan: the sweep resumes."""
    spec = {**BASE, "grid": {"joint.geometry.shaft_angle_deg": [0, 10]}}
    first = run_sweep(spec, tmp_path, workers=1)
    assert first["spec"]["function"] == "cardan_exudyn.sweep:summary_outputs"
    again = run_sweep({**spec, "function": summary_outputs}, tmp_path, workers=1)
    assert again["run_now"] == 0 and again["ok"] == 2


def test_progress_shows_cases_failures_and_eta(tmp_path, capsys):
    """The progress bar on stderr counts cases and failures; off by default outside a terminal."""
    run_sweep(torque_spec([1, 13, 2]), tmp_path / "a", workers=1, progress=True)
    err = capsys.readouterr().err
    assert "3/3" in err and "failed=1" in err and "<" in err
    run_sweep(torque_spec([1, 13, 2]), tmp_path / "b", workers=1)
    assert capsys.readouterr().err == ""




def test_cli_exit_codes_and_json(tmp_path, capsys):
    """Exit 0 when every case is ok, 3 when some failed (files still written); --json prints
    sweep.json on stdout and nothing else."""
    spec = write_spec(tmp_path / "spec.toml", """
scene = "paper-literal-10deg"
engine = "reference"
function = "test_sweep:cheap_case"
[grid]
"load.torque" = [1, 2]
""")
    assert main(["sweep", str(spec), "--out", str(tmp_path / "ok"), "--workers", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out == json.loads((tmp_path / "ok" / "sweep.json").read_text())
    assert out["ok"] == 2 and out["spec"]["grid"] == {"load.torque": [1, 2]}
    args = ["sweep", str(spec), "--out", str(tmp_path / "bad"), "--workers", "1",
            "--grid", "load.torque=1,13", "--set", "revolutions=1"]
    assert main(args) == 3
    captured = capsys.readouterr()
    assert captured.out == "" and "1 ok, 1 error" in captured.err
    assert table(tmp_path / "bad")["status"].tolist() == ["ok", "error"]


BAD_CLI = [
    (["--scene", "paper-literal-10deg", "--grid", "joint.geometry.shaft_angel_deg=1,2"], "unknown key(s)"),
    (["--scene", "paper-literal-10deg", "--grid", "load.torque"], "--grid must look like PATH=V1,V2"),
    (["--scene", "paper-literal-10deg"], "nothing to sweep"),
    (["--grid", "load.torque=1"], "`scene` is required"),
    (["/nonexistent.toml"], "cannot read sweep spec"),
]


@pytest.mark.parametrize("args, message", BAD_CLI, ids=[m for _, m in BAD_CLI])
def test_cli_bad_input_exits_2_and_writes_nothing(tmp_path, args, message):
    """Bad input: exit 2, one line on stderr, no traceback, no output folder."""
    proc = cardan_sweep(*args, "--out", str(tmp_path / "out"), "--engine", "reference")
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2
    assert message in stderr and len(stderr.strip().splitlines()) == 1
    assert "Traceback" not in stderr and stdout == ""
    assert not (tmp_path / "out").exists()




def test_dask_cluster_gives_the_local_results(tmp_path, monkeypatch):
    """On a real two-process LocalCluster over loopback the records equal the in-process run's,
    failures included; a case that kills its worker is recorded as KilledWorker."""
    distributed = pytest.importorskip("distributed")
    import dask

    spec = {**BASE, "grid": {"joint.geometry.shaft_angle_deg": [0, 15, 30],
                             "load.torque": [1.0, 2.0]}}
    failing = torque_spec([1, 13, 7])
    run_sweep(spec, tmp_path / "local", workers=1)
    run_sweep(failing, tmp_path / "local-failing", workers=1)
    monkeypatch.setenv("SWEEP_TEST_DIE_AT", "3.0")  # read by the workers' dying_case
    # one death makes a KilledWorker (Dask's default retries the task on three workers)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address=None) as cluster:
        summary = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address)
        failed = run_sweep(failing, tmp_path / "dask-failing", scheduler=cluster.scheduler_address)
        crashed = run_sweep(torque_spec([1.0, 3.0, 2.0], function="test_sweep:dying_case"),
                            tmp_path / "dask-crash", scheduler=cluster.scheduler_address)
    assert summary["executor"]["kind"] == "dask" and summary["executor"]["threads"] == 2
    assert summary["ok"] == 6 and failed["failed_ids"] == ["0001", "0002"]
    assert crashed["failed_ids"] == ["0001"] and crashed["ok"] == 2
    assert read_records(tmp_path / "dask-crash" / "cases.jsonl")["0001"]["error_type"] == "KilledWorker"
    assert_same_results(tmp_path / "local", tmp_path / "dask")
    assert_same_results(tmp_path / "local-failing", tmp_path / "dask-failing")


def test_summary_outputs_are_scalars():
    """The default case function keeps numbers and strings, flattens small tables, drops the scene."""
    from reference.paper.scenes import named_scene
    from reference.scene.mapping import replace

    out = summary_outputs(replace(named_scene("paper-literal-10deg"), revolutions=1), "reference")
    assert "scene" not in out and out["status"] == "ok"
    assert all(v is None or isinstance(v, (str, bool, int, float)) for v in out.values())
    assert math.isfinite(out["mean_efficiency"]) and "quadrature.evaluations" in out


def test_sweep_spec_object_and_scene_object(tmp_path):
    """Programmatic use: a SweepSpec with a Scene and explicit cases."""
    from reference.paper.scenes import named_scene

    spec = SweepSpec(scene=named_scene("rig-literal"), engine="reference", function=cheap_case,
                     cases=({"id": "x", "load.torque": 2.0}, {"id": "y", "load.torque": 13.0}))
    summary = run_sweep(spec, tmp_path, workers=1)
    assert summary["failed_ids"] == ["y"] and summary["spec"]["function"] == "test_sweep:cheap_case"
    assert table(tmp_path)["id"].tolist() == ["x", "y"]


def test_a_pool_broken_between_two_submissions_ends_the_round_cleanly(monkeypatch):
    """A worker can die after the last wait and before the next submission: `submit` then raises
    BrokenProcessPool (seen once in CI). The task not yet submitted goes back to the queue, the
    finished ones are emitted, the ones in flight are returned for the one-at-a-time rerun."""
    import contextlib
    from collections import deque
    from concurrent.futures import Future
    from concurrent.futures.process import BrokenProcessPool

    from cardan_exudyn.sweep import executors

    class Pool:
        def __init__(self):
            self.calls = 0

        def submit(self, fn, task, *args):
            self.calls += 1
            if self.calls == 3:
                raise BrokenProcessPool("a child process terminated abruptly")
            future = Future()
            if task == "done":
                future.set_result([{"id": task}])
            return future

    monkeypatch.setattr(executors, "_pool", lambda workers, context: contextlib.nullcontext(Pool()))
    queue, emitted = deque(["done", "flying", "unsent", "later"]), []
    victims = executors._pool_round(queue, None, None, 2, None, emitted.append)
    assert emitted == [[{"id": "done"}]]
    assert victims == ["flying"]
    assert list(queue) == ["unsent", "later"]
