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
from cardan_exudyn.report import plots
from cardan_exudyn.studies.reproduce import compute as rep
from cardan_exudyn.studies.reproduce import report as report
from cardan_exudyn.studies.reproduce.command import reproduce
from cardan_exudyn.sweep import CASES_FILE, make_plan, read_records
from reference.paper.parameter_sets import PARAMETER_SETS, parameter_set
from reference.paper.scenes import paper_scene
from reference.results.result import Result
from reference.results.summary import Status, Summary
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace

QUICK_IDS = [f"{p}-{c}" for p in ("physical", "literal", "matched")
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
    assert reproduce(out, quick=True, workers=1, progress=False).success
    return out


@pytest.mark.parametrize("quick", [False, True])
def test_runner_builds_the_paper_scenes(quick):
    """The sweep plan has the 33 (quick: 9) runs in report order, and the scene the runner builds
    for each case is exactly paper_scene(angle, speed, parameters) (with --quick's overrides)."""
    runs = rep.paper_runs(quick)
    plan = make_plan(rep.sweep_spec(runs, quick))
    assert [c.id for c in plan.cases] == [r.id for r in runs]
    assert len(plan.cases) == (9 if quick else 33)
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
    assert len(rows) == 9 and (rows.status == "ok").all()
    assert list(dict.fromkeys(rows.parameters)) == ["physical", "literal", "matched"]
    direct = engine_run(replace(paper_scene(10.0, 2000.0), **rep.QUICK_OVERRIDES), "exudyn")
    numbers = rep.run_numbers(direct)
    row = rows[(rows.parameters == "physical") & (rows.study == "table2")
               & (rows.shaft_angle_deg == 10.0)].iloc[0]
    for key in ("mean_efficiency", "mean_instantaneous_efficiency", "energy_balance_residual_J",
                "loss_share_input_spider", "steps"):
        assert row[key] == numbers[key], key
    records = _records(quick_report)
    assert sorted(records) == sorted(QUICK_IDS)
    lines = (quick_report / rep.RUNS_DIR / CASES_FILE).read_text().splitlines()
    assert max(len(line) for line in lines) < 4000  # no time histories in the records
    record = records["physical-table2-10deg-2000rpm"]
    files = quick_report / rep.RUNS_DIR / rep.FILES_DIR
    with np.load(files / record["files"] / "history.npz") as data:
        for column in rep.HISTORY_COLUMNS:
            np.testing.assert_array_equal(data[column], direct.table[column].to_numpy(float))
    assert sorted(p.name for p in files.iterdir()) == sorted(r["files"] for r in records.values())
    summaries = json.loads((quick_report / "summaries.json").read_text())
    assert [s["scene"]["name"] for s in summaries] == [
        f"paper-{p}-{c}" for p in ("physical", "literal", "matched")
        for c in ("0deg-2000rpm", "10deg-2000rpm", "10deg-500rpm")]
    assert [s["scene"]["parameter_set"] for s in summaries] == [r.split("-")[0] for r in QUICK_IDS]
    assert summaries[1]["mean_efficiency"] == direct.summary.mean_efficiency
    for name in ("fig4_efficiency_10deg_physical.png", "fig5_pair_losses_literal.png",
                 "fig6_angles_matched.png", "fig7_speeds_physical.png", "table2.png", "speed.png"):
        assert (quick_report / name).is_file(), name
    plan = json.loads((quick_report / rep.RUNS_DIR / "plan.json").read_text())
    assert plan["function_args"] == {"files": str(files.resolve())}


def test_interrupted_reproduce_resumes(tmp_path, monkeypatch, no_drawing):
    """Ctrl-C in the fourth run keeps the three records; the rerun runs only the six missing
    cases, drops a stray case folder, and writes the report; a third invocation runs nothing;
    --restart runs all again."""
    out = tmp_path / "rep"
    first = Counting(interrupt_at=4)
    monkeypatch.setattr(rep.engines, "run", first)
    with pytest.raises(KeyboardInterrupt):
        reproduce(out, quick=True, workers=1, progress=False)
    assert sorted(_records(out)) == sorted(QUICK_IDS[:3])
    assert not (out / "report.md").exists()
    stray = out / rep.RUNS_DIR / rep.FILES_DIR / "paper-literal-0deg-2000rpm-interrupted"
    stray.mkdir()

    second = Counting()
    monkeypatch.setattr(rep.engines, "run", second)
    result = reproduce(out, quick=True, workers=1, progress=False)
    assert result.success and result.reused == 3 and result.sweep["run_now"] == 6
    assert second.names == [f"paper-{p}-{c}" for p in ("literal", "matched")
                            for c in ("0deg-2000rpm", "10deg-2000rpm", "10deg-500rpm")]
    assert not stray.exists()
    rows = pd.read_csv(out / "results.csv")
    assert len(rows) == 9 and (rows.status == "ok").all()
    assert "3 of the 9 runs from the records of an earlier invocation" in (out / "report.md").read_text()
    assert len(json.loads((out / "summaries.json").read_text())) == 9

    third = Counting()
    monkeypatch.setattr(rep.engines, "run", third)
    assert reproduce(out, quick=True, workers=1, progress=False).success
    assert third.names == []
    assert pd.read_csv(out / "results.csv").equals(rows)

    fourth = Counting()
    monkeypatch.setattr(rep.engines, "run", fourth)
    assert reproduce(out, quick=True, workers=1, progress=False, restart=True).success
    assert len(fourth.names) == 9
    assert "earlier invocation" not in (out / "report.md").read_text()
    assert len(list((out / rep.RUNS_DIR / rep.FILES_DIR).iterdir())) == 9


def test_failing_cases_are_recorded_and_the_report_is_written(tmp_path, monkeypatch, capsys,
                                                              no_drawing):
    """A case that raises and one that self-locks: exit 3, their status and reason in the
    records and the report, the other seven in every table; --retry-failed reruns only them."""
    out = tmp_path / "rep"
    engine = Counting(fail={"paper-matched-10deg-500rpm": "raise",
                            "paper-physical-0deg-2000rpm": "self_locking"})
    monkeypatch.setattr(rep.engines, "run", engine)
    assert main(["reproduce", "--quick", "--workers", "1", "--out", str(out)]) == 3
    records = _records(out)
    assert records["matched-speed-10deg-500rpm"]["status"] == "error"
    assert "boom in the engine" in records["matched-speed-10deg-500rpm"]["traceback"]
    assert records["physical-table2-0deg-2000rpm"]["status"] == "self_locking"
    rows = pd.read_csv(out / "results.csv", keep_default_na=False)
    assert list(rows.status) == ["self_locking"] + ["ok"] * 7 + ["error"]
    assert rows.reason.iloc[-1] == "RuntimeError: boom in the engine"
    report = (out / "report.md").read_text()
    failed = report.split("### Cases without a result")[1].split("##")[0]
    assert "| physical | table2 | 0 | 2000 | self_locking | friction loop gain 1.3 >= 1 |" in failed
    assert "| matched | speed | 10 | 500 | error | RuntimeError: boom in the engine |" in failed
    for name in ("fig7_speeds_physical.png", "fig4_efficiency_10deg_matched.png", "table2.png"):
        assert (out / name).is_file(), name
    summaries = json.loads((out / "summaries.json").read_text())
    assert summaries[0]["status"] == "self_locking"
    assert summaries[-1] == {"status": "error", "reason": "RuntimeError: boom in the engine",
                             "case": "matched-speed-10deg-500rpm"}
    err = capsys.readouterr().err
    assert "matched-speed-10deg-500rpm: error: RuntimeError: boom in the engine" in err

    again = Counting()
    monkeypatch.setattr(rep.engines, "run", again)
    assert main(["reproduce", "--quick", "--workers", "1", "--retry-failed", "--out", str(out)]) == 0
    assert sorted(again.names) == ["paper-matched-10deg-500rpm", "paper-physical-0deg-2000rpm"]
    assert (pd.read_csv(out / "results.csv").status == "ok").all()


def test_two_workers_give_the_same_report(quick_report, tmp_path, no_drawing):
    """Cases in two spawned worker processes (which receive the files folder as an argument of
    the case function): the same numbers, summaries and histories (what the figures are drawn
    from) as in one process, and the same figure files."""
    out = tmp_path / "rep"
    assert reproduce(out, quick=True, workers=2, progress=False).success
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


def test_report_names_the_sets_and_marks_fitted_and_held_out(quick_report):
    """The report names the three sets (no former names), has each set's parameter table with the
    matched set's non-physical values marked, marks every row fitted or held out from the set's
    stored fit cases, and summarises RMS and largest error of both groups per set."""
    text = (quick_report / "report.md").read_text()
    assert "physical (default), literal, matched" in text.splitlines()[0]
    own = text.split("## Assumption register")[0]  # after it: the data file's register, verbatim
    assert "plain" not in own.replace("explain", "") and "calibrated" not in own.replace(
        "(formerly 'calibrated')", "")
    for name in PARAMETER_SETS:
        assert f"\n### {name}" in text
    matched = text.split("### matched")[1].split("###")[0]
    for value in ("spider_lever", "frame_lever", "spider_com_offset"):
        assert next(line for line in matched.splitlines() if line.startswith(f"| {value} |")).count(
            "**NO**") == 1, value
    assert "**Outside the plausible range:** `spider_lever`, `frame_lever`, `spider_com_offset`" in matched
    rows = pd.read_csv(quick_report / "results.csv")
    for _, row in rows.iterrows():
        fit = parameter_set(row.parameters)["fit_cases"]
        scene = f"{row.shaft_angle_deg:g}:{row.speed_rpm:g}"
        assert row.used_in_fit == (f"table2:{scene}" in fit or f"speed:{scene}" in fit), row.to_dict()
        assert row.fit == ("fitted" if row.used_in_fit else "held out")
        assert row.engine == "exudyn" and isinstance(row.engine_version, str) and row.dt_s > 0
    assert not rows[rows.parameters == "literal"].used_in_fit.any()
    assert rows[rows.parameters == "physical"].used_in_fit.any()
    summary = text.split("### Errors against the paper, fitted and held out")[1].split("\n## ")[0]
    for line in ("| physical | fitted |", "| physical | held out |", "| literal | held out |",
                 "| matched | fitted |", "| matched | held out |"):
        assert line in summary, line
    assert "| literal | fitted |" not in summary
    assert "Not computed" in text or "## What plausible physics can reach" in text
    assert "exudyn" in text.split("**How every number was computed.**")[1].split("\n")[0]


def test_error_summary_by_hand():
    """RMS and signed largest difference of the fitted and the held-out cases, per set."""
    rows = pd.DataFrame([
        {"parameters": "physical", "status": "ok", "used_in_fit": True, "study": "table2",
         "shaft_angle_deg": 0.0, "speed_rpm": 2000.0, "difference_to_paper": 0.003},
        {"parameters": "physical", "status": "ok", "used_in_fit": True, "study": "table2",
         "shaft_angle_deg": 10.0, "speed_rpm": 2000.0, "difference_to_paper": -0.004},
        {"parameters": "physical", "status": "ok", "used_in_fit": False, "study": "speed",
         "shaft_angle_deg": 10.0, "speed_rpm": 500.0, "difference_to_paper": -0.01},
        {"parameters": "physical", "status": "error", "used_in_fit": False, "study": "table2",
         "shaft_angle_deg": 35.0, "speed_rpm": 2000.0, "difference_to_paper": float("nan")},
    ])
    got = report.error_summary(rows)
    assert [(g["cases"], g["count"]) for g in got] == [("fitted", 2), ("held out", 1)]
    assert got[0]["rms"] == pytest.approx(np.sqrt((0.003 ** 2 + 0.004 ** 2) / 2), rel=1e-12)
    assert got[0]["largest"] == -0.004 and got[0]["largest_at"] == "table2:10:2000"
    assert got[1]["rms"] == pytest.approx(0.01) and got[1]["largest_at"] == "speed:10:500"


@pytest.mark.parametrize("values, clip, expected", [
    ([0.97, 0.99, 0.98], None, (0.9684, 0.9916)),
    ([0.5, 0.5], None, (0.49884, 0.50116)),
    ([-3.0, 0.2, 0.6, np.nan, np.inf], (-0.5, 1.05), (0.168, 0.632)),
    ([np.nan], (-0.5, 1.05), (-0.5, 1.05)),
], ids=["margin", "constant", "clipped", "empty"])
def test_axis_limits_follow_the_data(values, clip, expected):
    """Limits are the finite values' range (inside ``clip``) widened by 8 % of the span each side,
    a span of at least 2e-3 before the margin."""
    np.testing.assert_allclose(plots.data_limits(values, clip=clip), expected, rtol=0, atol=1e-12)


def test_mean_figure_axes_show_the_variation(quick_report):
    """Each set's panel spans its own data (model and paper values) with a small margin, not
    0-1.05: the panels of the physical and matched sets are under 0.05 wide."""
    rows = pd.read_csv(quick_report / "results.csv")
    part = rows[rows.study == "table2"]
    panels = {p: part[part.parameters == p].sort_values("shaft_angle_deg") for p in PARAMETER_SETS}
    fig = plots.efficiency_against_paper(panels, "shaft_angle_deg", "shaft angle [deg]")
    try:
        for ax, (name, df) in zip(fig.axes, panels.items(), strict=True):
            data = df[["mean_efficiency", "paper_mean_efficiency"]].to_numpy(float)
            lo, hi = ax.get_ylim()
            span = data.max() - data.min()
            assert lo <= data.min() and hi >= data.max(), name
            assert hi - lo <= 1.2 * span + 2e-3, name
            assert ax.get_title() == name
        assert fig.axes[0].get_ylim()[1] - fig.axes[0].get_ylim()[0] < 0.05
    finally:
        plots.close(fig)


def test_history_figures_show_one_steady_revolution():
    """The figures' rows: the last whole input revolution from 0 to 360 deg, without the run's
    first START_UP_STEPS steps where a one-revolution run has them; the first-minus-last
    revolution effect is zero for an exactly periodic history and absent for one revolution."""
    n = 400
    theta = np.linspace(0.0, 4 * np.pi, 2 * n + 1)
    history = {"t": theta / 200.0, "theta_in": theta, "power_in": 400 + 10 * np.sin(2 * theta),
               **{f"power_loss_{p}": 2 + np.cos(2 * theta) ** 2 for p in PAIR_NAMES}}
    angle, rows = report.steady_revolution(history)
    assert rows.sum() == n + 1 and not rows[:n].any()
    np.testing.assert_allclose(angle[[0, -1]], [0.0, 360.0], atol=1e-9)
    assert report.start_up_effect(history) == pytest.approx(0.0, abs=1e-12)
    one = {k: v[: n + 1] for k, v in history.items()}
    angle, rows = report.steady_revolution(one)
    assert rows.sum() == n + 1 - report.START_UP_STEPS and not rows[: report.START_UP_STEPS].any()
    assert angle[-1] == pytest.approx(360.0)
    assert report.start_up_effect(one) is None
