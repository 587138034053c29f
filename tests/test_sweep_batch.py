"""Sweeps in batches (issue 20): reference cases run through the batched engine, records per case."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from processes import wait_for

import reference.engine.batch.solve
import reference.engine.solve
from cardan_exudyn import engines
from cardan_exudyn.sweep import (
    Batch,
    CaseFunction,
    expand_cases,
    plan_tasks,
    read_records,
    run_sweep,
    spec_from_mapping,
)
from reference.paper.scenes import named_scene
from reference.scene.mapping import replace
from reference.scene.validation import SceneError

TESTS = Path(__file__).parent
# the reference engine at one revolution without a time table: ~0.05 s per case
BASE = {"scene": "paper-literal-10deg", "engine": "reference",
        "fixed": {"revolutions": 1, "record.timeseries": False}}
# what may differ between a batched and a single run: wall times, and the quadrature's own
# counters and error estimates where the batched pass adapts differently (reference/engine/batch/solve.py)
COSTS = ("case_wall_s", "wall_time_s", "quadrature.")
# the quadrature accepts each work integral to 1e-9 of the input work (ReferenceOptions); an
# efficiency 1 - W_loss / W_in carries both errors
AGREEMENT = 2e-9


def torques(n: int, **extra) -> dict:
    return {**BASE, "grid": {"load.torque": [1.0 + 0.25 * i for i in range(n)]}, **extra}


@pytest.fixture
def batches(monkeypatch):
    """Sizes of the reference engine's batched runs in this process. Scenes the contract lets run
    on their own (key None, as today's loop says of every scene) are given a common key, so that
    they do run through ``reference.engine.batch.solve.run_batch``."""
    sizes: list[int] = []
    real_key, real_run = reference.engine.batch.solve.batch_key, reference.engine.batch.solve.run_batch

    def key(scene):
        k = real_key(scene)
        return ("test",) if k is None else k

    def run(scenes, options=None):
        sizes.append(len(scenes))
        return real_run(scenes, options)

    monkeypatch.setattr(reference.engine.batch.solve, "batch_key", key)
    monkeypatch.setattr(reference.engine.batch.solve, "run_batch", run)
    return sizes


def assert_same_records(a: dict, b: dict) -> None:
    """Same cases, keys, statuses and texts; numbers within AGREEMENT; costs aside."""
    assert sorted(a) == sorted(b)
    for case_id in a:
        x, y = a[case_id], b[case_id]
        assert sorted(x) == sorted(y), case_id
        for key in x:
            if key.startswith(COSTS):
                continue
            if isinstance(x[key], float) and isinstance(y[key], float):
                assert math.isclose(x[key], y[key], rel_tol=AGREEMENT, abs_tol=AGREEMENT), (case_id, key)
            else:
                assert x[key] == y[key], (case_id, key)


def test_reference_cases_run_in_batches_with_the_records_of_single_runs(tmp_path, batches):
    """Eight reference cases in this process run as four batches of two (a quarter of the cases
    per batch, BATCHES_PER_WORKER), and give the records of the same sweep without batches."""
    summary = run_sweep(torques(8), tmp_path / "batched", workers=1)
    assert batches == [2, 2, 2, 2]
    assert summary["batching"] == {"batches": 4, "batched_cases": 8, "largest_batch": 2}
    batches.clear()
    single = run_sweep(torques(8), tmp_path / "single", workers=1, batch_size=1)
    assert batches == [] and single["batching"]["batches"] == 0
    assert summary["ok"] == single["ok"] == 8
    batched = read_records(tmp_path / "batched" / "cases.jsonl")
    assert_same_records(batched, read_records(tmp_path / "single" / "cases.jsonl"))
    # a batched case's wall time is its share of the batch: equal within each pair of cases
    walls = [batched[f"{i:04d}"]["case_wall_s"] for i in range(8)]
    assert walls[0] == walls[1] and walls[2] == walls[3] and all(w > 0 for w in walls)


def test_engines_run_batch_equals_run_in_order():
    """The dispatch's run_batch returns one result per scene, in order, equal to run's; scenes of
    different keys (with and without friction) are split, and bad input names the scene."""
    base = replace(named_scene("paper-literal-10deg"), revolutions=1, **{"record.timeseries": False})
    scenes = [replace(base, **{"load.torque": t}) for t in (1.0, 2.0)] + [
        replace(named_scene("paper-literal-35deg-frictionless"), revolutions=1)]
    results = engines.run_batch(scenes, "reference")
    singles = [engines.run(s, "reference") for s in scenes]
    assert [r.summary.input_work for r in results] == pytest.approx(
        [r.summary.input_work for r in singles], rel=AGREEMENT)
    assert engines.run_batch([], "reference") == []
    with pytest.raises(TypeError, match=r"`scenes\[1\]` must be a Scene"):
        engines.run_batch([base, "paper-literal-10deg"], "reference")
    with pytest.raises(TypeError, match="`scenes` must be a sequence"):
        engines.run_batch(base, "reference")
    with pytest.raises(engines.EngineUnavailable, match="`engine` must be one of"):
        engines.run_batch([base], "nope")
    assert engines.batch_key(base, "exudyn") is None and not engines.has_batch("mujoco")


def test_engines_run_batch_refuses_a_long_scene_by_its_index_before_running(monkeypatch):
    """An over-long scene behind scenes of other keys (a torque drive runs on its own) is named by
    its index in the caller's list, and nothing runs first (it was named by its index within its
    group, after the other groups had run)."""
    ran = []

    def chunk(scenes, options):
        ran.append(scenes)
        return [None] * len(scenes)

    monkeypatch.setattr(reference.engine.batch.solve, "_run_chunk", chunk)
    base = named_scene("paper-10deg")
    scenes = [named_scene("rig-errors"),
              replace(base, drive={"kind": "torque", "torque": 2.0, "initial_speed": 209.0}),
              base, replace(base, **{"numerics.dt": 1e-10})]
    with pytest.raises(SceneError, match=r"^scenes\[3\]: "):
        engines.run_batch(scenes, "reference")
    assert ran == []


def test_a_failing_case_in_a_batch_records_only_itself(tmp_path, batches, monkeypatch):
    """An exception inside a batch (here: load torque 2.0 makes the engine raise) reruns the
    batch's cases one by one: the case that raises is recorded as an error, its batch-mate ok."""
    real_batch, real_run = reference.engine.batch.solve.run_batch, reference.engine.solve.run

    def raising(scene, options=None):
        if scene.load.torque == 2.0:
            raise RuntimeError("engine failure for this scene")
        return real_run(scene, options)

    def batch(scenes, options=None):
        if any(s.load.torque == 2.0 for s in scenes):
            raise RuntimeError("engine failure in this batch")
        return real_batch(scenes, options)

    monkeypatch.setattr(reference.engine.batch.solve, "run_batch", batch)
    monkeypatch.setattr(reference.engine.solve, "run", raising)
    summary = run_sweep(torques(8), tmp_path / "out", workers=1)
    records = read_records(tmp_path / "out" / "cases.jsonl")
    assert summary["failed_ids"] == ["0004"] and summary["ok"] == 7
    assert records["0004"]["error_type"] == "RuntimeError" and "this scene" in records["0004"]["error"]
    assert records["0005"]["status"] == "ok"  # the failing case's batch-mate


