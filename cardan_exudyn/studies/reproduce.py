"""``cardan reproduce``: the paper's results with friction, under two parameter sets, as a report.

For each parameter set (``plain``: the paper read literally, with the assumption register for
what it does not state; ``calibrated``: the few free parameters identified by ``cardan
calibrate`` from a subset of the paper's numbers) the report has

- Table 2 (0 to 35 deg at 2000 rpm) and the speed study (500, 1000, 2000 rpm at 10 deg) next to
  the paper, with both mean-efficiency definitions (one minus lost over input energy over whole
  revolutions, and the time average of eq. (18)); for the calibrated set the cases used in the
  fit are marked and the error on the held-out cases is summarised;
- the per-pair loss breakdown (share of the input work lost in each pair);
- the time histories of Figures 4 (efficiency at 10 deg), 5 (power loss per pair at 10 deg),
  6 (efficiency at several angles) and 7 (efficiency at several speeds);
- the energy balance residual of every run, and the assumption register.

How the runs are made
---------------------
The runs (the eleven cases under each parameter set: 22; 6 with ``--quick``) are one sweep of
:mod:`cardan_exudyn.sweep.runner` with an explicit case list, in ``OUT/runs/``. The base scene is
``paper_scene(10 deg, 2000 rpm)``; each case's overrides are the leaf-by-leaf difference between
its own scene (:func:`reference.paper.paper_scene`, either parameter set) and the base, and
:func:`paper_runs` checks that the runner rebuilds exactly that scene. Case ids read like
``calibrated-table2-35deg-2000rpm``. So the cases can run in worker processes (``workers``), a
rerun of an interrupted ``cardan reproduce`` runs only the cases without a record (a rerun of a
finished one redraws the report from the records; ``restart`` runs everything again), a case
that fails or raises is recorded with its status and reason while the report is written from
the others, and progress is the sweep runner's bar.

Besides each run's numbers (the record: a few scalars, :func:`run_numbers`), the report needs the
engine's full summary (``summaries.json``) and, for Figures 4-7, time histories. The case function
:func:`paper_case_outputs` writes both into a folder of its own, ``OUT/runs/files/<scene
name>-<random token>/`` (``summary.json`` and ``history.npz`` with the columns of
:data:`HISTORY_COLUMNS`, each written to a temporary name, fsync'ed and renamed), and returns that
folder's name in its record (``files``). Why this way:

- records stay small (about 1.4 kB each): the histories are about 12,700 rows x 6 columns for the
  22 runs, which in the records would be about 1.6 MB of JSON in ``cases.jsonl`` and a text cell
  of up to 180 kB per case in the sweep's ``results.csv`` (as ``.npz`` files: 0.9 MB);
  recomputing them after the sweep would run 14 of the 22 scenes twice;
- the files are complete before the function returns, so a record in ``cases.jsonl`` (which the
  runner writes after the function returns) implies its files exist: a resumed run finds the
  files of every recorded case; a random token keeps two runs of one scene (Table 2's 10 deg case
  is the speed study's 2000 rpm case) and a rerun of a failed case apart; folders no record names
  (a case interrupted after writing them) are deleted once every case has a record;
- the folder reaches the case function through the environment variable
  :data:`FILES_ENV`, set by :func:`reproduce` for the duration of the sweep: the runner calls a
  case function with the scene and the engine only, the folder is no part of a scene (in it, it
  would change the scene and its hash, and so the plan, whenever the report folder moves), and
  the runner's workers are this process or processes spawned from it, which inherit its
  environment (``reproduce`` offers no Dask cluster, whose workers would not). Without the
  variable the function writes nothing and returns the numbers, so it also serves
  ``cardan sweep --function cardan_exudyn.studies.reproduce:paper_case_outputs``;
- ``.npz`` keeps float64 exactly (whether a CSV reads back bit for bit depends on the pandas
  version's parser), so the figures are drawn from exactly the engine's numbers, as before.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.studies.calibrate import in_fit
from cardan_exudyn.engines import run_scene
from cardan_exudyn.io import atomic_directory, atomic_write, dumps
from cardan_exudyn.sweep.runner import (
    CASES_FILE,
    SweepError,
    SweepSpec,
    _flatten,
    _never_leaf,
    read_records,
    run_sweep,
)
from reference.paper import (
    PARAMETER_SETS,
    assumption_register,
    calibrated_choices,
    calibrated_parameters,
    paper_cases,
    paper_data,
    paper_scene,
    stated_values,
)
from reference.scene import PAIR_NAMES, Scene, replace, scene_to_dict


def fit_case_keys() -> list[str]:
    """The cases the calibrated set was fitted to, as ``study:angle:rpm`` keys."""
    return list(paper_data().get("calibrated", {}).get("fit_cases", []))


RUNS_DIR, FILES_DIR = "runs", "files"
FILES_ENV = "CARDAN_REPRODUCE_FILES"
CASE_FUNCTION = "cardan_exudyn.studies.reproduce:paper_case_outputs"
HISTORY_COLUMNS = ("t", "efficiency", *(f"power_loss_{pair}" for pair in PAIR_NAMES))
QUICK_OVERRIDES = {"numerics.accuracy": 1e-4, "revolutions": 1.0}
# the numbers of a run, in the order of the report's results.csv (after difference_to_paper)
RUN_NUMBERS = ("mean_torque_in", "input_work_J", "loss_work_J", "energy_balance_residual_J",
               "loop_gain_estimate", "friction_evaluations_per_step", "steps", "wall_time_s",
               *(f"loss_share_{pair}" for pair in PAIR_NAMES))


def run_numbers(result) -> dict[str, Any]:
    """Status, reason and, for a run that is ``ok``, the numbers the report tabulates."""
    s = result.summary
    out: dict[str, Any] = {"status": s["status"], "reason": s.get("reason", "")}
    if not result.ok:
        return out
    t = result.table
    energy = t["energy_kinetic"] + t["energy_potential"]
    work = {c: float(np.trapezoid(t[c], t["t"])) for c in ("power_in", "power_out", "power_loss")}
    out.update({
        "mean_efficiency": s["mean_efficiency"],
        "mean_instantaneous_efficiency": s["mean_instantaneous_efficiency"],
        "mean_torque_in": s["mean_torque_in"],
        "input_work_J": s["input_work"],
        "loss_work_J": s["loss_work"],
        "energy_balance_residual_J": work["power_in"] - work["power_out"] - work["power_loss"]
        - float(energy.iloc[-1] - energy.iloc[0]),
        "loop_gain_estimate": s["friction"]["loop_gain_estimate"],
        "friction_evaluations_per_step": s["friction"]["mean_iterations_per_step"],
        "steps": s["steps"],
        "wall_time_s": s["wall_time_s"],
    })
    for pair in PAIR_NAMES:
        out[f"loss_share_{pair}"] = s[f"loss_work_{pair}"] / s["input_work"]
    return out


def paper_case_outputs(scene: Scene, engine: str) -> dict[str, Any]:
    """Sweep case function: run ``scene``, return :func:`run_numbers` and the name of the folder
    (under ``$CARDAN_REPRODUCE_FILES``) holding its ``summary.json`` and ``history.npz``."""
    result = run_scene(scene, engine)
    out = run_numbers(result)
    root = os.environ.get(FILES_ENV)
    if root:
        folder = Path(root) / f"{scene.name}-{uuid.uuid4().hex[:12]}"
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write(folder / "summary.json",
                      lambda f: f.write((dumps(result.summary) + "\n").encode("utf-8")))
        if result.ok and result.table is not None:
            columns = {c: result.table[c].to_numpy(dtype=float) for c in HISTORY_COLUMNS}
            atomic_write(folder / "history.npz", lambda f: np.savez(f, **columns))
        out["files"] = folder.name
    return out


def case_row(case: dict, parameters: str, record: dict[str, Any]) -> dict[str, Any]:
    """One row of the report's ``results.csv``: the case, the paper's value and the run's numbers
    (from its sweep record)."""
    row: dict[str, Any] = {
        "parameters": parameters,
        "study": case["study"],
        "shaft_angle_deg": case["shaft_angle_deg"],
        "speed_rpm": case["speed_rpm"],
        "paper_mean_efficiency": case["paper_mean_efficiency"],
        "status": record["status"],
        "reason": record.get("reason") or "",
        "used_in_fit": parameters == "calibrated" and in_fit(case, fit_case_keys()),
    }
    if record["status"] != "ok":
        return row

    def number(key: str) -> Any:
        value = record.get(key)
        return float("nan") if value is None else value

    row["mean_efficiency"] = number("mean_efficiency")
    row["mean_instantaneous_efficiency"] = number("mean_instantaneous_efficiency")
    row["difference_to_paper"] = row["mean_efficiency"] - case["paper_mean_efficiency"]
    row.update({key: number(key) for key in RUN_NUMBERS})
    return row


def _md(df: pd.DataFrame, columns: list[str], floatfmt: str = ".4f") -> str:
    head = "| " + " | ".join(columns) + " |\n|" + "---|" * len(columns) + "\n"
    lines = []
    for _, r in df[columns].iterrows():
        cells = []
        for c, v in zip(columns, r, strict=True):
            if isinstance(v, (float, np.floating)):
                fmt = "g" if c.endswith(("_deg", "_rpm")) else floatfmt
                cells.append("" if np.isnan(v) else format(v, fmt))
            else:
                cells.append(str(v))
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + "\n"


def _held_out_summary(rows: pd.DataFrame) -> str:
    cal = rows[(rows.parameters == "calibrated") & (rows.status == "ok")]
    if cal.empty:
        return ""
    out = []
    for label, sel in (("fitted", cal[cal.used_in_fit]), ("held out", cal[~cal.used_in_fit])):
        if sel.empty:
            continue
        err = sel["difference_to_paper"].abs()
        out.append(f"- {label} ({len(sel)} cases): max |difference| {err.max():.4f}, "
                   f"RMS {np.sqrt((err ** 2).mean()):.4f}")
    plain = rows[(rows.parameters == "plain") & (rows.status == "ok")]
    if not plain.empty:
        err = plain["difference_to_paper"].abs()
        out.append(f"- plain reading ({len(plain)} cases): max |difference| {err.max():.4f}, "
                   f"RMS {np.sqrt((err ** 2).mean()):.4f}")
    return "\n".join(out) + "\n"


def write_report(folder: Path, rows: pd.DataFrame, histories: dict, quick: bool,
                 wall: float, reused: int = 0) -> None:
    """``report.md``, ``results.csv``, ``assumptions.csv`` and the figures into ``folder``;
    ``reused``: runs taken from an earlier invocation's records (said in the report's head)."""
    from cardan_exudyn.report import plots

    rows.to_csv(folder / "results.csv", index=False)
    register = pd.DataFrame(assumption_register())
    register.to_csv(folder / "assumptions.csv", index=False)
    calibrated = pd.DataFrame(calibrated_parameters())
    stated = pd.DataFrame(stated_values())
    stated["value"] = stated["value"].astype(str)
    figures = []
    for parameters in PARAMETER_SETS:
        sel = rows[(rows.parameters == parameters) & (rows.status == "ok")]
        if sel.empty:
            continue
        t2 = sel[sel.study == "table2"].sort_values("shaft_angle_deg")
        sp = sel[sel.study == "speed"].sort_values("speed_rpm")
        hist = histories.get(parameters, {})
        if not t2.empty:
            plots.save(plots.efficiency_against_paper({parameters: t2}, "shaft_angle_deg",
                                                      "shaft angle [deg]"),
                       folder / f"table2_{parameters}.png")
            figures.append(f"table2_{parameters}.png")
        if not sp.empty:
            plots.save(plots.efficiency_against_paper({parameters: sp}, "speed_rpm",
                                                      "input speed [rpm]"),
                       folder / f"speed_{parameters}.png")
            figures.append(f"speed_{parameters}.png")
        if "10deg" in hist:
            plots.save(plots.efficiency_history({"10 deg, 2000 rpm": hist["10deg"]},
                                                f"Figure 4 ({parameters})"),
                       folder / f"fig4_efficiency_10deg_{parameters}.png")
            plots.save(plots.pair_losses(hist["10deg"], f"Figure 5 ({parameters}): power loss, "
                                                        "10 deg, 2000 rpm"),
                       folder / f"fig5_pair_losses_{parameters}.png")
            figures += [f"fig4_efficiency_10deg_{parameters}.png",
                        f"fig5_pair_losses_{parameters}.png"]
        angles = {k: v for k, v in hist.items() if k.startswith("angle ")}
        if angles:
            plots.save(plots.efficiency_history(angles, f"Figure 6 ({parameters})", ylim=(-0.5, 1.05)),
                       folder / f"fig6_angles_{parameters}.png")
            figures.append(f"fig6_angles_{parameters}.png")
        speeds = {k: v for k, v in hist.items() if k.startswith("speed ")}
        if speeds:
            plots.save(plots.efficiency_history(speeds, f"Figure 7 ({parameters})"),
                       folder / f"fig7_speeds_{parameters}.png")
            figures.append(f"fig7_speeds_{parameters}.png")

    main_cols = ["parameters", "study", "shaft_angle_deg", "speed_rpm", "status",
                 "paper_mean_efficiency", "mean_efficiency", "difference_to_paper",
                 "mean_instantaneous_efficiency", "used_in_fit", "loop_gain_estimate"]
    loss_cols = ["parameters", "shaft_angle_deg", "speed_rpm"] + [f"loss_share_{p}" for p in PAIR_NAMES]
    check_cols = ["parameters", "shaft_angle_deg", "speed_rpm", "input_work_J", "loss_work_J",
                  "energy_balance_residual_J", "friction_evaluations_per_step", "steps",
                  "wall_time_s"]
    ok = rows[rows.status == "ok"]
    failed = rows[rows.status != "ok"]
    md = [
        "# The paper's results with friction: plain reading and calibrated set\n",
        f"Generated by `cardan reproduce{' --quick' if quick else ''}` in {wall:.1f} s"
        + (f" ({reused} of the {len(rows)} runs from the records of an earlier invocation in "
           f"`{RUNS_DIR}/`)" if reused else "") + ". Every "
        "number and plot here was computed by the code in this repository from "
        "`reference/data/paper.toml`; nothing is copied from the paper except the column "
        "`paper_mean_efficiency`.\n",
        "**Parameter sets.** `plain`: every value the paper states, read literally (moment "
        "lever of eq. (1) = bearing length L), and the assumption register below for what it "
        "does not state. `calibrated`: the plain reading with the parameters listed under "
        "*Calibrated parameters* identified by `cardan calibrate` from the cases marked "
        "`used_in_fit`; the other cases are held out.\n",
        "**Definitions.** `mean_efficiency` = 1 - (loss work)/(input work) over whole input "
        "revolutions; `mean_instantaneous_efficiency` = time average of eq. (18), which is "
        "unbounded where the input power changes sign (it does at large angles).\n",
        "## Mean efficiency against the paper\n",
        _md(ok, main_cols),
        "\n### Summary of differences to the paper\n",
        _held_out_summary(rows),
    ]
    if not failed.empty:
        md += ["\n### Cases without a result\n",
               _md(failed, ["parameters", "study", "shaft_angle_deg", "speed_rpm", "status",
                            "reason"])]
    if not calibrated.empty:
        cal = calibrated.assign(plain_value=calibrated["plain_value"].astype(str))
        choices = pd.DataFrame([{"name": k, **v} for k, v in calibrated_choices().items()])
        md += ["\n## Calibrated parameters\n",
               f"Fitted by `cardan calibrate` to {', '.join(fit_case_keys())} "
               "(study:angle:rpm):\n\n",
               _md(cal, ["name", "value", "unit", "plain_value", "meaning"], ".5g"),
               "\nDiscrete choices of the calibrated set (not fitted):\n\n",
               _md(choices.assign(value=choices["value"].astype(str)), ["name", "value", "reason"]),
               "\n**Reading.** The fitted levers are not plausible dimensions for a joint this "
               "size (a 60 mm spider lever is a 30 mm arm radius on a 45.6 g spider; a 0.59 m "
               "frame lever is a bearing spacing far beyond shafts whose centres of mass sit "
               "0.13 m and 0.09 m from the joint). They act as correction factors: the paper's "
               "numbers need the moment term of eqs. (1)-(2) about 10 times weaker in the "
               "spider pairs and about 60 times weaker in the frame pairs than the stated "
               "bearing lengths give.\n"]
    md += [
        "\n## Where the power goes: share of the input work lost in each pair\n",
        _md(ok, loss_cols),
        "\n## Checks: energy balance and cost\n",
        "`energy_balance_residual_J` = input work - output work - friction loss work - change "
        "of mechanical energy over the run (trapezoidal, zero up to the integration error).\n\n",
        _md(ok, check_cols, ".4g"),
        "\n## Plots\n",
        "\n".join(f"![{f}]({f})\n" for f in figures),
        "\n## Assumption register\n",
        "Every value the paper does not state, the value used, and why (also "
        "`assumptions.csv`).\n\n",
        _md(register.assign(value=register["value"].astype(str)),
            ["name", "value", "unit", "assumption", "reason"]),
        "\n## Values taken from the paper\n",
        _md(stated, ["name", "value", "unit", "source"]),
    ]
    (folder / "report.md").write_text("\n".join(md), encoding="utf-8")


HISTORY_ANGLES = (0.0, 10.0, 20.0, 35.0)
BASE_ANGLE_DEG, BASE_SPEED_RPM = 10.0, 2000.0


@dataclass(frozen=True)
class PaperRun:
    """One run of the report: a paper case under a parameter set, as a sweep case."""

    id: str
    parameters: str
    case: dict[str, Any]
    overrides: dict[str, Any]


def selected_cases(quick: bool = False) -> list[dict[str, Any]]:
    """The paper's eleven cases, or the three of ``--quick`` (0 and 10 deg, 500 rpm)."""
    cases = paper_cases()
    if quick:
        cases = [c for c in cases if (c["study"] == "table2" and c["shaft_angle_deg"] in (0.0, 10.0))
                 or (c["study"] == "speed" and c["speed_rpm"] == 500.0)]
    return cases


