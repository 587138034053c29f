"""The report folder of a Validation, written atomically: ``report.md``, ``validation.json``,
``figure10.png`` (the paper's Figure 10) and ``signals.csv``.
"""

from __future__ import annotations

import json
import math
import os
import shlex
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.jsonable import dumps, to_jsonable
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from rigdata.reproduce import model_settings, run_environment
from rigdata.validation import K, Validation

__all__ = ["figure", "figure_title", "friction_text", "markdown", "write_report"]

#: What Figure 10 compares, under it in ``report.md``.
FIGURE_CAPTION = ("*Figure 10.* Measured P_out / P_in (k = 2 band) against the model's own P_out / P_in, "
                  "like with like, over time and input yoke angle; the lower panel is their difference. "
                  "The paper's 1 - P_loss / P_in (dashed, upper panel) differs from P_out / P_in within "
                  "a revolution by the power into the joint's inertia; over whole revolutions both "
                  "give the same work ratio W_out / W_in.")

#: Line colour of each engine's computed efficiency.
COLOURS = {"reference": "C0", "exudyn": "C1"}


def _limits(eta: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    """Efficiency axis limits [-]: the k = 2 band's 1st and 99th percentiles, showing at least [0.8, 1.05]."""
    finite = np.isfinite(eta) & np.isfinite(u)
    lo = np.percentile((eta - K * u)[finite], 1) if finite.any() else 0.0
    hi = np.percentile((eta + K * u)[finite], 99) if finite.any() else 1.0
    return float(min(lo, 0.8)), float(max(hi, 1.05))


def _series(v: Validation) -> dict[str, dict[str, np.ndarray]]:
    """Each engine's computed time series (engines that ran ``ok``)."""
    return {engine: comp["series"] for engine, comp in v.computed.items() if comp.get("series") is not None}


def _over_time(ax: Any, v: Validation, t: np.ndarray, eta: np.ndarray, u: np.ndarray) -> None:
    """Top panel: measured P_out / P_in with its band and each engine's P_out / P_in (the paper's
    1 - P_loss / P_in dashed) over time [s].
    """
    ax.fill_between(t, eta - K * u, eta + K * u, color="0.85", label="measured, k = 2 band")
    ax.plot(t, eta, color="k", lw=0.8, label="measured P_out / P_in")
    for engine, series in _series(v).items():
        colour = COLOURS.get(engine, "C2")
        ax.plot(series["t"], series["power_ratio"], color=colour, lw=1.2,
                label=f"computed P_out / P_in ({engine})")
        ax.plot(series["t"], series["efficiency"], color=colour, lw=0.8, ls="--",
                label=f"computed 1 - P_loss / P_in ({engine}, the paper's)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title("Measured against computed efficiency (cf. the paper's Figure 10)", fontsize=10)


def _over_angle(ax: Any, v: Validation, eta: np.ndarray, u: np.ndarray) -> None:
    """The middle panel: measured and computed P_out / P_in over the input yoke angle [deg], every
    revolution overlaid.
    """
    cond = v.conditioned
    angle = np.degrees(np.mod(cond.angle_in[cond.in_window()] + cond.phase, 2 * math.pi))
    order = np.argsort(angle)
    ax.fill_between(angle[order], (eta - K * u)[order], (eta + K * u)[order], color="0.85")
    ax.plot(angle, eta, ".", ms=1, color="k", label="measured P_out / P_in (all revolutions)")
    for engine, series in _series(v).items():
        a = np.degrees(np.mod(series["theta_in"], 2 * math.pi))
        ax.plot(a, series["power_ratio"], ".", ms=1, color=COLOURS.get(engine, "C2"),
                label=f"computed P_out / P_in ({engine})")
    ax.set_xlabel("input yoke angle [deg] (phase estimated)")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=7, loc="lower right", markerscale=8)


def _difference(ax: Any, v: Validation, t: np.ndarray, eta: np.ndarray, u: np.ndarray) -> None:
    """The bottom panel: measured P_out / P_in minus the computed P_out / P_in over time, against the
    measurement's band.
    """
    for engine, series in _series(v).items():
        model = np.interp(t, series["t"], series["power_ratio"])
        ax.plot(t, eta - model, color=COLOURS.get(engine, "C2"), lw=0.8,
                label=f"measured - computed P_out / P_in ({engine})")
    ax.fill_between(t, -K * u, K * u, color="0.85", label="k = 2 band of the measurement")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("difference of P_out / P_in [-]")
    ax.legend(fontsize=7, loc="lower right")


def figure_title(v: Validation) -> str:
    """Figure 10's heading: file, SYNTHETIC when the record is, and the model's shaft angle and friction."""
    model = model_settings(v.scene)
    synthetic = "SYNTHETIC DATA (not a measurement): " if v.record.provenance.get("synthetic") else ""
    return (f"{synthetic}{Path(str(v.record.file)).name}\nmodel {v.scene.name}: shaft angle "
            f"{model['shaft_angle_deg']:.3f} deg, {friction_text(model['friction_coefficient'])}")


def _pyplot() -> Any:
    """matplotlib's pyplot on the file backend."""
    import matplotlib  # imported on first use: only the report draws (0.3 s and a backend choice)

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure(v: Validation) -> Any:
    """Figure 10 of ``v`` headed by :func:`figure_title`: P_out / P_in over time and input angle, measured
    (k = 2 band) against computed, and their difference.
    """
    inst = v.measured.instantaneous
    inside = v.conditioned.in_window()
    t = inst["t"][inside]
    eta = inst["efficiency"][inside]
    u = inst["u"][inside]
    fig, axes = _pyplot().subplots(3, 1, figsize=(9, 10))
    _over_time(axes[0], v, t, eta, u)
    _over_angle(axes[1], v, eta, u)
    _difference(axes[2], v, t, eta, u)
    fig.suptitle(figure_title(v), fontsize=10, color="C3" if v.record.provenance.get("synthetic") else "k")
    fig.tight_layout()
    return fig


def _synthetic_banner(s: dict) -> list[str]:
    """The report's first lines for synthetic data (true efficiency and phase); none otherwise."""
    if not s.get("synthetic"):
        return []
    settings = json.loads(s["synthetic"].get("settings", "{}"))
    return ["**SYNTHETIC DATA** - generated by " + str(s["synthetic"].get("generator")) +
            f" (true efficiency {settings.get('true_efficiency', float('nan')):.6f}, true yoke "
            f"phase {math.degrees(settings.get('true_phase', float('nan')) % math.pi):.3f} deg "
            "modulo 180), not a measurement.", ""]


def friction_text(friction: dict[str, float]) -> str:
    """The friction coefficients in words: one value for every pair, else each pair's."""
    values = set(friction.values())
    if len(values) == 1:
        return f"friction coefficient {number(values.pop(), '.4g')} in every pair"
    return "friction coefficients " + ", ".join(f"{pair} {number(f, '.4g')}" for pair, f in friction.items())


def _versions(env: dict) -> str:
    """The engines with their packages' versions, Python and the other packages, in words."""
    engines = ", ".join(f"{e} ({d['package']} {d['version']})" for e, d in env.get("engines", {}).items())
    packages = ", ".join(f"{p} {ver}" for p, ver in env.get("packages", {}).items() if ver is not None)
    return (f"Engines: {engines or 'none'}; Python {env.get('python')}, {packages}; commit "
            f"{env.get('commit') or 'unknown'}; {env.get('date')}.")


def _reproduce(s: dict) -> list[str]:
    """What the model ran with and how the report was made: scene, shaft angle, friction, file hash,
    command, versions.
    """
    scene = s["scene"]
    model = s["model"]
    command = f"`{s['command']}`" if s.get("command") else "none (the Python API, rigdata.validate)"
    return ["## Model run and how to reproduce it", "",
            f"- Scene `{scene['name']}` (SHA-256 `{scene['sha256']}`; the whole scene, drive and load "
            f"included, is `scene.toml` in validation.json): shaft angle "
            f"**{model['shaft_angle_deg']:.3f} deg**, {friction_text(model['friction_coefficient'])}.",
            f"- Input file `{s['file']}`, SHA-256 `{s.get('file_sha256')}`.",
            f"- Command: {command}.",
            f"- {_versions(s.get('environment', {}))}",
            "- The model alone runs again from validation.json: `rigdata.rerun(\"validation.json\", "
            "engine)`.", ""]


def _conditioning(s: dict) -> list[str]:
    """The file, the window, the filter and the yoke phase, in words."""
    c = s["conditioning"]
    return [f"File `{s['file']}` ({s['provenance'].get('format')}), {s['sample_rate']:.6g} Hz, "
            f"{s['duration_s']:.4g} s. Window: {c['revolutions']} whole input revolutions, "
            f"t = {c['window_s'][0]:.4f} .. {c['window_s'][1]:.4f} s; low-pass {c['cutoff_hz']:.3g} Hz "
            f"({c['cutoff_harmonics']:g} shaft harmonics, Butterworth order {c['filter_order']} "
            f"forward-backward); input yoke phase {c['phase_deg']:.3f} deg "
            f"({c['phase_fit'].get('source')}; shaft angle that fits best "
            f"{math.degrees(c['phase_fit'].get('shaft_angle_fit', float('nan'))):.3f} deg).", ""]


#: Largest relative difference of the interval's two sides still called symmetric [-].
SYMMETRIC_WITHIN = 0.1


def _percent(fraction: float) -> str:
    """``fraction`` [-] in per cent to two significant digits (0.0019: ``0.19``)."""
    return number(100 * fraction, ".2g")


def _shape(s: dict, lo: float, hi: float) -> str:
    """Whether the interval is asymmetric about the estimate (sides differing by more than
    :data:`SYMMETRIC_WITHIN` of their mean) and why; empty when it is not.
    """
    below = s["measured_efficiency"] - lo
    above = hi - s["measured_efficiency"]
    if not abs(above - below) > SYMMETRIC_WITHIN * (above + below) / 2:
        return ""
    return (f" - asymmetric ({number(above, '.4f')} above the estimate, {number(below, '.4f')} below): the "
            f"input work is in the denominator with {_percent(s['relative_u_torque_in'])} % relative "
            "uncertainty")


def _measured(s: dict) -> list[str]:
    """The measured efficiency, its Monte Carlo interval and its uncertainty budget."""
    lines = ["## Measured efficiency over whole revolutions", "",
             f"eta = W_out / W_in = **{s['measured_efficiency']:.4f}**, standard uncertainty "
             f"u = {s['measured_efficiency_u']:.4f} (GUM, first order)."]
    mc = s.get("monte_carlo") or {}
    if mc:
        lo, hi = mc["interval_95"]
        lines += [f"Monte Carlo ({mc['samples']} draws): std {mc['std']:.4f}, 95 % interval "
                  f"[{number(lo, '.4f')}, {number(hi, '.4f')}]{_shape(s, lo, hi)}."]
    lines += ["", f"Mean input speed {s['mean_speed_in']:.4g} rad/s, mean input torque "
              f"{s['mean_torque_in']:.4g} N m, output {s['mean_torque_out']:.4g} N m.", ""]
    rows = [{**b, "u": f"{number(b['standard_uncertainty'], '.3g')} {b['unit']}"}
            for b in s["uncertainty_budget"]]
    lines.append(markdown_table(rows, ["quantity", "u", "sensitivity", "contribution"],
                                formats={"sensitivity": ".3g", "contribution": ".3g"},
                                headers=["input quantity", "standard uncertainty", "sensitivity",
                                         "contribution to u(eta)"]).rstrip("\n"))
    return lines


def _accuracy(s: dict) -> list[str]:
    """What the transducers' accuracy class does to the measurement, and what would be needed."""
    return ["", f"**What the accuracy class does:** with the torques at "
            f"{s['mean_torque_in']:.3g} N m on transducers of "
            f"{s['transducer_in']['full_scale']:g} N m full scale, class "
            f"{100 * s['transducer_in']['accuracy_class']:g} % alone gives each torque a "
            f"{_percent(s['relative_u_torque_in'])} % standard uncertainty; the measured efficiency "
            f"cannot distinguish anything closer than 2u = "
            f"{number(2 * s['measured_efficiency_u'], '.2g')}. For "
            f"u = 0.01 from the class the transducers would need class "
            f"{number(100 * (s['accuracy_class_for_u_0.01'] or math.nan), '.3g')} % (or a full scale "
            "that much smaller), or a zero taken at standstill before the run removing the offset part.",
            ""]


def _computed(s: dict) -> list[str]:
    """Each engine's computed efficiency and its comparison with the measurement."""
    rows = []
    for engine, comp in s["computed"].items():
        cmp = s["comparisons"].get(engine, {})
        interval = cmp.get("difference_interval_95_mc")
        rows.append({**cmp, **comp, "engine": engine, "interval": (
            f"[{number(interval[0], '.4f')}, {number(interval[1], '.4f')}]" if interval else None)})
    table = markdown_table(
        rows, ["engine", "status", "mean_efficiency", "work_ratio", "difference", "difference_u",
               "significant_k2", "interval"],
        formats={key: ".5f" for key in ("mean_efficiency", "work_ratio", "difference", "difference_u")},
        headers=["engine", "status", "mean efficiency", "W_out/W_in", "difference", "u(diff)",
                 "significant (k=2)", "MC 95 % interval of diff"])
    lines = ["## Computed efficiency (model driven by the measurement)", "", table.rstrip("\n")]
    sens = s.get("model_sensitivities") or {}
    if sens:
        lines += ["", f"The model barely depends on the measured load: {number(sens['load'], '.3g')} per "
                  f"N m of output-torque offset (correlated with the measurement's own, propagated as "
                  f"such); the yoke half a turn away changes it by {number(sens['phase_ambiguity'], '.2g')}."]
    return lines


def _checks(s: dict) -> list[str]:
    """One line per check that failed (``rigdata.checks``), none when all passed."""
    return [f"**Check {f['check']}: {f['status']}.** {f['message']}." for f in s.get("checks", [])
            if f["status"] != "ok"] + ([""] if any(f["status"] != "ok" for f in s.get("checks", [])) else [])


def markdown(s: dict) -> str:
    """The report's text, from :meth:`Validation.as_dict`."""
    lines = ["# Rig measurement against the model", "", *_synthetic_banner(s), *_checks(s), *_reproduce(s),
             *_conditioning(s),
             *_measured(s), *_accuracy(s), *_computed(s),
             "", "![Figure 10](figure10.png)", "", FIGURE_CAPTION, "", "## Assumptions", ""]
    lines += [f"- `{k}`: {v}" for k, v in s["assumptions"].items()]
    return "\n".join(lines) + "\n"


def _signals(v: Validation) -> dict[str, np.ndarray]:
    """The conditioned signals with the measured and each engine's instantaneous efficiency."""
    cond = v.conditioned
    inst = v.measured.instantaneous
    table = {"t": cond.t, "angle_in": cond.angle_in, "speed_in": cond.speed_in,
             "speed_out": cond.speed_out, "torque_in": cond.torque_in, "torque_out": cond.torque_out,
             "efficiency_measured": inst["efficiency"], "efficiency_measured_u": inst["u"]}
    for engine, series in _series(v).items():
        table[f"efficiency_{engine}"] = np.interp(cond.t, series["t"], series["efficiency"], left=np.nan,
                                                  right=np.nan)
    return table


def write_report(v: Validation, out: str | os.PathLike,
                 command: Sequence[str] | None = None) -> dict[str, Any]:
    """Write ``report.md``, ``validation.json``, ``figure10.png`` and ``signals.csv`` into ``out`` atomically.

    Built beside ``out`` and swapped in whole, so a failed run leaves the previous report or none.

    Parameters
    ----------
    v : Validation
    out : path-like
        The report folder, replaced as a whole.
    command : sequence of str, optional
        The command line that made ``v`` (``cardan rig validate ...``), stored as ``command``; None: the
        Python API.

    Returns
    -------
    dict
        The JSON summary written to ``validation.json``.
    """
    s = {**v.as_dict(), "command": shlex.join(command) if command is not None else None,
         "environment": to_jsonable(run_environment(v.computed))}
    with atomic_directory(out) as tmp:
        (tmp / "validation.json").write_text(dumps(s), encoding="utf-8")
        (tmp / "report.md").write_text(markdown(s), encoding="utf-8")
        fig = figure(v)
        fig.savefig(tmp / "figure10.png", dpi=110)
        _pyplot().close(fig)
        pd.DataFrame(_signals(v)).to_csv(tmp / "signals.csv", index=False)
    return s
