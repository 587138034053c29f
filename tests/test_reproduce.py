"""`cardan reproduce` through the sweep runner: the scenes it builds, resume after an
interruption, failing cases, worker processes, bad input."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pandas as pd
import pytest

from cardan_exudyn.cli import main
from cardan_exudyn.engines import run as engine_run
from cardan_exudyn.studies import reproduce as rep
from cardan_exudyn.sweep import CASES_FILE, make_plan, read_records
from reference.paper import paper_scene
from reference.scene import replace
from reference.schema import Result, Status, Summary

QUICK_IDS = [f"{p}-{c}" for p in ("plain", "calibrated")
             for c in ("table2-0deg-2000rpm", "table2-10deg-2000rpm", "speed-10deg-500rpm")]


def _records(out) -> dict:
    return read_records(out / rep.RUNS_DIR / CASES_FILE)


class Counting:
    """Stands in for the engine call of the case function: counts the scenes it runs, can raise
    or return a failed result for chosen scene names."""

    def __init__(self, interrupt_at: int | None = None, fail: dict | None = None) -> None:
        self.names: list[str] = []
        self.interrupt_at, self.fail = interrupt_at, fail or {}

    def __call__(self, scene, engine):
        self.names.append(scene.name)
        if self.interrupt_at is not None and len(self.names) == self.interrupt_at:
            raise KeyboardInterrupt
        action = self.fail.get(scene.name)
        if action == "raise":
            raise RuntimeError("boom in the engine")
        if action == "self_locking":
            return Result(None, Summary(Status.SELF_LOCKING, "friction loop gain 1.3 >= 1"))
        return engine_run(scene, engine)


@pytest.fixture
def no_drawing(monkeypatch):
    """Figures are made but not rendered (an empty file each): rendering is most of a quick
    report's time, and the tests using this look at numbers and text."""
    import matplotlib.pyplot as plt

    from cardan_exudyn.report import plots

    def save(fig, path):
        plt.close(fig)
        open(path, "wb").close()

    monkeypatch.setattr(plots, "save", save)


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce") / "quick"
    assert rep.reproduce(out, quick=True, workers=1, progress=False).success
    return out


@pytest.mark.parametrize("quick", [False, True])
def test_runner_builds_the_paper_scenes(quick):
    """The sweep plan has the 22 (quick: 6) runs in report order, and the scene the runner builds
    for each case is exactly paper_scene(angle, speed, parameters) (with --quick's overrides)."""
    runs = rep.paper_runs(quick)
    plan = make_plan(rep.sweep_spec(runs, quick))
    assert [c.id for c in plan.cases] == [r.id for r in runs]
    assert len(plan.cases) == (6 if quick else 22)
    if quick:
        assert [r.id for r in runs] == QUICK_IDS
    for run, case in zip(runs, plan.cases, strict=True):
        expected = paper_scene(run.case["shaft_angle_deg"], run.case["speed_rpm"],
                               parameters=run.parameters)
        if quick:
            expected = replace(expected, **rep.QUICK_OVERRIDES)
        built = replace(plan.base, **case.overrides)
        assert built == expected, run.id
        assert built.name == expected.name
    assert plan.spec.function == rep.CASE_FUNCTION and plan.spec.function_args == {}
    assert rep.sweep_spec(runs, quick, files="/report/runs/files").function_args == {
        "files": "/report/runs/files"}


