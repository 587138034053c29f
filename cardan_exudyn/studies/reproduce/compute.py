"""``cardan reproduce``: the paper's results with friction, under its three parameter sets, as a
report.

For each parameter set of :data:`reference.paper.parameter_sets.PARAMETER_SETS` (``physical``, the default:
every open value a dimension or physical quantity inside its plausible range; ``literal``: the
paper read literally, kept as evidence; ``matched``: fitted to the paper's numbers with values
that are not plausible dimensions) the report has

- Table 2 (0 to 35 deg at 2000 rpm) and the speed study (500, 1000, 2000 rpm at 10 deg) next to
  the paper, with both mean-efficiency definitions (one minus lost over input energy over whole
  revolutions, and the time average of eq. (18)), each number with its engine, engine version,
  step and estimated error; the cases the set was fitted to are marked, and its errors against
  the paper (RMS and largest) are summarised for the fitted and the held-out cases apart;
- the set's parameter table (value, plausible range, inside it or not, fitted or not, reason),
  and the envelope of each paper number over the plausible box when it is stored;
- the per-pair loss breakdown (share of the input work lost in each pair);
- the time histories of Figures 4 (efficiency at 10 deg), 5 (power loss per pair at 10 deg),
  6 (efficiency at several angles) and 7 (efficiency at several speeds, against the input angle);
- the energy balance residual of every run, and the assumption register.

This module runs the cases and registers the command; :mod:`.reproduce_report` writes the report.

How the runs are made
---------------------
The runs (the eleven cases under each parameter set: 33; 9 with ``--quick``) are one sweep of
:mod:`cardan_exudyn.sweep` with an explicit case list, in ``OUT/runs/``. The base scene is
``paper_scene(10 deg, 2000 rpm)`` of the ``physical`` set; each case's overrides are the
leaf-by-leaf difference between its own scene (:func:`reference.paper.scenes.paper_scene`, any parameter
set) and the base, and :func:`paper_runs` checks that the runner rebuilds exactly that scene
(the ``physical`` set's output load, solved per case for a mean input torque of 2 N m, is one
such leaf). Case ids read like ``matched-table2-35deg-2000rpm``. So the cases can run in worker
processes (``workers``), a rerun of an interrupted ``cardan reproduce`` runs only the cases
without a record (a rerun of a finished one redraws the report from the records; ``restart``
runs everything again), a case that fails or raises is recorded with its status and reason
while the report is written from the others, and progress is the sweep runner's bar.

Besides each run's numbers (the record: a few scalars, :func:`run_numbers`), the report needs the
engine's full summary (``summaries.json``) and, for Figures 4-7, time histories. The case function
:func:`paper_case_outputs` writes both into a folder of its own, ``OUT/runs/files/<scene
name>-<random token>/`` (``summary.json`` and ``history.npz`` with the columns of
:data:`HISTORY_COLUMNS`, each written to a temporary name, fsync'ed and renamed), and returns that
folder's name in its record (``files``). Why this way:

- records stay small (about 1.4 kB each): the histories were about 12,700 rows x 6 columns for
  22 runs, which in the records would be about 1.6 MB of JSON in ``cases.jsonl`` and a text cell
  of up to 180 kB per case in the sweep's ``results.csv`` (as ``.npz`` files: 0.9 MB);
  recomputing them after the sweep would run 14 of the 22 scenes twice;
- the files are complete before the function returns, so a record in ``cases.jsonl`` (which the
  runner writes after the function returns) implies its files exist: a resumed run finds the
  files of every recorded case; a random token keeps two runs of one scene (Table 2's 10 deg case
  is the speed study's 2000 rpm case) and a rerun of a failed case apart; folders no record names
  (a case interrupted after writing them) are deleted once every case has a record;
- the folder reaches the case function as its argument ``files`` (the sweep's
  ``function_args``), which the runner sends with the function's name to every worker, in this
  process or a spawned one: the folder is no part of a scene (in it, it would change the scene
  and its hash whenever the report folder moves), and it is part of the sweep's plan, so a
  report folder moved elsewhere takes ``--restart``. Without it the function writes nothing and
  returns the numbers, so it also serves ``cardan sweep --function
  cardan_exudyn.studies.reproduce.compute:paper_case_outputs``;
- ``.npz`` keeps float64 exactly (whether a CSV reads back bit for bit depends on the pandas
  version's parser), so the figures are drawn from exactly the engine's numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn import engines
from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory, atomic_write
from cardan_exudyn.report.format import number
from cardan_exudyn.sweep import CASES_FILE, SweepError, SweepSpec, flatten_paths, read_records, run_sweep
from reference.paper.cases import paper_cases
from reference.paper.parameter_sets import DEFAULT_PARAMETER_SET, PARAMETER_SETS
from reference.paper.scenes import paper_scene
from reference.results.result import Result
from reference.results.summary import Status
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene

__all__ = ["RUNS_DIR", "FILES_DIR", "CASE_FUNCTION", "HISTORY_COLUMNS", "QUICK_OVERRIDES",
           "PaperRun", "Reproduction", "run_numbers", "paper_case_outputs", "selected_cases",
           "base_scene", "paper_runs", "sweep_spec", "reproduce", "register", "handler",
           "outcome_lines"]

RUNS_DIR, FILES_DIR = "runs", "files"
CASE_FUNCTION = "cardan_exudyn.studies.reproduce.compute:paper_case_outputs"
HISTORY_COLUMNS = ("t", "theta_in", "efficiency", "power_in", *(f"power_loss_{pair}" for pair in PAIR_NAMES))
QUICK_OVERRIDES = {"numerics.accuracy": 1e-4, "revolutions": 1.0}
HISTORY_ANGLES = (0.0, 10.0, 20.0, 35.0)
BASE_ANGLE_DEG, BASE_SPEED_RPM = 10.0, 2000.0


def run_numbers(result: Result) -> dict[str, Any]:
    """Status, reason and, for a run that is ``ok``, the numbers the report tabulates.

    Works in J (``input_work_J``, ``loss_work_J``, ``energy_balance_residual_J``: input minus
    output minus friction loss work minus the change of mechanical energy, trapezoidal over the
    run), ``mean_torque_in`` and ``output_load_N_m`` (the scene's constant load) in N m,
    ``dt_s`` (the step the run was made with), ``accuracy_target`` (the scene's
    ``numerics.accuracy``) and ``wall_time_s`` in s, ``steps_per_revolution``
    (at the mean input speed); ``engine`` and ``engine_version`` name what computed them;
    efficiencies, loop gain and loss shares are dimensionless.
    """
    s = result.summary
    out: dict[str, Any] = {"status": s.status, "reason": s.reason}
    if not result.success:
        return out
    t = result.table
    energy = t["energy_kinetic"] + t["energy_potential"]
    work = {c: float(np.trapezoid(t[c], t["t"])) for c in ("power_in", "power_out", "power_loss")}
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
        "energy_balance_residual_J": work["power_in"] - work["power_out"] - work["power_loss"]
        - float(energy.iloc[-1] - energy.iloc[0]),
        "loop_gain_estimate": friction.loop_gain_estimate,
        "friction_evaluations_per_step": friction.mean_iterations_per_step,
        "steps": s.steps,
        "wall_time_s": s.wall_time_s,
    })
    for pair in PAIR_NAMES:
        out[f"loss_share_{pair}"] = s.pair_loss_work[pair] / s.input_work
    return out


def paper_case_outputs(scene: Scene, engine: str, files: str | None = None) -> dict[str, Any]:
    """Sweep case function: run ``scene`` and return :func:`run_numbers`.

    Parameters
    ----------
    scene : Scene
        The case's scene.
    engine : str
        Engine name.
    files : str, optional
        Folder under which the run's ``summary.json`` and ``history.npz`` go, into a folder of
        their own whose name the outputs give as ``files``; nothing is written without it.
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
    """Every run in report order (parameter set, then the paper's case order).

    A run's overrides are the leaves in which its scene differs from :func:`base_scene`; the
    scene the sweep runner builds from them (with ``--quick``'s overrides) is checked to equal
    ``paper_scene(angle, speed, parameters)`` (with the same overrides).
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
    """The explicit-case sweep of the runs (engine ``exudyn``, case function
    :func:`paper_case_outputs`, writing into ``files`` when given)."""
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
    """The engine summary of every run (a stand-in naming the status for a run that raised) and
    the time histories by parameter set and label, from the runs' files."""
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
    """What :func:`reproduce` did.

    Attributes
    ----------
    out : Path
        The report folder.
    runs : list of PaperRun
        Every run, in report order.
    records : dict
        Case id -> sweep record (status, reason, the numbers of :func:`run_numbers`).
    sweep : dict
        The sweep's summary (``OUT/runs/sweep.json``): ``run_now``, ``wall_time_s`` [s],
        ``executor``, ...
    """

    out: Path
    runs: list[PaperRun]
    records: dict[str, dict[str, Any]]
    sweep: dict[str, Any]

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


def reproduce(out: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
              restart: bool = False, retry_failed: bool = False,
              progress: bool | None = None) -> Reproduction:
    """Run the paper's cases under every parameter set through the sweep runner and write the
    report into ``out``.

    Parameters
    ----------
    out : path
        Report folder, replaced atomically when the report is complete; the sweep (plan,
        records, per-run files) lives in ``out/runs/`` and is kept, so that a rerun of an
        interrupted invocation runs only the cases without a record.
    quick : bool
        Three cases per set (0 and 10 deg at 2000 rpm, 500 rpm), accuracy 1e-4, one revolution.
    workers : int, optional
        Local worker processes (default: the sweep runner's, every available core); 1 runs the
        cases in this process.
    restart, retry_failed : bool
        Discard every earlier record; rerun the cases recorded with a status other than ``ok``.
    progress : bool, optional
        The sweep runner's progress bar on stderr; default when stderr is a terminal.

    Returns
    -------
    Reproduction
        The runs, their records and the sweep's summary; ``success`` is False when a run failed
        (the report covers the others).

    Raises
    ------
    SweepError
        ``out`` is not a folder, ``out/runs`` holds another plan (e.g. ``--quick`` then not)
        or another invocation is running there (raised before anything runs); or, after the
        runs, a recorded case's files are missing (the records are kept; ``restart`` helps).
    cardan_exudyn.sweep.executors.SweepInterrupted
        Ctrl-C or SIGTERM (a :class:`KeyboardInterrupt`): the runs finished before it are
        recorded in ``out/runs``, none as failed, the report folder is as it was; the same call
        (command) runs only the missing runs (``docs/outputs.md``).
    """
    # pandas and matplotlib (about 1 s) load only to write a report: `cardan` imports this module
    # to register the command
    from cardan_exudyn.studies.reproduce import report as reproduce_report

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {str(out)!r} exists and is not a folder")
    runs = paper_runs(quick)
    folder_runs = out / RUNS_DIR
    files = folder_runs / FILES_DIR
    sweep = run_sweep(sweep_spec(runs, quick, files.resolve()), folder_runs, workers=workers,
                      restart=restart, retry_failed=retry_failed, progress=progress)
    records = read_records(folder_runs / CASES_FILE)
    rows = [reproduce_report.case_row(r.case, r.parameters, records[r.id]) for r in runs]
    summaries, histories = _collect(runs, records, files)
    _remove_unreferenced(files, records)
    result = Reproduction(out, runs, records, sweep)
    with atomic_directory(out) as folder:
        reproduce_report.write_report(folder, rows, histories, quick, sweep["wall_time_s"],
                                      result.reused, RUNS_DIR)
        (folder / "summaries.json").write_text(dumps(summaries) + "\n", encoding="utf-8")
        os.replace(folder_runs, folder / RUNS_DIR)
    return result


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan reproduce`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("reproduce", help="reproduce the paper's studies into a report folder")
    p.add_argument("--out", metavar="DIR", default="reports/reproduce", help="report folder")
    p.add_argument("--quick", action="store_true", help="fewer scenes and a coarser accuracy")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the runs recorded in OUT/runs and run every case again")
    p.add_argument("--retry-failed", action="store_true", help="rerun the cases recorded as failed")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan reproduce``; exit 3 when a run failed (the report covers the others)."""
    out_folder(args.out)
    try:
        result = reproduce(args.out, quick=args.quick, workers=args.workers, restart=args.restart,
                           retry_failed=args.retry_failed)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    for line in outcome_lines(result):
        print(line, file=sys.stderr)
    return EXIT_OK if result.success else EXIT_FAILED


def outcome_lines(result: Reproduction) -> list[str]:
    """What ``cardan reproduce`` says at the end: each failed run, then where the report is."""
    lines = [f"  {run.id}: {result.records[run.id]['status']}: {result.records[run.id].get('reason')}"
             for run in result.failed]
    sweep, out = result.sweep, result.out
    executor = sweep["executor"]
    how = (f" in {number(sweep['wall_time_s'], '.1f')} s, {executor['kind']}"
           + (f", {executor['workers']} workers" if executor.get("workers", 1) > 1 else "")
           if sweep["run_now"] else "")
    earlier = (f"; {result.reused} from earlier records in {out}/{RUNS_DIR}, --restart runs them again"
               if result.reused else "")
    lines.append(f"wrote {out}/report.md ({len(result.runs)} runs, "
                 f"{len(result.runs) - len(result.failed)} ok; {sweep['run_now']} run now{how}"
                 f"{earlier})")
    return lines