def base_scene() -> Scene:
    """The sweep's base scene: the plain set at 10 deg, 2000 rpm."""
    return paper_scene(BASE_ANGLE_DEG, BASE_SPEED_RPM, parameters="plain")


def paper_runs(quick: bool = False) -> list[PaperRun]:
    """Every run in report order (parameter set, then the paper's case order).

    A run's overrides are the leaves in which its scene differs from :func:`base_scene`; the
    scene the sweep runner builds from them (with ``--quick``'s overrides) is checked to equal
    ``paper_scene(angle, speed, parameters)`` (with the same overrides).
    """
    base = base_scene()
    fixed = QUICK_OVERRIDES if quick else {}
    built_base = replace(base, **fixed) if fixed else base
    base_leaves = _flatten(scene_to_dict(base), _never_leaf)
    sets = [p for p in PARAMETER_SETS if p == "plain" or calibrated_parameters()]
    runs = []
    for parameters in sets:
        for case in selected_cases(quick):
            scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"], parameters=parameters)
            leaves = _flatten(scene_to_dict(scene), _never_leaf)
            if set(leaves) != set(base_leaves):
                raise RuntimeError(f"{scene.name}: scene fields {sorted(set(leaves) ^ set(base_leaves))} "
                                   "differ in kind from the base scene's")
            overrides = {k: v for k, v in leaves.items() if v != base_leaves[k]}
            expected = replace(scene, **fixed) if fixed else scene
            if replace(built_base, **overrides) != expected:
                raise RuntimeError(f"{scene.name}: the overrides do not rebuild the scene")
            run_id = (f"{parameters}-{case['study']}-{case['shaft_angle_deg']:g}deg-"
                      f"{case['speed_rpm']:g}rpm")
            runs.append(PaperRun(run_id, parameters, case, overrides))
    return runs