def test_resume_runs_only_the_missing_cases_in_batches(tmp_path, batches):
    """After a partial run (eight of sixteen records), the rerun batches the missing cases only."""
    out = tmp_path / "out"
    run_sweep(torques(16), out, workers=1)
    lines = (out / "cases.jsonl").read_text().splitlines()
    (out / "cases.jsonl").write_text("\n".join(lines[:8]) + "\n")
    batches.clear()
    summary = run_sweep(torques(16), out, workers=1)
    assert summary["run_now"] == 8 and summary["ok"] == 16 and batches == [2, 2, 2, 2]
    assert len((out / "cases.jsonl").read_text().splitlines()) == 16


def test_custom_functions_and_other_engines_are_not_batched():
    """Only the default case function without arguments, on an engine with a batched pass."""
    spec = spec_from_mapping({**torques(8), "grid": {"load.torque": [1.0, 2.0, 3.0, 4.0, 5.0],
                                                      "engine": ["reference", "exudyn"]}})
    cases = expand_cases(spec)
    tasks = plan_tasks(cases, spec.case_function(), workers=1)
    assert [len(t.cases) for t in tasks if isinstance(t, Batch)] == [2, 2]
    assert sorted(c.engine for c in tasks if not isinstance(c, Batch)) == ["exudyn"] * 5 + ["reference"]
    for function in (CaseFunction("test_sweep:cheap_case"),
                     CaseFunction("cardan_exudyn.sweep:summary_outputs", {"unused": 1})):
        assert not any(isinstance(t, Batch) for t in plan_tasks(cases, function, workers=1))
    assert not any(isinstance(t, Batch) for t in plan_tasks(cases, spec.case_function(), 1, batch_size=1))
    sizes = [len(t.cases) for t in plan_tasks(cases * 1000, spec.case_function(), 2) if isinstance(t, Batch)]
    assert max(sizes) == 625  # 5000 reference cases over 2 workers x 4 batches each


