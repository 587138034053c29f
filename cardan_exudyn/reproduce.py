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
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn import plots
from cardan_exudyn.calibrate import in_fit
from cardan_exudyn.engine import run
from cardan_exudyn.io import atomic_directory, dumps
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
from reference.scene import PAIR_NAMES, replace


def fit_case_keys() -> list[str]:
    """The cases the calibrated set was fitted to, as ``study:angle:rpm`` keys."""
    return list(paper_data().get("calibrated", {}).get("fit_cases", []))


def case_row(case: dict, parameters: str, result) -> dict[str, Any]:
    s = result.summary
    row: dict[str, Any] = {
        "parameters": parameters,
        "study": case["study"],
        "shaft_angle_deg": case["shaft_angle_deg"],
        "speed_rpm": case["speed_rpm"],
        "paper_mean_efficiency": case["paper_mean_efficiency"],
        "status": s["status"],
        "reason": s.get("reason", ""),
        "used_in_fit": parameters == "calibrated" and in_fit(case, fit_case_keys()),
    }
    if not result.ok:
        return row
    t = result.table
    energy = t["energy_kinetic"] + t["energy_potential"]
    work = {c: float(np.trapezoid(t[c], t["t"])) for c in ("power_in", "power_out", "power_loss")}
    row.update({
        "mean_efficiency": s["mean_efficiency"],
        "mean_instantaneous_efficiency": s["mean_instantaneous_efficiency"],
        "difference_to_paper": s["mean_efficiency"] - case["paper_mean_efficiency"],
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
        row[f"loss_share_{pair}"] = s[f"loss_work_{pair}"] / s["input_work"]
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
                 wall: float) -> None:
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
        f"Generated by `cardan reproduce{' --quick' if quick else ''}` in {wall:.1f} s. Every "
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


def reproduce(out: str, quick: bool = False) -> int:
    """Run the paper's cases under both parameter sets; write the report; 0, or 3 on a failure."""
    cases = paper_cases()
    if quick:
        cases = [c for c in cases if (c["study"] == "table2" and c["shaft_angle_deg"] in (0.0, 10.0))
                 or (c["study"] == "speed" and c["speed_rpm"] == 500.0)]
    sets = [p for p in PARAMETER_SETS if p == "plain" or calibrated_parameters()]
    rows, histories, summaries = [], {p: {} for p in sets}, []
    start = time.perf_counter()
    total = len(cases) * len(sets)
    k = 0
    for parameters in sets:
        for case in cases:
            k += 1
            scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"],
                                parameters=parameters)
            if quick:
                scene = replace(scene, **{"numerics.accuracy": 1e-4, "revolutions": 1.0})
            result = run(scene)
            summaries.append(result.summary)
            s = result.summary
            eta = s.get("mean_efficiency")
            print(f"[{k}/{total}] {scene.name}: {s['status']}"
                  + (f", mean efficiency {eta:.4f}" if eta is not None else "")
                  + f", {s['wall_time_s']:.2f} s", file=sys.stderr, flush=True)
            rows.append(case_row(case, parameters, result))
            if result.ok:
                hist = histories[parameters]
                if case["study"] == "table2" and case["shaft_angle_deg"] in HISTORY_ANGLES:
                    hist[f"angle {case['shaft_angle_deg']:g} deg"] = result.table
                if case["study"] == "table2" and case["shaft_angle_deg"] == 10.0:
                    hist["10deg"] = result.table
                if case["study"] == "speed":
                    hist[f"speed {case['speed_rpm']:g} rpm"] = result.table
    frame = pd.DataFrame(rows)
    wall = time.perf_counter() - start
    with atomic_directory(out) as folder:
        write_report(folder, frame, histories, quick, wall)
        (folder / "summaries.json").write_text(dumps(summaries) + "\n", encoding="utf-8")
    print(f"wrote {out}/report.md ({total} runs, {wall:.1f} s)", file=sys.stderr)
    return 0 if all(s["status"] == "ok" for s in summaries) else 3