def sweep_spec(runs: list[PaperRun], quick: bool = False) -> SweepSpec:
    """The explicit-case sweep of the runs (engine ``exudyn``, case function
    :func:`paper_case_outputs`)."""
    return SweepSpec(scene=base_scene(), engine="exudyn",
                     fixed=dict(QUICK_OVERRIDES) if quick else {},
                     cases=tuple({"id": r.id, **r.overrides} for r in runs), function=CASE_FUNCTION)


def _case_files(files: Path, run: PaperRun, record: dict[str, Any]) -> Path | None:
    """The folder of a recorded run's summary and history; ``None`` for a run that raised."""
    name = record.get("files")
    if not name:
        if record["status"] == "ok":
            raise SweepError(f"the record of case {run.id} names no files (was it made by another "
                             "case function?); rerun with --restart")
        return None
    folder = files / name
    needed = ["summary.json"] + (["history.npz"] if record["status"] == "ok" else [])
    missing = [n for n in needed if not (folder / n).is_file()]
    if missing:
        raise SweepError(f"{folder}: {', '.join(missing)} missing (case {run.id}); rerun with --restart")
    return folder


def _remove_unreferenced(files: Path, records: dict[str, dict[str, Any]]) -> None:
    """Delete case folders no record names (cases interrupted after writing, replaced records)."""
    if not files.is_dir():
        return
    keep = {r.get("files") for r in records.values()}
    for entry in files.iterdir():
        if entry.name not in keep:
            shutil.rmtree(entry) if entry.is_dir() else entry.unlink()


