"""The report of ``cardan reproduce``: ``results.csv``, ``assumptions.csv``, the figures,
``summaries.json`` and ``report.md``. Every number is computed from ``reference/paper/data/paper.toml``;
only ``paper_mean_efficiency`` is copied from the paper.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report import plots
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.studies.reproduce.compute import RUNS_DIR, Reproduction
from reference.paper import (
    DEFAULT_PARAMETER_SET,
    PARAMETER_SETS,
    assumption_register,
    envelope,
    parameter_set,
    parameter_table,
    stated_values,
)
from reference.paper.cases import in_fit
from reference.paper.parameter_sets import LEVER_DIMENSIONS
from reference.results.summary import Status
from reference.scene.joint import PAIR_NAMES

__all__ = ["RUN_NUMBERS", "START_UP_STEPS", "fit_case_keys", "case_row", "write_reproduction", "write_report",
           "draw_figures", "report_text", "error_summary", "parameter_rows", "steady_revolution"]

# the numbers of a run, in the order of the report's results.csv (after difference_to_paper)
RUN_NUMBERS = ("efficiency_error_estimate", "accuracy_met", "accuracy_target", "engine",
               "engine_version", "dt_s", "steps_per_revolution", "output_load_N_m", "mean_torque_in",
               "input_work_J", "loss_work_J", "energy_balance_residual_J",
               "loop_gain_estimate", "friction_evaluations_per_step", "steps", "wall_time_s",
               *(f"loss_share_{pair}" for pair in PAIR_NAMES))
MAIN_COLUMNS = ["study", "shaft_angle_deg", "speed_rpm", "fit", "paper_mean_efficiency",
                "mean_efficiency", "difference_to_paper", "efficiency_error_estimate", "accuracy_met",
                "mean_instantaneous_efficiency", "engine", "engine_version", "dt_s",
                "steps_per_revolution"]
MAIN_FORMATS = {"dt_s": ".3g", "steps_per_revolution": ".0f", "efficiency_error_estimate": ".1e",
                "difference_to_paper": "+.4f"}
FAILED_COLUMNS = ["parameters", "study", "shaft_angle_deg", "speed_rpm", "status", "reason"]
LOSS_COLUMNS = ["parameters", "shaft_angle_deg", "speed_rpm", *(f"loss_share_{p}" for p in PAIR_NAMES)]
CHECK_COLUMNS = ["parameters", "shaft_angle_deg", "speed_rpm", "output_load_N_m", "input_work_J",
                 "loss_work_J", "energy_balance_residual_J", "loop_gain_estimate",
                 "friction_evaluations_per_step", "steps", "wall_time_s"]
PARAMETER_COLUMNS = ["name", "value", "unit", "plausible", "inside", "fitted", "reason"]
ENVELOPE_COLUMNS = ["case", "paper", "lowest", "highest", "reachable", "closest"]
# the mean-efficiency figures: study, x column, x label, file name
MEAN_FIGURES = (("table2", "shaft_angle_deg", "shaft angle [deg]", "table2.png"),
                ("speed", "speed_rpm", "input speed [rpm]", "speed.png"))
START_UP_STEPS = 40
"""Steps at the start of a run left out of the time-history figures: the generalized-alpha
integrator starts with its acceleration-like variables equal to the consistent accelerations,
which excites a period-two oscillation of the reactions (and of every pair's friction, which
follows them) that decays by a factor of about 0.8 per step at spectral radius 0.6 (0.6 at 0.3,
gone after three steps at 0): the reactions at the same input angle one revolution later are
smooth. After 40 steps it is below 1e-3 of its first amplitude."""


def fit_case_keys(parameters: str) -> list[str]:
    """The cases a parameter set was fitted to, as ``study:angle:rpm`` keys (none: not fitted)."""
    return list(parameter_set(parameters).get("fit_cases", []))


def case_row(case: Mapping[str, Any], parameters: str, record: Mapping[str, Any]) -> dict[str, Any]:
    """One row of ``results.csv``: paper ``case``, its value, whether set ``parameters`` was fitted to
    it (``used_in_fit``) and, for an ``ok`` ``record``, its numbers (SI units).
    """
    used = in_fit(case, fit_case_keys(parameters))
    row: dict[str, Any] = {
        "parameters": parameters,
        "study": case["study"],
        "shaft_angle_deg": case["shaft_angle_deg"],
        "speed_rpm": case["speed_rpm"],
        "paper_mean_efficiency": case["paper_mean_efficiency"],
        "status": record["status"],
        "reason": record.get("reason") or "",
        "used_in_fit": used,
        "fit": "fitted" if used else "held out",
    }
    if record["status"] != Status.OK:
        return row
    row["mean_efficiency"] = _value(record, "mean_efficiency")
    row["mean_instantaneous_efficiency"] = _value(record, "mean_instantaneous_efficiency")
    row["difference_to_paper"] = row["mean_efficiency"] - case["paper_mean_efficiency"]
    row.update({key: _value(record, key) for key in RUN_NUMBERS})
    return row


def _value(record: Mapping[str, Any], key: str) -> Any:
    """A recorded number; NaN where the record has none (JSON null)."""
    value = record.get(key)
    return float("nan") if value is None else value


def write_report(folder: Path, rows: Sequence[Mapping[str, Any]] | pd.DataFrame,
                 histories: Mapping[str, Mapping[str, Any]], quick: bool, wall: float,
                 reused: int = 0, runs_dir: str = "runs") -> None:
    """Write ``report.md``, ``results.csv``, ``assumptions.csv`` and the figures into the existing
    ``folder``, from ``rows`` (one :func:`case_row` per run) and ``histories`` (set -> label ->
    time history); ``quick``, ``wall`` [s], ``reused`` and ``runs_dir`` go into the head.
    """
    rows = pd.DataFrame(rows)
    rows.to_csv(folder / "results.csv", index=False)
    register = pd.DataFrame(assumption_register())
    register.to_csv(folder / "assumptions.csv", index=False)
    figures = draw_figures(folder, rows, histories)
    text = report_text(rows, register, figures, quick=quick, wall=wall, reused=reused,
                       runs_dir=runs_dir)
    (folder / "report.md").write_text(text, encoding="utf-8")


def write_reproduction(result: Reproduction) -> Path:
    """Write the report folder ``result.out`` (replaced atomically): the report of
    :func:`write_report`, ``summaries.json``, and the sweep's ``runs/`` moved into it."""
    rows = [case_row(r.case, r.parameters, result.records[r.id]) for r in result.runs]
    with atomic_directory(result.out) as folder:
        write_report(folder, rows, result.histories, result.quick, result.sweep["wall_time_s"],
                     result.reused, RUNS_DIR)
        (folder / "summaries.json").write_text(dumps(result.summaries) + "\n", encoding="utf-8")
        os.replace(result.out / RUNS_DIR, folder / RUNS_DIR)
    return result.out


