"""The runs of ``cardan reproduce``: the paper's eleven cases under each parameter set, as one sweep.

Each case writes its ``summary.json`` and ``history.npz`` into ``OUT/runs/files/<name>-<token>/``
and names it in its record: records stay a few scalars, ``.npz`` keeps float64 exactly, and the
folder is a ``function_args`` entry, not part of the scene (whose hash would then move with it).
"""

from __future__ import annotations

import json
import os
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn import engines
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_write
from cardan_exudyn.sweep import CASES_FILE, SweepError, SweepSpec, flatten_paths, read_records, run_sweep
from reference.paper import DEFAULT_PARAMETER_SET, PARAMETER_SETS, paper_cases, paper_scene
from reference.results.result import Result
from reference.results.summary import Status
from reference.scene import replace, scene_to_dict
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["RUNS_DIR", "FILES_DIR", "CASE_FUNCTION", "HISTORY_COLUMNS", "QUICK_OVERRIDES",
           "PaperRun", "Reproduction", "run_numbers", "paper_case_outputs", "selected_cases",
           "base_scene", "paper_runs", "sweep_spec", "run_cases", "energy_balance_residual"]

RUNS_DIR = "runs"
"""The sweep's folder inside the report folder."""
FILES_DIR = "files"
"""The cases' own files inside :data:`RUNS_DIR`."""
CASE_FUNCTION = "cardan_exudyn.studies.reproduce.compute:paper_case_outputs"
HISTORY_COLUMNS = ("t", "theta_in", "efficiency", "power_in", *(f"power_loss_{pair}" for pair in PAIR_NAMES))
QUICK_OVERRIDES = {"numerics.accuracy": 1e-4, "revolutions": 1.0}
HISTORY_ANGLES = (0.0, 10.0, 20.0, 35.0)
BASE_ANGLE_DEG = 10.0
BASE_SPEED_RPM = 2000.0


def run_numbers(result: Result) -> dict[str, Any]:
    """Status, reason and, for an ``ok`` run, the numbers the report tabulates (works [J], torques
    [N m], ``dt_s``, ``wall_time_s`` [s], ``accuracy_target``, ``steps_per_revolution``, engine and
    version; efficiencies, loop gain and loss shares [-]).
    """
    s = result.summary
    out: dict[str, Any] = {"status": s.status, "reason": s.reason}
    if not result.success:
        return out
    friction = s.friction
    speed = s.mean_speed_in
    out.update({
        "engine": s.engine,
        "engine_version": s.engine_version,
        "dt_s": s.dt,
        "steps_per_revolution": (2 * np.pi / (abs(speed) * s.dt) if s.dt and speed else None),
        "output_load_N_m": s.scene.get("load", {}).get("torque"),
        "mean_efficiency": s.mean_efficiency,
        "efficiency_error_estimate": s.efficiency_error_estimate,
        "accuracy_target": s.scene.get("numerics", {}).get("accuracy"),
        "accuracy_met": s.accuracy_met,
        "mean_instantaneous_efficiency": s.mean_instantaneous_efficiency,
        "mean_torque_in": s.mean_torque_in,
        "input_work_J": s.input_work,
        "loss_work_J": s.loss_work,
        "energy_balance_residual_J": energy_balance_residual(result.table),
        "loop_gain_estimate": friction.loop_gain_estimate,
        "friction_evaluations_per_step": friction.mean_iterations_per_step,
        "steps": s.steps,
        "wall_time_s": s.wall_time_s,
    })
    for pair in PAIR_NAMES:
        out[f"loss_share_{pair}"] = s.pair_loss_work[pair] / s.input_work
    return out


def energy_balance_residual(table) -> float:
    """Input minus output minus friction loss work minus the change of mechanical energy over a
    run's time ``table`` [J], each work trapezoidal: zero up to the integration error."""
    energy = table["energy_kinetic"] + table["energy_potential"]
    work = {c: float(np.trapezoid(table[c], table["t"])) for c in ("power_in", "power_out", "power_loss")}
    return work["power_in"] - work["power_out"] - work["power_loss"] - float(energy.iloc[-1] - energy.iloc[0])


