"""The long runs' files and report section: CSV tables, the summary as JSON, three figures
(:func:`write_long`), and the markdown section of the measured figures (:func:`markdown`).

The report shows the measurements; the tolerances they are held to are the tests of
``tests/benchmarks/test_longrun.py``, which the section names.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.ticker import NullFormatter, ScalarFormatter

from benchmarks.longrun.plan import (
    DEFAULT_RHO,
    DISSIPATION_MODEL,
    DRIFT_SCENE,
    ENGINE,
    REFERENCE,
    RHO_LADDER_STEPS,
    RHO_MODEL,
    STARTUP_REVOLUTIONS,
    model_loss,
)
from benchmarks.longrun.runs import LongRuns
from benchmarks.longrun.summary import rho_ladder, step_ladder
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.report import plots
from cardan_exudyn.report.format import markdown_table, number

__all__ = ["NODE_COLOURS", "figure_constraints", "figure_efficiency", "figure_energy", "write_long",
           "MEASURE_LABELS", "TESTS", "drift_section", "energy_section", "markdown"]

NODE_COLOURS = {"Rxyz": "C0", "EP": "C1", "RotVecLG": "C2"}


def _rotation_coordinates(node_type: str, g: pd.DataFrame) -> pd.Series:
    return g["ep_norm_error"] if node_type == "EP" else math.pi - g["rotvec_norm_max"]


def figure_constraints(drift: pd.DataFrame) -> Any:
    """Per-revolution maxima of the constraint violations and rotation coordinates, per node type."""
    fig, axes = plots.plt.subplots(2, 3, figsize=(13, 7), constrained_layout=True)
    panels = (("position_violation_m", "marker distance [m]"),
              ("angle_violation_rad", "axis misalignment [rad]"),
              ("velocity_violation_m_s", "constrained relative velocity [m/s]"),
              ("angular_velocity_violation_rad_s", "constrained rel. angular velocity [rad/s]"),
              ("orthogonality_error", "max abs(A^T A - I) [-]"),
              ("rotation_coordinates", "EP: abs(|p| - 1); RotVecLG: pi - |nu|"))
    for ax, (key, label) in zip(axes.ravel(), panels, strict=True):
        for node_type, g in drift.groupby("node_type", sort=False):
            y = (_rotation_coordinates(node_type, g) if key == "rotation_coordinates"
                 else g[key]).to_numpy(dtype=float)
            if np.isfinite(y).any():
                ax.semilogy(g["revolution"], np.maximum(np.abs(y), 1e-18), lw=0.8, label=node_type,
                            color=NODE_COLOURS.get(node_type))
        ax.set_xlabel("input revolution")
        ax.set_ylabel(f"per-revolution max: {label}", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle(f"{DRIFT_SCENE}: constraint and rotation-coordinate drift", fontsize=10)
    return fig


def figure_efficiency(drift: pd.DataFrame, summary: dict[str, Any]) -> Any:
    """Per-revolution efficiency about its mean, energy-balance residual, input-angle error."""
    fig, axes = plots.plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    for node_type, g in drift.groupby("node_type", sort=False):
        s = summary["drift"].get(node_type, {}).get("efficiency", {})
        steady = g.iloc[STARTUP_REVOLUTIONS:]
        mean = s.get("mean", float(steady["efficiency"].mean()))
        colour = NODE_COLOURS.get(node_type)
        axes[0].plot(steady["revolution"], steady["efficiency"] - mean, ".", ms=1.5, color=colour,
                     label=f"{node_type} (mean {mean:.7f})")
        axes[1].plot(steady["revolution"], steady["balance_residual_j"], lw=0.8, color=colour,
                     label=node_type)
        error = g["input_angle_error_rad"].to_numpy(dtype=float)
        axes[2].plot(g["revolution"], error, lw=0.8, color=colour, label=node_type)
    axes[0].set_ylabel("per-revolution efficiency minus its mean [-]")
    axes[1].set_ylabel("W_in - W_out - W_loss - dE per revolution [J]")
    axes[2].set_ylabel("theta_in - omega t at whole revolutions [rad]")
    for ax in axes:
        ax.set_xlabel("input revolution")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=5)
    fig.suptitle(f"{DRIFT_SCENE}: per-revolution efficiency, energy balance, input angle",
                 fontsize=10)
    return fig


def _plot_energy_histories(ax: Any, energy: pd.DataFrame) -> None:
    for _, g in energy.groupby("case", sort=False):
        y = np.abs(g["relative_energy_deviation"].to_numpy(dtype=float))
        k = g["revolution"].to_numpy()
        keep = (k > 0) & (y > 0)
        first = g.iloc[0]
        reference = first["engine"] == REFERENCE
        label = (f"ref. {first['shaft_angle_deg']:g} deg" if reference else
                 f"{first['shaft_angle_deg']:g} deg, {number(first['steps_per_revolution'], '.0f')}/rev, "
                 f"rho {first['spectral_radius']:g}")
        if keep.any():
            ax.loglog(k[keep], y[keep], lw=0.8, ls="--" if reference else "-", label=label)
    ax.set_xlabel("input revolution")
    ax.set_ylabel("|E(2 pi k) - E(0)| / E(0) [-]")
    ax.legend(fontsize=5, ncol=2, loc="upper left")


def _plot_energy_ladders(axes: Any, cases: list[dict[str, Any]]) -> None:
    """Loss per revolution against the step count and the spectral radius, with the model."""
    for angle in sorted({c["shaft_angle_deg"] for c in cases}):
        ladder = step_ladder(cases, angle)
        if ladder:
            n = np.array([c["steps_per_revolution"] for c in ladder])
            axes[0].loglog(n, [c["loss_per_revolution"] for c in ladder], "o", label=f"{angle:g} deg")
            if angle in DISSIPATION_MODEL:
                grid = np.geomspace(n.min() * 0.8, n.max() * 1.25, 20)
                axes[0].loglog(grid, [model_loss(angle, DEFAULT_RHO, x) for x in grid], "k:", lw=0.8)
        rhos = rho_ladder(cases, angle)
        if rhos:
            r = np.array([c["spectral_radius"] for c in rhos])
            axes[1].semilogy(r, [c["loss_per_revolution"] for c in rhos], "o", label=f"{angle:g} deg")
            if angle in DISSIPATION_MODEL:
                grid = np.linspace(0.0, 0.99, 60)
                spr = float(np.mean([c["steps_per_revolution"] for c in rhos]))
                axes[1].semilogy(grid, [model_loss(angle, x, spr) for x in grid], "k:", lw=0.8)
    axes[0].set_xticks([100, 200, 400, 700])
    axes[0].xaxis.set_major_formatter(ScalarFormatter())
    axes[0].xaxis.set_minor_formatter(NullFormatter())
    axes[0].set_xlabel("steps per revolution (at the mean speed)")
    axes[0].set_ylabel(f"energy lost per revolution, rho {DEFAULT_RHO:g} [-]")
    axes[0].set_title("dotted: K c(rho) h^3", fontsize=8)
    axes[1].set_xlabel("spectral radius rho")
    axes[1].set_ylabel(f"energy lost per revolution, {RHO_LADDER_STEPS} steps/rev [-]")
    axes[1].set_title("dotted: K c(rho) h^3 (linear-oscillator damping)", fontsize=8)
    for ax in axes:
        ax.legend(fontsize=7)


def figure_energy(energy: pd.DataFrame, summary: dict[str, Any]) -> Any:
    """Relative energy against revolutions per case; loss per revolution against step and rho."""
    fig, axes = plots.plt.subplots(1, 3, figsize=(14, 4.4), constrained_layout=True)
    _plot_energy_histories(axes[0], energy)
    _plot_energy_ladders(axes[1:], summary["energy"]["cases"])
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    fig.suptitle("free-spinning frictionless joint: energy conservation", fontsize=10)
    return fig


def write_long(result: LongRuns, folder: Path) -> list[str]:
    """CSV tables, the summary as JSON and the figures into an existing ``folder``; file names."""
    folder = Path(folder)
    result.drift.to_csv(folder / "longrun_drift.csv", index=False, float_format="%.12g")
    result.energy.to_csv(folder / "longrun_energy.csv", index=False, float_format="%.12g")
    (folder / "longrun_summary.json").write_text(
        json.dumps(to_jsonable(result.summary), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    names = ["longrun_drift.csv", "longrun_energy.csv", "longrun_summary.json"]
    if not result.drift.empty:
        plots.save(figure_constraints(result.drift), folder / "longrun_constraints.png")
        plots.save(figure_efficiency(result.drift, result.summary), folder / "longrun_efficiency.png")
        names += ["longrun_constraints.png", "longrun_efficiency.png"]
    if not result.energy.empty:
        plots.save(figure_energy(result.energy, result.summary), folder / "longrun_energy.png")
        names.append("longrun_energy.png")
    return names


MEASURE_LABELS = (("position_violation_m", "marker distance [m]"),
                  ("angle_violation_rad", "axis misalignment [rad]"),
                  ("velocity_violation_m_s", "constrained relative velocity [m/s]"),
                  ("angular_velocity_violation_rad_s", "constrained relative angular velocity [rad/s]"),
                  ("orthogonality_error", "max abs(A^T A - I)"),
                  ("ep_norm_error", "abs(abs(p) - 1), EP"),
                  ("rotvec_norm_max", "abs(nu), RotVecLG [rad]"),
                  ("input_angle_error_rad", "theta_in - omega t [rad]"),
                  ("balance_residual_j", "W_in - W_out - W_loss - dE per revolution [J]"))
TESTS = ("`tests/benchmarks/test_longrun.py` holds these measurements to stated tolerances, each with its "
         "reason: the position constraints and the Euler parameters' norm within Newton's tolerance in every "
         "revolution; the velocity residuals and the energy-balance residual as large in the last "
         "window as in the first (periodic, not growing); rotation matrices orthogonal and rotation "
         "vectors within pi to rounding; the input's angle coordinate within pi (the post-step wrap "
         "takes out whole revolutions), so that it rounds at 4.4e-16 rad at most; every node type "
         "running all its revolutions; no trend of the per-revolution efficiency; an energy loss per "
         "revolution of order h^3 that follows c(rho); the default settings' energy drift within a "
         "margin of the model; the reference engine's drift per revolution at the level of its "
         "tolerance. `pytest tests/benchmarks/test_longrun.py` runs a short variant, `-m slow` the quick and "
         "full ones.")


def _measure_rows(drift: dict[str, Any], types: list[str]) -> list[dict[str, str]]:
    """Rows of the drift table for the measures: largest, and first / last window."""
    rows = []
    for key, label in MEASURE_LABELS:
        figures = {t: drift[t].get("measures", {}).get(key) for t in types}
        if all(f is None for f in figures.values()):
            continue
        figures = {t: f or {} for t, f in figures.items()}
        rows.append({"per revolution": f"{label}: largest",
                     **{t: number(f.get("max_abs"), ".3g") for t, f in figures.items()}})
        rows.append({"per revolution": f"{label}: first / last window",
                     **{t: f"{number(f.get('first_window_max_abs'), '.3g')} / "
                           f"{number(f.get('last_window_max_abs'), '.3g')}" for t, f in figures.items()}})
    return rows


def _efficiency_rows(drift: dict[str, Any], types: list[str]) -> list[dict[str, str]]:
    """Rows of the drift table for the per-revolution efficiency."""
    eff = {t: drift[t].get("efficiency", {}) for t in types}

    def row(label: str, cell: Any) -> dict[str, str]:
        return {"per revolution": label, **{t: cell(eff[t]) for t in types}}

    return [
        row("efficiency: revolution 1", lambda e: number(e.get("first_revolution"), ".7f")),
        row("efficiency: mean after start-up", lambda e: number(e.get("mean"), ".7f")),
        row("efficiency: scatter about the trend", lambda e: number(e.get("scatter"), ".3g")),
        row("efficiency: trend per 1000 revolutions (+- std. error)",
            lambda e: f"{number(e.get('trend_per_1000_revolutions'), '.3g')} +- "
                      f"{number(e.get('trend_stderr_per_1000_revolutions'), '.3g')}"),
        row("efficiency: last minus first window mean (+- std. error)",
            lambda e: f"{number(e.get('last_minus_first'), '.3g')} +- "
                      f"{number(e.get('difference_stderr'), '.3g')}"),
    ]


def drift_section(s: dict[str, Any]) -> list[str]:
    """(a) The drift runs: settings and one column of figures per node type."""
    st = s["settings"]
    drift = s["drift"]
    types = list(drift)
    rows = [{"per revolution": "status", **{t: str(drift[t]["status"]) for t in types}},
            {"per revolution": "wall time [s]",
             **{t: number(drift[t].get("wall_time_s"), ".0f") for t in types}},
            {"per revolution": "Newton iterations / friction evaluations per step",
             **{t: f"{number(drift[t].get('newton_iterations_per_step'), '.3g')} / "
                   f"{number(drift[t].get('friction_evaluations_per_step'), '.3g')}" for t in types}}]
    rows += _measure_rows(drift, types) + _efficiency_rows(drift, types)
    return [f"### Drift: {st['drift_revolutions']} revolutions of `{st['drift_scene']}` with friction", "",
            f"Converged friction coupling; step {number(st['drift_dt_s'], '.4g')} s = "
            f"{number(st['drift_steps_per_revolution'], '.0f')} steps per input revolution "
            f"({st['drift_dt_choice']}). Every value is the largest of a revolution; 'first'/'last' "
            f"are the largest over the first/last window of revolutions (after "
            f"{st['startup_revolutions_excluded']} start-up revolution).", "",
            markdown_table(rows, ["per revolution", *types]).rstrip("\n"), "",
            "Figures: `longrun_constraints.png`, `longrun_efficiency.png`.", ""]


def _model_loss_of(c: dict[str, Any]) -> float:
    modelled = c["engine"] == ENGINE and c["shaft_angle_deg"] in DISSIPATION_MODEL
    if modelled and c.get("steps_per_revolution"):
        return model_loss(c["shaft_angle_deg"], c["spectral_radius"], c["steps_per_revolution"])
    return float("nan")


def _fit_line(angle: str, fit: dict[str, Any]) -> str:
    parts = [f"{angle} deg:"]
    if "order" in fit:
        parts.append(f"loss ~ h^{fit['order']:.3f} at rho {DEFAULT_RHO:g} (neighbours: "
                     + ", ".join(f"{k:.3f}" for k in fit["order_between_neighbours"]) + ");")
    if "K_fitted" in fit:
        parts.append(f"K fitted {fit['K_fitted']:.4g} (cases with rho {RHO_MODEL[0]:g} to "
                     f"{RHO_MODEL[1]:g}, largest deviation {100 * fit['K_fit_max_deviation']:.1f} %), "
                     f"stated {number(DISSIPATION_MODEL.get(float(angle)), '.4g')};")
    if fit.get("rho_dependence"):
        parts.append("loss(rho)/loss(0.6) measured vs theory: " + ", ".join(
            f"{r['spectral_radius']:g}: {r['measured_ratio']:.4g} vs {r['theory_ratio']:.4g}"
            for r in fit["rho_dependence"]) + ".")
    return "- " + " ".join(parts)


def energy_section(s: dict[str, Any]) -> list[str]:
    """(b) The free-spinning runs: one row per case, the fits per shaft angle."""
    st = s["settings"]
    en = s["energy"]
    rows = [{**c, "status": str(c["status"]), "completed_revolutions": str(c.get("completed_revolutions", 0)),
             "model_loss": _model_loss_of(c)} for c in en["cases"]]
    columns = ["case", "status", "steps_per_revolution", "completed_revolutions", "relative_drift",
               "loss_per_revolution", "model_loss", "within_revolution_range", "wall_time_s"]
    formats = {"steps_per_revolution": ".0f", "relative_drift": ".3g", "loss_per_revolution": ".3g",
               "model_loss": ".3g", "within_revolution_range": ".3g", "wall_time_s": ".1f"}
    headers = ["case", "status", "steps/rev (mean speed)", "revolutions", "relative drift",
               "loss per revolution", "model loss per revolution", "range within a revolution", "wall [s]"]
    return [f"### Energy: free-spinning frictionless joint, {st['energy_revolutions']} revolutions", "",
            f"Torque drive of 0 N m from {st['energy_speed_rpm']:g} rpm, no load, gravity on; total "
            "mechanical energy at whole input revolutions relative to the start. 'Loss per revolution' "
            "is the slope over the second half of the run; the model is K c(rho) h^3 with c(rho) the "
            "linear-oscillator damping coefficient of generalized-alpha and h = 2 pi / (steps per "
            "revolution at the mean speed).", "",
            markdown_table(rows, columns, formats=formats, headers=headers).rstrip("\n"), "",
            *[_fit_line(angle, fit) for angle, fit in en["fits"].items()],
            "", "Figure: `longrun_energy.png`.", ""]


def markdown(result: LongRuns) -> str:
    """A report section: settings, the measured drift and energy figures, what the tests check,
    and what did not run through."""
    s = result.summary
    st = s["settings"]
    walls = s["wall_time_s"]
    out = ["## Long runs", "",
           f"{st['variant'].capitalize()} variant: wall time {walls['total']:.0f} s "
           f"(drift {walls['drift']:.0f} s, energy {walls['energy']:.0f} s). Generalized-alpha, index 3, "
           f"spectral radius {st['spectral_radius']:g} unless stated, full Newton.", ""]
    out += drift_section(s) + energy_section(s)
    out += ["### What the tests check", "", TESTS, ""]
    if s.get("findings"):
        out += ["Findings:", ""] + [f"- {text}" for text in s["findings"]] + [""]
    return "\n".join(out)