def reproduce(out: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
              restart: bool = False, retry_failed: bool = False,
              progress: bool | None = None) -> int:
    """Run the paper's cases under both parameter sets through the sweep runner and write the
    report into ``out``; returns 0, or 3 when a run failed (the report covers the others).

    Parameters
    ----------
    out : path
        Report folder, replaced atomically when the report is complete; the sweep (plan,
        records, per-run files) lives in ``out/runs/`` and is kept, so that a rerun of an
        interrupted invocation runs only the cases without a record.
    quick : bool
        Three cases per set, accuracy 1e-4, one revolution.
    workers : int, optional
        Local worker processes (default: the sweep runner's, every available core); 1 runs the
        cases in this process.
    restart, retry_failed : bool
        Discard every earlier record; rerun the cases recorded with a status other than ``ok``.
    progress : bool, optional
        The sweep runner's progress bar on stderr; default when stderr is a terminal.

    Raises
    ------
    SweepError
        ``out`` is not a folder, ``out/runs`` holds another plan (e.g. ``--quick`` then not)
        or another invocation is running there (raised before anything runs); or, after the
        runs, a recorded case's files are missing (the records are kept; ``restart`` helps).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {str(out)!r} exists and is not a folder")
    runs = paper_runs(quick)
    folder_runs = out / RUNS_DIR
    files = folder_runs / FILES_DIR
    previous = os.environ.get(FILES_ENV)
    os.environ[FILES_ENV] = str(files.resolve())
    try:
        sweep = run_sweep(sweep_spec(runs, quick), folder_runs, workers=workers, restart=restart,
                          retry_failed=retry_failed, progress=progress)
    finally:
        if previous is None:
            os.environ.pop(FILES_ENV, None)
        else:
            os.environ[FILES_ENV] = previous
    records = read_records(folder_runs / CASES_FILE)
    rows, summaries = [], []
    histories: dict[str, dict[str, Any]] = {r.parameters: {} for r in runs}
    for run in runs:
        record = records[run.id]
        rows.append(case_row(run.case, run.parameters, record))
        case_files = _case_files(files, run, record)
        if case_files is None:
            summaries.append({"status": record["status"], "reason": record.get("reason"),
                              "case": run.id})
            continue
        summaries.append(json.loads((case_files / "summary.json").read_text(encoding="utf-8")))
        if record["status"] != "ok":
            continue
        with np.load(case_files / "history.npz") as data:
            table = pd.DataFrame({c: data[c] for c in HISTORY_COLUMNS})
        hist, case = histories[run.parameters], run.case
        if case["study"] == "table2" and case["shaft_angle_deg"] in HISTORY_ANGLES:
            hist[f"angle {case['shaft_angle_deg']:g} deg"] = table
        if case["study"] == "table2" and case["shaft_angle_deg"] == 10.0:
            hist["10deg"] = table
        if case["study"] == "speed":
            hist[f"speed {case['speed_rpm']:g} rpm"] = table
    _remove_unreferenced(files, records)
    frame = pd.DataFrame(rows)
    wall = sweep["wall_time_s"]
    reused = len(runs) - sweep["run_now"]
    with atomic_directory(out) as folder:
        write_report(folder, frame, histories, quick, wall, reused)
        (folder / "summaries.json").write_text(dumps(summaries) + "\n", encoding="utf-8")
        os.replace(folder_runs, folder / RUNS_DIR)
    failed = [r for r in runs if records[r.id]["status"] != "ok"]
    for run in failed:
        record = records[run.id]
        print(f"  {run.id}: {record['status']}: {record.get('reason')}", file=sys.stderr)
    executor = sweep["executor"]
    how = (f" in {wall:.1f} s, {executor['kind']}"
           + (f", {executor['workers']} workers" if executor.get("workers", 1) > 1 else "")
           if sweep["run_now"] else "")
    print(f"wrote {out}/report.md ({len(runs)} runs, {len(runs) - len(failed)} ok; "
          f"{sweep['run_now']} run now{how}"
          + (f"; {reused} from earlier records in {out}/{RUNS_DIR}, --restart runs them again"
             if reused else "") + ")", file=sys.stderr)
    return 0 if not failed else 3