def paper_case_outputs(scene: Scene, engine: str, files: str | None = None) -> dict[str, Any]:
    """Sweep case function: run ``scene`` with ``engine`` and return :func:`run_numbers`; with
    ``files``, the run's ``summary.json`` and ``history.npz`` go into a new folder under it, named
    in the outputs.
    """
    result = engines.run(scene, engine)
    out = run_numbers(result)
    if files:
        folder = Path(files) / f"{scene.name}-{uuid.uuid4().hex[:12]}"
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write(folder / "summary.json",
                     lambda f: f.write((dumps(result.summary) + "\n").encode("utf-8")))
        if result.success and result.table is not None:
            columns = {c: result.table[c].to_numpy(dtype=float) for c in HISTORY_COLUMNS}
            atomic_write(folder / "history.npz", lambda f: np.savez(f, **columns))
        out["files"] = folder.name
    return out


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
    """The sweep's base scene: the default (``physical``) set at 10 deg, 2000 rpm."""
    return paper_scene(BASE_ANGLE_DEG, BASE_SPEED_RPM, parameters=DEFAULT_PARAMETER_SET)


def paper_runs(quick: bool = False) -> list[PaperRun]:
    """Every run in report order (parameter set, then the paper's case order); each run's overrides
    are checked to rebuild ``paper_scene(angle, speed, parameters)`` from :func:`base_scene`.
    """
    base = base_scene()
    fixed = QUICK_OVERRIDES if quick else {}
    built_base = replace(base, **fixed) if fixed else base
    base_leaves = flatten_paths(scene_to_dict(base))
    runs = []
    for parameters in PARAMETER_SETS:
        for case in selected_cases(quick):
            scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"], parameters=parameters)
            overrides = _overrides(scene, base_leaves)
            expected = replace(scene, **fixed) if fixed else scene
            if replace(built_base, **overrides) != expected:
                raise RuntimeError(f"{scene.name}: the overrides do not rebuild the scene")
            run_id = (f"{parameters}-{case['study']}-{case['shaft_angle_deg']:g}deg-"
                      f"{case['speed_rpm']:g}rpm")
            runs.append(PaperRun(run_id, parameters, case, overrides))
    return runs


def _overrides(scene: Scene, base_leaves: dict[str, Any]) -> dict[str, Any]:
    """The leaves (dotted paths) in which ``scene`` differs from the base scene's."""
    leaves = flatten_paths(scene_to_dict(scene))
    if set(leaves) != set(base_leaves):
        raise RuntimeError(f"{scene.name}: scene fields {sorted(set(leaves) ^ set(base_leaves))} "
                           "differ in kind from the base scene's")
    return {k: v for k, v in leaves.items() if v != base_leaves[k]}


def sweep_spec(runs: list[PaperRun], quick: bool = False,
               files: str | os.PathLike | None = None) -> SweepSpec:
    """The explicit-case :class:`SweepSpec` of ``runs`` (``--quick`` overrides when ``quick``), whose
    case function writes each run's files under ``files`` (none: nothing written).
    """
    return SweepSpec(scene=base_scene(), engine="exudyn",
                     fixed=dict(QUICK_OVERRIDES) if quick else {},
                     cases=tuple({"id": r.id, **r.overrides} for r in runs), function=CASE_FUNCTION,
                     function_args={"files": str(files)} if files is not None else {})


def _case_files(files: Path, run: PaperRun, record: dict[str, Any]) -> Path | None:
    """The folder of a recorded run's summary and history; ``None`` for a run that raised."""
    name = record.get("files")
    if not name:
        if record["status"] == Status.OK:
            raise SweepError(f"the record of case {run.id} names no files (was it made by another "
                             "case function?); rerun with --restart")
        return None
    folder = files / name
    needed = ["summary.json"] + (["history.npz"] if record["status"] == Status.OK else [])
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