def test_quick_report_numbers_and_files(quick_report):
    """Rows, summaries and histories come from the runs: equal to a direct run of the scene, bit
    for bit; records stay small; no file is left that no record names."""
    rows = pd.read_csv(quick_report / "results.csv")
    assert len(rows) == 6 and (rows.status == "ok").all()
    assert set(rows.parameters) == {"plain", "calibrated"}
    direct = engine_run(replace(paper_scene(10.0, 2000.0), **rep.QUICK_OVERRIDES), "exudyn")
    numbers = rep.run_numbers(direct)
    row = rows[(rows.parameters == "plain") & (rows.study == "table2")
               & (rows.shaft_angle_deg == 10.0)].iloc[0]
    for key in ("mean_efficiency", "mean_instantaneous_efficiency", "energy_balance_residual_J",
                "loss_share_input_spider", "steps"):
        assert row[key] == numbers[key], key
    records = _records(quick_report)
    assert sorted(records) == sorted(QUICK_IDS)
    lines = (quick_report / rep.RUNS_DIR / CASES_FILE).read_text().splitlines()
    assert max(len(line) for line in lines) < 4000  # no time histories in the records
    record = records["plain-table2-10deg-2000rpm"]
    files = quick_report / rep.RUNS_DIR / rep.FILES_DIR
    with np.load(files / record["files"] / "history.npz") as data:
        for column in rep.HISTORY_COLUMNS:
            np.testing.assert_array_equal(data[column], direct.table[column].to_numpy(float))
    assert sorted(p.name for p in files.iterdir()) == sorted(r["files"] for r in records.values())
    summaries = json.loads((quick_report / "summaries.json").read_text())
    assert [s["scene"]["name"] for s in summaries] == [
        "paper-0deg-2000rpm", "paper-10deg-2000rpm", "paper-10deg-500rpm",
        "paper-calibrated-0deg-2000rpm", "paper-calibrated-10deg-2000rpm",
        "paper-calibrated-10deg-500rpm"]
    assert summaries[1]["mean_efficiency"] == direct.summary.mean_efficiency
    for name in ("fig4_efficiency_10deg_plain.png", "fig6_angles_calibrated.png",
                 "fig7_speeds_plain.png", "table2_calibrated.png"):
        assert (quick_report / name).is_file(), name
    plan = json.loads((quick_report / rep.RUNS_DIR / "plan.json").read_text())
    assert plan["function_args"] == {"files": str(files.resolve())}


def test_interrupted_reproduce_resumes(tmp_path, monkeypatch, no_drawing):
    """Ctrl-C in the fourth run keeps the three records; the rerun runs only the three missing
    cases, drops a stray case folder, and writes the report; a third invocation runs nothing;
    --restart runs all again."""
    out = tmp_path / "rep"
    first = Counting(interrupt_at=4)
    monkeypatch.setattr(rep.engines, "run", first)
    with pytest.raises(KeyboardInterrupt):
        rep.reproduce(out, quick=True, workers=1, progress=False)
    assert sorted(_records(out)) == sorted(QUICK_IDS[:3])
    assert not (out / "report.md").exists()
    stray = out / rep.RUNS_DIR / rep.FILES_DIR / "paper-calibrated-0deg-2000rpm-interrupted"
    stray.mkdir()

    second = Counting()
    monkeypatch.setattr(rep.engines, "run", second)
    result = rep.reproduce(out, quick=True, workers=1, progress=False)
    assert result.success and result.reused == 3 and result.sweep["run_now"] == 3
    assert second.names == ["paper-calibrated-0deg-2000rpm", "paper-calibrated-10deg-2000rpm",
                            "paper-calibrated-10deg-500rpm"]
    assert not stray.exists()
    rows = pd.read_csv(out / "results.csv")
    assert len(rows) == 6 and (rows.status == "ok").all()
    assert "3 of the 6 runs from the records of an earlier invocation" in (out / "report.md").read_text()
    assert len(json.loads((out / "summaries.json").read_text())) == 6

    third = Counting()
    monkeypatch.setattr(rep.engines, "run", third)
    assert rep.reproduce(out, quick=True, workers=1, progress=False).success
    assert third.names == []
    assert pd.read_csv(out / "results.csv").equals(rows)

    fourth = Counting()
    monkeypatch.setattr(rep.engines, "run", fourth)
    assert rep.reproduce(out, quick=True, workers=1, progress=False, restart=True).success
    assert len(fourth.names) == 6
    assert "earlier invocation" not in (out / "report.md").read_text()
    assert len(list((out / rep.RUNS_DIR / rep.FILES_DIR).iterdir())) == 6


