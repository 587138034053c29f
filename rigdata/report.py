"""The report of a :class:`~rigdata.validation.Validation`: the paper's Figure 10, the text and
the signals, written into a folder atomically.

``report.md`` (measured efficiency with its budget, computed efficiency per engine, the
comparison, assumptions), ``validation.json`` (:meth:`Validation.as_dict`), ``figure10.png``
(:func:`figure`) and ``signals.csv`` (the conditioned signals with the measured and computed
instantaneous efficiency).
"""

from __future__ import annotations

import json
import math
import os
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from rigdata.validation import K, Validation

__all__ = ["figure", "markdown", "write_report"]

#: Line colour of each engine's computed efficiency.
COLOURS = {"reference": "C0", "exudyn": "C1"}


def _limits(eta: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    """Efficiency axis limits [-]: the k = 2 band's 1st and 99th percentiles, widened to show at
    least [0.8, 1.05]."""
    finite = np.isfinite(eta) & np.isfinite(u)
    lo = np.percentile((eta - K * u)[finite], 1) if finite.any() else 0.0
    hi = np.percentile((eta + K * u)[finite], 99) if finite.any() else 1.0
    return float(min(lo, 0.8)), float(max(hi, 1.05))


def _series(v: Validation) -> dict[str, dict[str, np.ndarray]]:
    """Each engine's computed time series (engines that ran ``ok``)."""
    return {engine: comp["series"] for engine, comp in v.computed.items() if comp.get("series") is not None}


def _over_time(ax: Any, v: Validation, t: np.ndarray, eta: np.ndarray, u: np.ndarray) -> None:
    """Figure 10's top panel: the measured efficiency with its band, and the computed ones, over
    time [s]."""
    ax.fill_between(t, eta - K * u, eta + K * u, color="0.85", label="measured, k = 2 band")
    ax.plot(t, eta, color="k", lw=0.8, label="measured P_out / P_in")
    for engine, series in _series(v).items():
        ax.plot(series["t"], series["efficiency"], color=COLOURS.get(engine, "C2"), lw=1.2,
                label=f"computed 1 - P_loss / P_in ({engine})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title("Measured against computed efficiency (cf. the paper's Figure 10)")


def _over_angle(ax: Any, v: Validation, eta: np.ndarray, u: np.ndarray) -> None:
    """The middle panel: the same over the input yoke angle [deg], every revolution overlaid."""
    cond = v.conditioned
    angle = np.degrees(np.mod(cond.angle_in[cond.in_window()] + cond.phase, 2 * math.pi))
    order = np.argsort(angle)
    ax.fill_between(angle[order], (eta - K * u)[order], (eta + K * u)[order], color="0.85")
    ax.plot(angle, eta, ".", ms=1, color="k", label="measured (all revolutions)")
    for engine, series in _series(v).items():
        a = np.degrees(np.mod(series["theta_in"], 2 * math.pi))
        ax.plot(a, series["efficiency"], ".", ms=1, color=COLOURS.get(engine, "C2"),
                label=f"computed ({engine})")
    ax.set_xlabel("input yoke angle [deg] (phase estimated)")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=8, loc="lower right", markerscale=8)


def _difference(ax: Any, v: Validation, t: np.ndarray, eta: np.ndarray, u: np.ndarray) -> None:
    """The bottom panel: measured minus computed over time, against the measurement's band."""
    for engine, series in _series(v).items():
        model = np.interp(t, series["t"], series["efficiency"])
        ax.plot(t, eta - model, color=COLOURS.get(engine, "C2"), lw=0.8,
                label=f"measured - computed ({engine})")
    ax.fill_between(t, -K * u, K * u, color="0.85", label="k = 2 band of the measurement")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("difference [-]")
    ax.legend(fontsize=8, loc="lower right")


def _pyplot() -> Any:
    """matplotlib's pyplot on the file backend."""
    import matplotlib  # imported on first use: only the report draws (0.3 s and a backend choice)

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure(v: Validation) -> Any:
    """Figure 10: efficiency over time and over input angle, measured with its k = 2 band
    against computed; and the difference.

    Parameters
    ----------
    v : Validation
        The validation (its measurement's instantaneous efficiency is computed here if not yet).

    Returns
    -------
    matplotlib.figure.Figure
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


def _measured(s: dict) -> list[str]:
    """The measured efficiency, its Monte Carlo interval and its uncertainty budget."""
    lines = ["## Measured efficiency over whole revolutions", "",
             f"eta = W_out / W_in = **{s['measured_efficiency']:.4f}**, standard uncertainty "
             f"u = {s['measured_efficiency_u']:.4f} (GUM, first order)."]
    mc = s.get("monte_carlo") or {}
    if mc:
        lo, hi = mc["interval_95"]
        lines += [f"Monte Carlo ({mc['samples']} draws): std {mc['std']:.4f}, 95 % interval "
                  f"[{number(lo, '.4f')}, {number(hi, '.4f')}] - asymmetric: the input work is in the "
                  f"denominator with {100 * s['relative_u_torque_in']:.0f} % relative uncertainty."]
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
            f"{100 * s['relative_u_torque_in']:.0f} % standard uncertainty; the measured efficiency "
            f"cannot distinguish anything closer than 2u = {2 * s['measured_efficiency_u']:.2f}. For "
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


def markdown(s: dict) -> str:
    """The report's text, from :meth:`Validation.as_dict`."""
    lines = ["# Rig measurement against the model", "", *_synthetic_banner(s), *_conditioning(s),
             *_measured(s), *_accuracy(s), *_computed(s),
             "", "![Figure 10](figure10.png)", "", "## Assumptions", ""]
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


def write_report(v: Validation, out: str | os.PathLike) -> dict[str, Any]:
    """Write ``report.md``, ``validation.json``, ``figure10.png`` and ``signals.csv`` into
    ``out``, atomically: built in a temporary folder beside it and swapped in whole, so an
    interrupted or failed run leaves the previous report (or none), never half of one.

    Parameters
    ----------
    v : Validation
        From :func:`rigdata.validation.validate`.
    out : path-like
        The report folder (replaced as a whole).

    Returns
    -------
    dict
        The JSON summary written to ``validation.json``.
    """
    s = v.as_dict()
    with atomic_directory(out) as tmp:
        (tmp / "validation.json").write_text(dumps(s), encoding="utf-8")
        (tmp / "report.md").write_text(markdown(s), encoding="utf-8")
        fig = figure(v)
        fig.savefig(tmp / "figure10.png", dpi=110)
        _pyplot().close(fig)
        pd.DataFrame(_signals(v)).to_csv(tmp / "signals.csv", index=False)
    return s
