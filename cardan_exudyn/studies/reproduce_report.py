"""The report of ``cardan reproduce``: ``results.csv``, ``assumptions.csv``, the figures and
``report.md``, from the rows and time histories of the runs (:mod:`.reproduce` makes them).

Every number in the report is computed from ``reference/data/paper.toml`` by the code in this
repository; the only values copied from the paper are in the column ``paper_mean_efficiency``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.report import plots
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.studies.calibrate import in_fit
from reference.joint import PAIR_NAMES
from reference.paper import (
    PARAMETER_SETS,
    assumption_register,
    calibrated_choices,
    calibrated_parameters,
    paper_data,
    stated_values,
)
from reference.schema import Status

__all__ = ["RUN_NUMBERS", "fit_case_keys", "case_row", "write_report", "draw_figures", "report_text"]

# the numbers of a run, in the order of the report's results.csv (after difference_to_paper)
RUN_NUMBERS = ("efficiency_error_estimate", "accuracy_met", "mean_torque_in", "input_work_J",
               "loss_work_J", "energy_balance_residual_J",
               "loop_gain_estimate", "friction_evaluations_per_step", "steps", "wall_time_s",
               *(f"loss_share_{pair}" for pair in PAIR_NAMES))
MAIN_COLUMNS = ["parameters", "study", "shaft_angle_deg", "speed_rpm", "status",
                "paper_mean_efficiency", "mean_efficiency", "efficiency_error_estimate",
                "accuracy_met", "difference_to_paper",
                "mean_instantaneous_efficiency", "used_in_fit", "loop_gain_estimate"]
FAILED_COLUMNS = ["parameters", "study", "shaft_angle_deg", "speed_rpm", "status", "reason"]
LOSS_COLUMNS = ["parameters", "shaft_angle_deg", "speed_rpm", *(f"loss_share_{p}" for p in PAIR_NAMES)]
CHECK_COLUMNS = ["parameters", "shaft_angle_deg", "speed_rpm", "input_work_J", "loss_work_J",
                 "energy_balance_residual_J", "friction_evaluations_per_step", "steps", "wall_time_s"]
# the mean-efficiency figures: study, x column, x label, file name stem
MEAN_FIGURES = (("table2", "shaft_angle_deg", "shaft angle [deg]", "table2"),
                ("speed", "speed_rpm", "input speed [rpm]", "speed"))
LEVERS_READING = (
    "\n**Reading.** The fitted levers are not plausible dimensions for a joint this "
    "size (a 60 mm spider lever is a 30 mm arm radius on a 45.6 g spider; a 0.59 m "
    "frame lever is a bearing spacing far beyond shafts whose centres of mass sit "
    "0.13 m and 0.09 m from the joint). They act as correction factors: the paper's "
    "numbers need the moment term of eqs. (1)-(2) about 10 times weaker in the "
    "spider pairs and about 60 times weaker in the frame pairs than the stated "
    "bearing lengths give.\n")


def fit_case_keys() -> list[str]:
    """The cases the calibrated set was fitted to, as ``study:angle:rpm`` keys."""
    return list(paper_data().get("calibrated", {}).get("fit_cases", []))


def case_row(case: Mapping[str, Any], parameters: str, record: Mapping[str, Any]) -> dict[str, Any]:
    """One row of the report's ``results.csv``.

    Parameters
    ----------
    case : mapping
        A paper case (``study``, ``shaft_angle_deg``, ``speed_rpm``, ``paper_mean_efficiency``).
    parameters : str
        The parameter set, ``plain`` or ``calibrated``.
    record : mapping
        The run's sweep record (:func:`cardan_exudyn.studies.reproduce.run_numbers` and status).

    Returns
    -------
    dict
        The case, the paper's value and, for a run that is ``ok``, its numbers (works in J,
        torque in N m, wall time in s, efficiencies and shares dimensionless).
    """
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
    """Write ``report.md``, ``results.csv``, ``assumptions.csv`` and the figures into ``folder``.

    Parameters
    ----------
    folder : Path
        An existing folder.
    rows : sequence of dict or DataFrame
        One :func:`case_row` per run, in report order.
    histories : mapping
        Parameter set -> label -> time history (columns ``t`` [s], ``efficiency`` [-],
        ``power_loss_<pair>`` [W]); labels ``10deg``, ``angle <a> deg``, ``speed <n> rpm``.
    quick : bool
        The runs were ``--quick`` ones (said in the report's head).
    wall : float
        Wall time of the runs [s].
    reused : int
        Runs taken from an earlier invocation's records in ``runs_dir`` (said in the head).
    runs_dir : str
        Name of the folder of the sweep's records.
    """
    rows = pd.DataFrame(rows)
    rows.to_csv(folder / "results.csv", index=False)
    register = pd.DataFrame(assumption_register())
    register.to_csv(folder / "assumptions.csv", index=False)
    figures = draw_figures(folder, rows, histories)
    text = report_text(rows, register, figures, quick=quick, wall=wall, reused=reused,
                       runs_dir=runs_dir)
    (folder / "report.md").write_text(text, encoding="utf-8")


def draw_figures(folder: Path, rows: pd.DataFrame,
                 histories: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """Save every figure of the report into ``folder``; returns their file names in order."""
    figures: list[str] = []
    for parameters in PARAMETER_SETS:
        sel = rows[(rows.parameters == parameters) & (rows.status == Status.OK)]
        if sel.empty:
            continue
        figures += _mean_figures(folder, parameters, sel)
        figures += _history_figures(folder, parameters, histories.get(parameters, {}))
    return figures


def _mean_figures(folder: Path, parameters: str, sel: pd.DataFrame) -> list[str]:
    """Mean efficiency against the paper over Table 2's angles and over the speeds."""
    names = []
    for study, x, xlabel, stem in MEAN_FIGURES:
        part = sel[sel.study == study].sort_values(x)
        if not part.empty:
            names.append(_save(folder, f"{stem}_{parameters}.png",
                               plots.efficiency_against_paper({parameters: part}, x, xlabel)))
    return names


def _history_figures(folder: Path, parameters: str, hist: Mapping[str, Any]) -> list[str]:
    """Figures 4 and 5 (10 deg, 2000 rpm), 6 (several angles) and 7 (several speeds)."""
    names = []
    if "10deg" in hist:
        names.append(_save(folder, f"fig4_efficiency_10deg_{parameters}.png",
                           plots.efficiency_history({"10 deg, 2000 rpm": hist["10deg"]},
                                                    f"Figure 4 ({parameters})")))
        names.append(_save(folder, f"fig5_pair_losses_{parameters}.png",
                           plots.pair_losses(hist["10deg"], f"Figure 5 ({parameters}): power loss, "
                                                            "10 deg, 2000 rpm")))
    angles = {k: v for k, v in hist.items() if k.startswith("angle ")}
    if angles:
        names.append(_save(folder, f"fig6_angles_{parameters}.png",
                           plots.efficiency_history(angles, f"Figure 6 ({parameters})",
                                                    ylim=(-0.5, 1.05))))
    speeds = {k: v for k, v in hist.items() if k.startswith("speed ")}
    if speeds:
        names.append(_save(folder, f"fig7_speeds_{parameters}.png",
                           plots.efficiency_history(speeds, f"Figure 7 ({parameters})")))
    return names


def _save(folder: Path, name: str, fig: Any) -> str:
    plots.save(fig, folder / name)
    return name


def report_text(rows: pd.DataFrame, register: pd.DataFrame, figures: Sequence[str], *,
                quick: bool, wall: float, reused: int, runs_dir: str) -> str:
    """The markdown of ``report.md`` (arguments as for :func:`write_report`)."""
    ok = rows[rows.status == Status.OK]
    md = (_head(len(rows), quick, wall, reused, runs_dir) + _results(rows, ok)
          + _calibration() + _losses_and_checks(ok) + _appendix(figures, register))
    return "\n".join(md)


def _table(frame: pd.DataFrame, columns: Sequence[str], spec: str = ".4f") -> str:
    """A markdown table of ``columns``: numbers in float columns with ``spec`` (angles and speeds
    with ``g``), integers, booleans and text as they are, an undefined number as an empty cell."""
    formats = {c: "g" if c.endswith(("_deg", "_rpm")) else spec
               for c in columns if c in frame and frame[c].dtype.kind == "f"}
    return markdown_table(frame, columns, formats, missing="")


def _head(runs: int, quick: bool, wall: float, reused: int, runs_dir: str) -> list[str]:
    earlier = (f" ({reused} of the {runs} runs from the records of an earlier invocation in "
               f"`{runs_dir}/`)" if reused else "")
    return [
        "# The paper's results with friction: plain reading and calibrated set\n",
        f"Generated by `cardan reproduce{' --quick' if quick else ''}` in {number(wall, '.1f')} s"
        + earlier + ". Every "
        "number and plot here was computed by the code in this repository from "
        "`reference/data/paper.toml`; nothing is copied from the paper except the column "
        "`paper_mean_efficiency`.\n",
        "**Parameter sets.** `plain`: every value the paper states, read literally (moment "
        "lever of eq. (1) = bearing length L), and the assumption register below for what it "
        "does not state. `calibrated`: the plain reading with the parameters listed under "
        "*Calibrated parameters* identified by `cardan calibrate` from the cases marked "
        "`used_in_fit`; the other cases are held out.\n",
        "**Definitions.** `mean_efficiency` = 1 - (loss work)/(input work) over whole input "
        "revolutions; `efficiency_error_estimate` = the run's own estimate of its error "
        "(`docs/accuracy.md`), `accuracy_met` whether it is within the target "
        "(`numerics.accuracy`); `mean_instantaneous_efficiency` = time average of eq. (18), which is "
        "unbounded where the input power changes sign (it does at large angles): '-' where it "
        "is not defined or leaves [0, 1].\n",
    ]


def _results(rows: pd.DataFrame, ok: pd.DataFrame) -> list[str]:
    md = ["## Mean efficiency against the paper\n",
          _table(ok, MAIN_COLUMNS),
          "\n### Summary of differences to the paper\n",
          held_out_summary(rows)]
    failed = rows[rows.status != Status.OK]
    if not failed.empty:
        md += ["\n### Cases without a result\n", _table(failed, FAILED_COLUMNS)]
    return md


def held_out_summary(rows: pd.DataFrame) -> str:
    """Largest and RMS difference to the paper of the fitted, the held-out and the plain cases."""
    cal = rows[(rows.parameters == "calibrated") & (rows.status == Status.OK)]
    if cal.empty:
        return ""
    groups = [("fitted", cal[cal.used_in_fit]), ("held out", cal[~cal.used_in_fit])]
    plain = rows[(rows.parameters == "plain") & (rows.status == Status.OK)]
    if not plain.empty:
        groups.append(("plain reading", plain))
    out = []
    for label, sel in groups:
        if sel.empty:
            continue
        err = sel["difference_to_paper"].abs()
        out.append(f"- {label} ({len(sel)} cases): max |difference| {number(err.max(), '.4f')}, "
                   f"RMS {number(np.sqrt((err ** 2).mean()), '.4f')}")
    return "\n".join(out) + "\n"


def _calibration() -> list[str]:
    calibrated = pd.DataFrame(calibrated_parameters())
    if calibrated.empty:
        return []
    cal = calibrated.assign(plain_value=calibrated["plain_value"].astype(str))
    choices = pd.DataFrame([{"name": k, **v} for k, v in calibrated_choices().items()])
    return ["\n## Calibrated parameters\n",
            f"Fitted by `cardan calibrate` to {', '.join(fit_case_keys())} "
            "(study:angle:rpm):\n\n",
            _table(cal, ["name", "value", "unit", "plain_value", "meaning"], ".5g"),
            "\nDiscrete choices of the calibrated set (not fitted):\n\n",
            _table(choices.assign(value=choices["value"].astype(str)), ["name", "value", "reason"]),
            LEVERS_READING]


def _losses_and_checks(ok: pd.DataFrame) -> list[str]:
    return [
        "\n## Where the power goes: share of the input work lost in each pair\n",
        _table(ok, LOSS_COLUMNS),
        "\n## Checks: energy balance and cost\n",
        "`energy_balance_residual_J` = input work - output work - friction loss work - change "
        "of mechanical energy over the run (trapezoidal, zero up to the integration error).\n\n",
        _table(ok, CHECK_COLUMNS, ".4g"),
    ]


def _appendix(figures: Sequence[str], register: pd.DataFrame) -> list[str]:
    stated = pd.DataFrame(stated_values())
    stated["value"] = stated["value"].astype(str)
    return [
        "\n## Plots\n",
        "\n".join(f"![{f}]({f})\n" for f in figures),
        "\n## Assumption register\n",
        "Every value the paper does not state, the value used, and why (also "
        "`assumptions.csv`).\n\n",
        _table(register.assign(value=register["value"].astype(str)),
               ["name", "value", "unit", "assumption", "reason"]),
        "\n## Values taken from the paper\n",
        _table(stated, ["name", "value", "unit", "source"]),
    ]