def _history_labels(case: dict[str, Any]) -> list[str]:
    """Where a run's history appears: Figure 6's angles, Figures 4-5 (10 deg), Figure 7's speeds."""
    labels = []
    if case["study"] == "table2" and case["shaft_angle_deg"] in HISTORY_ANGLES:
        labels.append(f"angle {case['shaft_angle_deg']:g} deg")
    if case["study"] == "table2" and case["shaft_angle_deg"] == 10.0:
        labels.append("10deg")
    if case["study"] == "speed":
        labels.append(f"speed {case['speed_rpm']:g} rpm")
    return labels


def _load_history(path: Path) -> dict[str, np.ndarray]:
    with np.load(path) as data:
        return {c: data[c] for c in HISTORY_COLUMNS}


def _collect(runs: list[PaperRun], records: dict[str, dict[str, Any]],
             files: Path) -> tuple[list[dict[str, Any]], dict[str, dict[str, Any]]]:
    """Every run's engine summary (a stand-in naming the status for a run that raised) and the time
    histories by parameter set and label, from the runs' files.
    """
    summaries: list[dict[str, Any]] = []
    histories: dict[str, dict[str, Any]] = {r.parameters: {} for r in runs}
    for run in runs:
        record = records[run.id]
        case_files = _case_files(files, run, record)
        if case_files is None:
            summaries.append({"status": record["status"], "reason": record.get("reason"),
                              "case": run.id})
            continue
        summaries.append(json.loads((case_files / "summary.json").read_text(encoding="utf-8")))
        if record["status"] == Status.OK:
            history = _load_history(case_files / "history.npz")
            for label in _history_labels(run.case):
                histories[run.parameters][label] = history
    return summaries, histories


@dataclass(frozen=True)
class Reproduction:
    """What :func:`reproduce` did: folder ``out``, ``runs`` in report order, ``records`` (case id ->
    sweep record), ``sweep`` (``sweep.json``), ``summaries`` (engine summary per run), ``histories``
    (set -> label -> time history, SI units) and ``quick``.
    """

    out: Path
    runs: list[PaperRun]
    records: dict[str, dict[str, Any]]
    sweep: dict[str, Any]
    summaries: list[dict[str, Any]]
    histories: dict[str, dict[str, Any]]
    quick: bool = False

    @property
    def failed(self) -> list[PaperRun]:
        """The runs whose status is not ``ok``."""
        return [r for r in self.runs if self.records[r.id]["status"] != Status.OK]

    @property
    def success(self) -> bool:
        """True when every run ended ``ok``."""
        return not self.failed

    @property
    def reused(self) -> int:
        """Runs taken from the records of an earlier invocation."""
        return len(self.runs) - self.sweep["run_now"]


def run_cases(out: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
              restart: bool = False, retry_failed: bool = False,
              progress: bool | None = None) -> Reproduction:
    """Run (or resume) the cases in ``out/runs/`` and collect their records and files.

    ``quick``: three cases per set, accuracy 1e-4, one revolution; ``workers``, ``restart``,
    ``retry_failed``, ``progress``: as :func:`cardan_exudyn.sweep.run_sweep`. Raises SweepError
    (another plan or invocation in ``out/runs``; a recorded case's files missing) and
    ``SweepInterrupted`` (the same call resumes).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {str(out)!r} exists and is not a folder")
    runs = paper_runs(quick)
    folder_runs = out / RUNS_DIR
    files = folder_runs / FILES_DIR
    sweep = run_sweep(sweep_spec(runs, quick, files.resolve()), folder_runs, workers=workers,
                      restart=restart, retry_failed=retry_failed, progress=progress)
    records = read_records(folder_runs / CASES_FILE)
    summaries, histories = _collect(runs, records, files)
    _remove_unreferenced(files, records)
    return Reproduction(out, runs, records, sweep, summaries, histories, quick)