def steady_revolution(history: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """``(angle, rows)``: the history's last whole input revolution, without the first
    :data:`START_UP_STEPS` steps; ``angle`` [deg] from 0 to 360, ``rows`` a boolean mask.
    """
    theta = np.asarray(history["theta_in"], dtype=float)
    start = theta[-1] - 2 * np.pi
    rows = theta >= start - 1e-9
    rows[:START_UP_STEPS] = False
    offset = 2 * np.pi * np.floor(start / (2 * np.pi) + 1e-9)
    return np.degrees(theta[rows] - offset), rows


def start_up_effect(history: Mapping[str, Any]) -> float | None:
    """Mean efficiency of the first input revolution minus that of the last [-] (None with fewer than
    two): the whole effect of the start-up oscillation, the motion being periodic per revolution.
    """
    theta = np.asarray(history["theta_in"], dtype=float)
    if theta[-1] < 4 * np.pi - 1e-9:
        return None
    t = np.asarray(history["t"], float)
    power_in = np.asarray(history["power_in"], float)
    loss = sum(np.asarray(history[f"power_loss_{p}"], float) for p in PAIR_NAMES)

    def efficiency(rows: np.ndarray) -> float:
        """The mean efficiency [-] of the ``rows`` selected: one minus lost over input work."""
        return 1.0 - np.trapezoid(loss[rows], t[rows]) / np.trapezoid(power_in[rows], t[rows])

    return efficiency(theta <= 2 * np.pi + 1e-9) - efficiency(theta >= theta[-1] - 2 * np.pi - 1e-9)


def draw_figures(folder: Path, rows: pd.DataFrame,
                 histories: Mapping[str, Mapping[str, Any]]) -> list[tuple[str, str]]:
    """Save every figure of the report into ``folder`` from ``rows`` and ``histories``; returns (file
    name, caption) of each, in report order.
    """
    ok = rows[rows.status == Status.OK]
    figures = _mean_figures(folder, ok)
    for parameters in PARAMETER_SETS:
        figures += _history_figures(folder, parameters, histories.get(parameters, {}))
    return figures


def _mean_figures(folder: Path, ok: pd.DataFrame) -> list[tuple[str, str]]:
    """Mean efficiency against the paper over Table 2's angles and over the speeds, one panel per set."""
    figures = []
    for study, x, xlabel, name in MEAN_FIGURES:
        part = ok[ok.study == study]
        panels = {p: part[part.parameters == p].sort_values(x) for p in PARAMETER_SETS
                  if (part.parameters == p).any()}
        if panels:
            plots.save(plots.efficiency_against_paper(panels, x, xlabel), folder / name)
            figures.append((name, f"{'Table 2' if study == 'table2' else 'The speed study'}: mean "
                            "efficiency of each parameter set (lines) and the paper's values "
                            "(squares: filled where the set was fitted to it, open where held "
                            "out); each panel's axis spans its own data."))
    return figures


def _history_figures(folder: Path, parameters: str, hist: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Figures 4 and 5 (10 deg, 2000 rpm), 6 (angles) and 7 (speeds) over one steady revolution."""
    figures = []
    window = (f"the run's last input revolution (the first {START_UP_STEPS} steps of the run, "
              "where they fall in it, left out: see 'The start-up oscillation' below)")
    if "10deg" in hist:
        name = f"fig4_efficiency_10deg_{parameters}.png"
        plots.save(plots.efficiency_against_input_angle(_curves({"10 deg, 2000 rpm": hist["10deg"]}),
                                                        f"Figure 4 ({parameters})"), folder / name)
        figures.append((name, f"Figure 4 ({parameters}): eq. (18) at 10 deg, 2000 rpm, over {window}."))
        angle, sel = steady_revolution(hist["10deg"])
        name = f"fig5_pair_losses_{parameters}.png"
        losses = {p: np.asarray(hist["10deg"][f"power_loss_{p}"])[sel] for p in PAIR_NAMES}
        plots.save(plots.pair_losses(angle, losses, f"Figure 5 ({parameters}): power loss, 10 deg, "
                                                    "2000 rpm"), folder / name)
        effect = start_up_effect(hist["10deg"])
        said = ("" if effect is None else " The first revolution's mean efficiency differs from "
                f"the last's by {number(effect, '+.1e')} (the motion repeats every revolution: this is "
                "the start-up's whole effect on it).")
        figures.append((name, f"Figure 5 ({parameters}): power loss per pair over {window}.{said}"))
    for key, figure, what in (("angle ", 6, "several shaft angles at 2000 rpm"),
                              ("speed ", 7, "10 deg at several input speeds")):
        chosen = {k: v for k, v in hist.items() if k.startswith(key)}
        if chosen:
            name = f"fig{figure}_{'angles' if figure == 6 else 'speeds'}_{parameters}.png"
            plots.save(plots.efficiency_against_input_angle(_curves(chosen), f"Figure {figure} "
                                                            f"({parameters})"), folder / name)
            figures.append((name, f"Figure {figure} ({parameters}): eq. (18), {what}, against the "
                                  f"input angle over {window}."))
    return figures


def _curves(histories: Mapping[str, Any]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Label -> (input angle [deg], eq. (18) [-]) over each history's steady revolution."""
    out = {}
    for label, history in histories.items():
        angle, rows = steady_revolution(history)
        out[label] = (angle, np.asarray(history["efficiency"], dtype=float)[rows])
    return out


def report_text(rows: pd.DataFrame, register: pd.DataFrame, figures: Sequence[tuple[str, str]], *,
                quick: bool, wall: float, reused: int, runs_dir: str) -> str:
    """The markdown of ``report.md`` from ``rows``, the assumption ``register`` and ``figures``
    (:func:`draw_figures`); the rest as :func:`write_report`.
    """
    ok = rows[rows.status == Status.OK]
    md = (_head(rows, quick, wall, reused, runs_dir) + _parameter_sets() + _results(rows, ok)
          + _envelope() + _losses_and_checks(ok) + _plots(figures) + _appendix(register))
    return "\n".join(md)


def _table(frame: pd.DataFrame | Sequence[Mapping[str, Any]], columns: Sequence[str],
           spec: str = ".4f", formats: Mapping[str, str] | None = None) -> str:
    """A markdown table of ``columns``: floats with ``spec`` (angles and speeds ``g``) unless
    ``formats`` says otherwise, other values as they are, undefined numbers empty.
    """
    frame = pd.DataFrame(frame)
    chosen = {c: "g" if c.endswith(("_deg", "_rpm")) else spec
              for c in columns if c in frame and frame[c].dtype.kind == "f"}
    chosen.update({c: f for c, f in (formats or {}).items() if c in frame and frame[c].dtype.kind == "f"})
    return markdown_table(frame, columns, chosen, missing="")


def _head(rows: pd.DataFrame, quick: bool, wall: float, reused: int, runs_dir: str) -> list[str]:
    """The report's head: title, how it was generated, the parameter sets, the definitions."""
    earlier = (f" ({reused} of the {len(rows)} runs from the records of an earlier invocation in "
               f"`{runs_dir}/`)" if reused else "")
    ok = rows[rows.status == Status.OK]
    engines = sorted({f"{e} {v}" for e, v in zip(ok.get("engine", []), ok.get("engine_version", []),
                                                   strict=True)})
    return [
        "# The paper's results with friction under three parameter sets: physical (default), "
        "literal, matched\n",
        f"Generated by `cardan reproduce{' --quick' if quick else ''}` in {number(wall, '.1f')} s"
        + earlier + ". Every number and plot here was computed by the code in this repository from "
        "`reference/paper/data/paper.toml`; nothing is copied from the paper except the column "
        "`paper_mean_efficiency` (and the envelope's `paper`).\n",
        "**Parameter sets.** `physical` (the default of every scene, the CLI and the API): every "
        "open value a dimension or physical quantity inside its plausible range. `literal`: the "
        "paper read literally, kept as evidence. `matched`: fitted to the paper's numbers with "
        "values that are not plausible dimensions. Each set's values, ranges and reasons are under "
        "*Parameter sets*; every row below names its set.\n",
        f"**How every number was computed.** Engine: {', '.join(engines) or '-'} (the tables give "
        "engine and version per row), generalized-alpha with the step `dt_s` that the run's "
        "accuracy control chose (`steps_per_revolution` at the input speed), accuracy target "
        f"{_targets(ok)} on the mean efficiency. `efficiency_error_estimate` is the "
        "run's own estimate of its error (Richardson from a companion run at a coarser step, "
        "`docs/accuracy.md`), `accuracy_met` whether it is within the target.\n",
        "**Definitions.** `mean_efficiency` = 1 - (loss work)/(input work) over whole input "
        "revolutions; `mean_instantaneous_efficiency` = time average of eq. (18), which is "
        "unbounded where the input power changes sign (it does at large angles): empty where it "
        "is not defined or leaves [0, 1]. `fit`: `fitted` where the set's fitted values were "
        "identified from that case (or the same scene), `held out` otherwise; a set fitted to "
        "nothing has every case held out.\n",
    ]


def _targets(ok: pd.DataFrame) -> str:
    """The runs' accuracy targets (``numerics.accuracy``), as text."""
    values = sorted(set(ok["accuracy_target"].dropna())) if "accuracy_target" in ok else []
    return " / ".join(number(v, "g") for v in values) or "-"


def parameter_rows(parameters: str) -> list[dict[str, Any]]:
    """A set's parameter table for the report: the plausible range as text and ``inside`` as ``yes``,
    ``**NO**`` or ``-``; a moment lever is checked as the dimension it stands for
    (:data:`reference.paper.parameter_sets.LEVER_DIMENSIONS`).
    """
    out = []
    for row in parameter_table(parameters):
        plausible = row["plausible"]
        inside = row["plausible_value"]
        if row["name"] in LEVER_DIMENSIONS:
            dimension, factor = LEVER_DIMENSIONS[row["name"]]
            row = {**row, "reason": f"{row['reason']} (as {'2 x ' if factor != 1 else ''}"
                                    f"{dimension}: {number(row['value'] / factor, 'g')} m)"}
        text = ("-" if plausible is None else
                f"{number(plausible[0], 'g')} to {number(plausible[1], 'g')}"
                if all(isinstance(v, (int, float)) for v in plausible) else ", ".join(plausible))
        out.append({**row, "value": str(row["value"]), "plausible": text,
                    "inside": "-" if inside is None else "yes" if inside else "**NO**",
                    "fitted": "fitted" if row["fitted"] else "no"})
    return out


def _parameter_sets() -> list[str]:
    md = ["## Parameter sets\n"]
    for parameters in PARAMETER_SETS:
        spec = parameter_set(parameters)
        fit = spec.get("fit_cases", [])
        rows = parameter_rows(parameters)
        outside = [r["name"] for r in rows if r["inside"] == "**NO**"]
        md += [f"\n### {parameters}{' (default)' if parameters == DEFAULT_PARAMETER_SET else ''}\n",
               spec["description"] + "\n",
               (f"Fitted to {', '.join(f'`{k}`' for k in fit)} (study:angle:rpm); the other "
                "cases are held out.\n" if fit else "Fitted to nothing: every case is held out.\n"),
               _table(rows, PARAMETER_COLUMNS, ".5g"),
               (f"\n**Outside the plausible range:** {', '.join(f'`{n}`' for n in outside)}.\n"
                if outside else "\nEvery value with a range is inside it.\n")]
    return md


def error_summary(rows: pd.DataFrame) -> list[dict[str, Any]]:
    """Per parameter set, fitted and held-out cases apart: count, RMS and largest signed difference to
    the paper [-] with its case.
    """
    ok = rows[rows.status == Status.OK]
    out = []
    for parameters in PARAMETER_SETS:
        sel = ok[ok.parameters == parameters]
        for group, part in (("fitted", sel[sel.used_in_fit.astype(bool)]),
                            ("held out", sel[~sel.used_in_fit.astype(bool)])):
            if part.empty:
                continue
            diff = part["difference_to_paper"].astype(float)
            worst = part.loc[diff.abs().idxmax()]
            out.append({"parameters": parameters, "cases": group, "count": len(part),
                        "rms": float(np.sqrt((diff ** 2).mean())),
                        "largest": float(worst["difference_to_paper"]),
                        "largest_at": f"{worst['study']}:{worst['shaft_angle_deg']:g}:"
                                      f"{worst['speed_rpm']:g}"})
    return out


def _results(rows: pd.DataFrame, ok: pd.DataFrame) -> list[str]:
    """Mean efficiency of every set against the paper, the fitted and held-out errors, the cases
    without a result.
    """
    md = ["\n## Mean efficiency against the paper\n"]
    for parameters in PARAMETER_SETS:
        sel = ok[ok.parameters == parameters]
        if not sel.empty:
            md += [f"\n### {parameters}\n", _table(sel, MAIN_COLUMNS, formats=MAIN_FORMATS)]
    md += ["\n### Errors against the paper, fitted and held out\n",
           "Difference = model - paper, mean efficiency [-]; `largest` is the signed difference "
           "of largest magnitude, at `largest_at`.\n\n",
           _table(error_summary(rows), ["parameters", "cases", "count", "rms", "largest",
                                        "largest_at"], formats={"largest": "+.4f"})]
    failed = rows[rows.status != Status.OK]
    if not failed.empty:
        md += ["\n### Cases without a result\n", _table(failed, FAILED_COLUMNS)]
    return md


def _envelope() -> list[str]:
    """The envelope of each paper number over the plausible box, when it is stored."""
    rows = envelope()
    md = ["\n## What plausible physics can reach: the envelope\n"]
    if not rows:
        return md + ["Not computed: no envelope is stored in `reference/paper/data/paper.toml` "
                     "(`cardan calibrate --envelope` stores it).\n"]
    out = [{**r, "reachable": "yes" if r["reachable"] else "**NO**"} for r in rows]
    return md + ["Lowest and highest mean efficiency the model gives for each paper number over "
                 "the plausible box (the ranges of *Parameter sets*), and the closest plausible "
                 "value to the paper's.\n\n", _table(out, ENVELOPE_COLUMNS)]


def _losses_and_checks(ok: pd.DataFrame) -> list[str]:
    return [
        "\n## Where the power goes: share of the input work lost in each pair\n",
        _table(ok, LOSS_COLUMNS),
        "\n## Checks: energy balance and cost\n",
        "`output_load_N_m` = the constant output load (the `physical` set reads the paper's "
        "2 N m as the mean input torque, so its load is solved per case); "
        "`energy_balance_residual_J` = input work - output work - friction loss work - change "
        "of mechanical energy over the run (trapezoidal, zero up to the integration error).\n\n",
        _table(ok, CHECK_COLUMNS, ".4g"),
    ]


def _plots(figures: Sequence[tuple[str, str]]) -> list[str]:
    return [
        "\n## Plots\n",
        "\n".join(f"![{name}]({name})\n\n*{caption}*\n" for name, caption in figures),
        "\n### The start-up oscillation\n",
        "The time histories leave out the first steps of a run. Every run starts from a "
        "consistent state (the first row equals the row one revolution later to about 1e-3 W, "
        "friction iterated to consistency before the first step), but the generalized-alpha "
        "integrator starts its acceleration-like variables at the consistent accelerations, and "
        "its index-3 reactions then oscillate from step to step for a few dozen steps (also "
        "without friction, in the drive torque); every pair's friction follows its reactions, "
        "most visibly the output-frame pair's moment term. The oscillation decays faster at a "
        "lower spectral radius, and is absent one revolution later at the same input angle: an "
        "artefact of the integrator's start, not of the joint. The figures show the last whole "
        f"revolution (with one revolution, from step {START_UP_STEPS} on); the means keep every "
        "step (Figure 5's caption gives the start-up's effect on the first revolution's mean).\n",
    ]


def _appendix(register: pd.DataFrame) -> list[str]:
    stated = pd.DataFrame(stated_values())
    stated["value"] = stated["value"].astype(str)
    return [
        "\n## Assumption register\n",
        "Every value the paper does not state, the value used, and why (also "
        "`assumptions.csv`); a parameter set's values replace these where it has them.\n\n",
        _table(register.assign(value=register["value"].astype(str)),
               ["name", "value", "unit", "assumption", "reason"]),
        "\n## Values taken from the paper\n",
        _table(stated, ["name", "value", "unit", "source"]),
    ]