def test_failing_cases_are_recorded_and_the_report_is_written(tmp_path, monkeypatch, capsys,
                                                              no_drawing):
    """A case that raises and one that self-locks: exit 3, their status and reason in the
    records and the report, the other four in every table; --retry-failed reruns only them."""
    out = tmp_path / "rep"
    engine = Counting(fail={"paper-calibrated-10deg-500rpm": "raise",
                            "paper-0deg-2000rpm": "self_locking"})
    monkeypatch.setattr(rep.engines, "run", engine)
    assert main(["reproduce", "--quick", "--workers", "1", "--out", str(out)]) == 3
    records = _records(out)
    assert records["calibrated-speed-10deg-500rpm"]["status"] == "error"
    assert "boom in the engine" in records["calibrated-speed-10deg-500rpm"]["traceback"]
    assert records["plain-table2-0deg-2000rpm"]["status"] == "self_locking"
    rows = pd.read_csv(out / "results.csv", keep_default_na=False)
    assert list(rows.status) == ["self_locking", "ok", "ok", "ok", "ok", "error"]
    assert rows.reason.iloc[-1] == "RuntimeError: boom in the engine"
    report = (out / "report.md").read_text()
    failed = report.split("### Cases without a result")[1].split("##")[0]
    assert "| plain | table2 | 0 | 2000 | self_locking | friction loop gain 1.3 >= 1 |" in failed
    assert "| calibrated | speed | 10 | 500 | error | RuntimeError: boom in the engine |" in failed
    for name in ("fig7_speeds_plain.png", "fig4_efficiency_10deg_calibrated.png"):
        assert (out / name).is_file(), name
    summaries = json.loads((out / "summaries.json").read_text())
    assert summaries[0]["status"] == "self_locking"
    assert summaries[-1] == {"status": "error", "reason": "RuntimeError: boom in the engine",
                             "case": "calibrated-speed-10deg-500rpm"}
    err = capsys.readouterr().err
    assert "calibrated-speed-10deg-500rpm: error: RuntimeError: boom in the engine" in err

    again = Counting()
    monkeypatch.setattr(rep.engines, "run", again)
    assert main(["reproduce", "--quick", "--workers", "1", "--retry-failed", "--out", str(out)]) == 0
    assert sorted(again.names) == ["paper-0deg-2000rpm", "paper-calibrated-10deg-500rpm"]
    assert (pd.read_csv(out / "results.csv").status == "ok").all()


def test_two_workers_give_the_same_report(quick_report, tmp_path, no_drawing):
    """Cases in two spawned worker processes (which receive the files folder as an argument of
    the case function): the same numbers, summaries and histories (what the figures are drawn
    from) as in one process, and the same figure files."""
    out = tmp_path / "rep"
    assert rep.reproduce(out, quick=True, workers=2, progress=False).success
    sweep = json.loads((out / rep.RUNS_DIR / "sweep.json").read_text())
    assert sweep["executor"] == {"kind": "processes", "workers": 2}
    a = pd.read_csv(quick_report / "results.csv").drop(columns="wall_time_s")
    b = pd.read_csv(out / "results.csv").drop(columns="wall_time_s")
    pd.testing.assert_frame_equal(a, b)

    def without_wall(value):
        """``value`` without its wall times, the keys ending in ``wall_time_s`` at any depth (the
        run's, and those of its pilot and companion in ``accuracy``): they differ between any
        two runs. Everything else, the step choice and the error estimate included, must not."""
        if isinstance(value, dict):
            return {k: without_wall(v) for k, v in value.items() if not k.endswith("wall_time_s")}
        if isinstance(value, list):
            return [without_wall(v) for v in value]
        return value

    sa, sb = (without_wall(json.loads((f / "summaries.json").read_text())) for f in (out, quick_report))
    assert sa == sb
    # what the comparison still covers: each friction run's estimate and its companion's result
    estimated = [s["accuracy"] for s in sb if "companion_mean_efficiency" in s.get("accuracy", {})]
    assert estimated and all({"steps_per_revolution", "richardson", "pilot"} <= set(a) for a in estimated)
    ra, rb = _records(quick_report), _records(out)
    files_a, files_b = (f / rep.RUNS_DIR / rep.FILES_DIR for f in (quick_report, out))
    for case_id in QUICK_IDS:
        with np.load(files_a / ra[case_id]["files"] / "history.npz") as x, \
                np.load(files_b / rb[case_id]["files"] / "history.npz") as y:
            for column in rep.HISTORY_COLUMNS:
                np.testing.assert_array_equal(x[column], y[column])
    assert sorted(p.name for p in out.glob("*.png")) == sorted(p.name for p in quick_report.glob("*.png"))


def test_bad_input_exits_2_with_one_line(quick_report, tmp_path, monkeypatch, capsys, no_drawing):
    """--out naming a file, and an OUT/runs holding another plan (--quick runs, then the full
    set): exit 2, one line naming the problem, nothing run, nothing changed."""
    engine = Counting()
    monkeypatch.setattr(rep.engines, "run", engine)
    target = tmp_path / "file.txt"
    target.write_text("keep")
    assert main(["reproduce", "--out", str(target)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exists and is not a folder" in err[0]
    assert target.read_text() == "keep"

    out = tmp_path / "quick"
    shutil.copytree(quick_report, out)
    before = (out / rep.RUNS_DIR / CASES_FILE).read_bytes()
    assert main(["reproduce", "--workers", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "different sweep" in err[0] and "--restart" in err[0], err
    assert "Traceback" not in err[0]
    assert engine.names == []
    assert (out / rep.RUNS_DIR / CASES_FILE).read_bytes() == before
    assert (out / "report.md").read_bytes() == (quick_report / "report.md").read_bytes()