INTERRUPTED = """
import json, sys, time
import reference.engine.batch.solve as rb
real_key, real_run = rb.batch_key, rb.run_batch
rb.batch_key = lambda s: real_key(s) or ("test",)
def slow(scenes, options=None):
    time.sleep(0.4)  # long enough to be caught in flight
    return real_run(scenes, options)
rb.run_batch = slow
from cardan_exudyn.sweep import SweepInterrupted, run_sweep
try:
    run_sweep(json.loads(sys.argv[1]), sys.argv[2], workers=1, progress=False)
except SweepInterrupted as exc:
    print(exc.done, exc.total, flush=True)
    sys.exit(130)
"""


def test_ctrl_c_keeps_finished_batches_and_records_none_as_failed(tmp_path):
    """SIGINT to a batched sweep in its own process: the batches finished are recorded (whole),
    the batch in flight is not, nothing is recorded as failed, and the rerun completes the rest."""
    out, script = tmp_path / "out", tmp_path / "interrupted.py"
    script.write_text(INTERRUPTED)
    spec = torques(16)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS.parent), str(TESTS)])}

    def child() -> None:  # the default Ctrl-C of a terminal, even under a shell that ignores it
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    proc = subprocess.Popen([sys.executable, str(script), json.dumps(spec), str(out)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=child)
    cases = out / "cases.jsonl"
    wait_for(lambda: cases.exists() and cases.read_bytes().count(b"\n") >= 4, proc)
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    kept = read_records(cases)
    done, total = map(int, stdout.split())
    assert total == 16 and done == len(kept) and 4 <= len(kept) < 16 and len(kept) % 4 == 0
    assert all(r["status"] == "ok" for r in kept.values())
    summary = run_sweep(spec, out, workers=1)
    assert summary["run_now"] == 16 - len(kept) and summary["ok"] == 16
    assert len(cases.read_text().splitlines()) == 16, "a case ran twice"


def test_dask_cluster_runs_batches_with_the_local_results(tmp_path):
    """On a two-process LocalCluster the batched sweep's records equal the in-process run's."""
    distributed = pytest.importorskip("distributed")
    spec = torques(16)
    local = run_sweep(spec, tmp_path / "local", workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        dask = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert dask["executor"]["kind"] == "dask" and dask["batching"]["batches"] == 8
    assert local["batching"]["batches"] == 4 and dask["ok"] == local["ok"] == 16
    assert_same_records(read_records(tmp_path / "local" / "cases.jsonl"),
                        read_records(tmp_path / "dask" / "cases.jsonl"))


def test_tolerance_study_runs_in_batches_and_equals_single_runs(tmp_path, batches):
    """`cardan tolerance montecarlo`'s study goes through the sweep's batches, and its samples
    equal the single-scene engine's."""
    from cardan_exudyn.studies.tolerance.command import monte_carlo
    from cardan_exudyn.studies.tolerance.montecarlo import default_distributions

    scene = replace(named_scene("rig-matched"), revolutions=1)
    summary = monte_carlo(scene, "reference", 8, 1, out=tmp_path / "mc", workers=1, progress=False)
    assert batches == [2, 2, 2, 2] and summary["status_counts"] == {"ok": 8}
    records = read_records(tmp_path / "mc" / "cases" / "cases.jsonl")
    for case_id in ("0000", "0005"):
        record = records[case_id]
        single = engines.run(replace(scene, **record["overrides"]), "reference").summary
        assert record["mean_efficiency"] == pytest.approx(single.mean_efficiency, abs=AGREEMENT)
        assert set(record["overrides"]) == set(default_distributions())


def test_cli_batch_size_caps_the_batches(tmp_path, batches):
    """``cardan sweep --batch-size N`` reaches the runner: 12 cases (which would run as four
    batches of 3 in one process) in batches of at most 2, and ``--batch-size 1`` runs each case
    on its own."""
    import json

    from cardan_exudyn.cli import main

    spec = tmp_path / "spec.toml"
    torques_ = ", ".join(str(1.0 + 0.25 * i) for i in range(12))
    spec.write_text('engine = "reference"\nscene = "paper-literal-10deg"\n'
                    '[fixed]\n"record.timeseries" = false\n'
                    f'[grid]\n"load.torque" = [{torques_}]\n', encoding="utf-8")
    assert main(["sweep", str(spec), "--out", str(tmp_path / "two"), "--workers", "1", "--quiet",
                 "--batch-size", "2"]) == 0
    assert batches == [2] * 6
    batching = json.loads((tmp_path / "two" / "sweep.json").read_text(encoding="utf-8"))["batching"]
    assert batching == {"batches": 6, "batched_cases": 12, "largest_batch": 2}
    batches.clear()
    assert main(["sweep", str(spec), "--out", str(tmp_path / "one"), "--workers", "1", "--quiet",
                 "--batch-size", "1"]) == 0
    assert batches == []
