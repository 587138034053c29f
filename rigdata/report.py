"""Measured against computed efficiency, as the paper's Figure 10, with the uncertainty.

:func:`validate` conditions a record, measures its efficiency with the uncertainty budget,
drives each engine with it and compares: the difference, its standard uncertainty (the output
transducer's error enters both sides, so that part is propagated as correlated) and whether it
is significant at k = 2 (and by the Monte Carlo interval, which at 0.2 N m is far from
symmetric). :func:`write_report` puts it in a folder atomically.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any

import numpy as np

from cardan_exudyn.io import atomic_directory, dumps, to_jsonable
from reference.scene import Scene
from rigdata.conditioning import Conditioned, Conditioning, condition
from rigdata.efficiency import SQRT3, Measured, measured_efficiency
from rigdata.model import computed_efficiency, measured_scene, model_sensitivities, run_engine
from rigdata.record import RigRecord
from rigdata.transducer import PROVENANCE, Transducer

K = 2.0  # coverage factor of the significance test
#: Budget rows that are a constant error of the output torque, which the model's load shares.
CONSTANT_OUTPUT_ERRORS = ("accuracy class, output torque", "resolution (acquisition step), output torque")


def compare(measured: Measured, computed: dict, sensitivities: dict) -> dict:
    """Difference measured - computed, its standard uncertainty and significance (k = 2).

    The output transducer's constant errors (class, resolution) move the measured efficiency by
    ``c_meas`` per N m and the computed one (through the load) by ``sensitivities["load"]``: the
    difference sees ``c_meas - c_model`` (the drift, a ramp, is left uncorrelated: its share is
    below 1e-3 of the variance). The yoke phase's half-turn ambiguity is a rectangular term of half
    width |difference| / 2.
    """
    eta_model = computed["mean_efficiency"]
    d = measured.efficiency - eta_model
    terms = []
    for row in measured.budget:
        c = row["sensitivity"]
        if row["quantity"] in CONSTANT_OUTPUT_ERRORS:  # the model's load carries them too
            c = c - sensitivities["load"]
        terms.append(c * row["standard_uncertainty"])
    terms.append(0.5 * abs(sensitivities["phase_ambiguity"]) / SQRT3)
    u = math.sqrt(sum(x * x for x in terms))
    out = {"engine": computed["engine"], "computed_efficiency": eta_model, "difference": d,
           "difference_u": u, "expanded_u": K * u, "significant_k2": bool(abs(d) > K * u)}
    draws = measured.draws
    if draws:
        diffs = draws["efficiency"] - (eta_model + sensitivities["load"] * draws["offset_out"])
        lo, hi = np.percentile(diffs, [2.5, 97.5])
        # the draws spread the measurement around its value; the difference is significant when
        # zero is outside the 95 % interval of the difference they give
        out["difference_interval_95_mc"] = [float(lo), float(hi)]
        out["significant_mc"] = bool(not (lo <= 0.0 <= hi))
    return out


def validate(record: RigRecord, base: Scene, engines: tuple[str, ...] = ("reference", "exudyn"),
             conditioning: Conditioning | None = None,
             transducers: tuple[Transducer, Transducer] | None = None, monte_carlo: int = 2000,
             seed: int = 0, progress=None) -> dict[str, Any]:
    """The whole comparison for one record (see the module docstring).

    Parameters
    ----------
    record : RigRecord
    base : Scene
        Joint, friction and numerics of the model (its drive and load are replaced).
    engines : tuple of str
    progress : callable(str) or None
        Called with a line before each long step.
    """
    say = progress or (lambda line: None)
    transducers = transducers or (Transducer(), Transducer())
    say("conditioning")
    cond = condition(record, base.joint.geometry.shaft_angle, conditioning)
    say("measured efficiency and its uncertainty")
    measured = measured_efficiency(cond, transducers, monte_carlo=monte_carlo, seed=seed)
    scene = measured_scene(cond, base)
    computed, comparisons, sens = {}, {}, None
    for engine in engines:
        say(f"model driven by the measurement: {engine}")
        computed[engine] = computed_efficiency(run_engine(engine, scene))
        if computed[engine]["status"] != "ok":
            continue
        if sens is None:
            say("model sensitivities (load offset, yoke half turn)")
            sens = model_sensitivities(cond, base, transducers[1].accuracy_limit / SQRT3,
                                       computed[engine]["mean_efficiency"] if engine == "reference"
                                       else _reference_eta(cond, base))
        comparisons[engine] = compare(measured, computed[engine], sens)
    return {"record": record, "conditioned": cond, "measured": measured, "scene": scene,
            "computed": computed, "comparisons": comparisons, "sensitivities": sens or {},
            "transducers": transducers}


def _reference_eta(cond: Conditioned, base: Scene) -> float:
    return float(computed_efficiency(run_engine("reference", measured_scene(cond, base)))["mean_efficiency"])


def accuracy_needed(measured: Measured, target_u: float = 0.01) -> float:
    """Accuracy class [-] the torque transducers would need for a standard uncertainty of
    ``target_u`` from the class alone (it scales linearly)."""
    acc = [b["contribution"] for b in measured.budget if b["quantity"].startswith("accuracy class")]
    total = math.sqrt(sum(a * a for a in acc))
    cls = measured.summary["transducer_in"]["accuracy_class"]
    return cls * target_u / total if total > 0 else float("nan")


# --------------------------------------------------------------------------- output

def summary(v: dict) -> dict:
    """JSON summary of :func:`validate`'s result."""
    rec, cond, meas = v["record"], v["conditioned"], v["measured"]
    synthetic = rec.provenance.get("synthetic")
    out = {
        "file": str(rec.file), "provenance": {k: val for k, val in rec.provenance.items()
                                              if k not in ("header", "synthetic")},
        "synthetic": synthetic, "sample_rate": rec.sample_rate, "duration_s": rec.duration,
        "conditioning": {**cond.settings, "cutoff_hz": cond.cutoff, "window_s": list(cond.window),
                         "revolutions": cond.revolutions, "phase": cond.phase,
                         "phase_deg": math.degrees(cond.phase), "phase_fit": cond.phase_fit},
        **meas.as_dict(),
        "computed": {engine: {k: val for k, val in comp.items() if k != "series"}
                     for engine, comp in v["computed"].items()},
        "comparisons": v["comparisons"],
        "model_sensitivities": v["sensitivities"],
        "accuracy_class_for_u_0.01": accuracy_needed(meas),
        "assumptions": PROVENANCE,
    }
    return to_jsonable(out)


def figure(v: dict):
    """Figure 10: efficiency over time and over input angle, measured with its k = 2 band
    against computed; and the difference."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cond, meas = v["conditioned"], v["measured"]
    inst = meas.instantaneous
    inside = cond.in_window()
    t = inst["t"][inside]
    eta, u = inst["efficiency"][inside], inst["u"][inside]
    fig, axes = plt.subplots(3, 1, figsize=(9, 10))
    ax = axes[0]
    ax.fill_between(t, eta - K * u, eta + K * u, color="0.85", label="measured, k = 2 band")
    ax.plot(t, eta, color="k", lw=0.8, label="measured P_out / P_in")
    colours = {"reference": "C0", "exudyn": "C1"}
    for engine, comp in v["computed"].items():
        series = comp.get("series")
        if series is not None:
            ax.plot(series["t"], series["efficiency"], color=colours.get(engine, "C2"), lw=1.2,
                    label=f"computed 1 - P_loss / P_in ({engine})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title("Measured against computed efficiency (cf. the paper's Figure 10)")
    ax = axes[1]
    angle = np.degrees(np.mod(cond.angle_in[inside] + cond.phase, 2 * math.pi))
    order = np.argsort(angle)
    ax.fill_between(angle[order], (eta - K * u)[order], (eta + K * u)[order], color="0.85")
    ax.plot(angle, eta, ".", ms=1, color="k", label="measured (all revolutions)")
    for engine, comp in v["computed"].items():
        series = comp.get("series")
        if series is not None:
            a = np.degrees(np.mod(series["theta_in"], 2 * math.pi))
            ax.plot(a, series["efficiency"], ".", ms=1, color=colours.get(engine, "C2"),
                    label=f"computed ({engine})")
    ax.set_xlabel("input yoke angle [deg] (phase estimated)")
    ax.set_ylabel("efficiency [-]")
    ax.set_ylim(*_limits(eta, u))
    ax.legend(fontsize=8, loc="lower right", markerscale=8)
    ax = axes[2]
    for engine, comp in v["computed"].items():
        series = comp.get("series")
        if series is not None:
            model = np.interp(t, series["t"], series["efficiency"])
            ax.plot(t, eta - model, color=colours.get(engine, "C2"), lw=0.8,
                    label=f"measured - computed ({engine})")
    ax.fill_between(t, -K * u, K * u, color="0.85", label="k = 2 band of the measurement")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("difference [-]")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return fig


def _limits(eta: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    finite = np.isfinite(eta) & np.isfinite(u)
    lo = np.percentile((eta - K * u)[finite], 1) if finite.any() else 0.0
    hi = np.percentile((eta + K * u)[finite], 99) if finite.any() else 1.0
    return float(min(lo, 0.8)), float(max(hi, 1.05))


def markdown(s: dict) -> str:
    """The report's text."""
    lines = ["# Rig measurement against the model", ""]
    if s.get("synthetic"):
        settings = json.loads(s["synthetic"].get("settings", "{}"))
        lines += ["**SYNTHETIC DATA** - generated by " + str(s["synthetic"].get("generator")) +
                  f" (true efficiency {settings.get('true_efficiency', float('nan')):.6f}, true yoke "
                  f"phase {math.degrees(settings.get('true_phase', float('nan')) % math.pi):.3f} deg "
                  "modulo 180), not a measurement.", ""]
    c = s["conditioning"]
    lines += [f"File `{s['file']}` ({s['provenance'].get('format')}), {s['sample_rate']:.6g} Hz, "
              f"{s['duration_s']:.4g} s. Window: {c['revolutions']} whole input revolutions, "
              f"t = {c['window_s'][0]:.4f} .. {c['window_s'][1]:.4f} s; low-pass {c['cutoff_hz']:.3g} Hz "
              f"({c['cutoff_harmonics']:g} shaft harmonics, Butterworth order {c['filter_order']} "
              f"forward-backward); input yoke phase {c['phase_deg']:.3f} deg "
              f"({c['phase_fit'].get('source')}; shaft angle that fits best "
              f"{math.degrees(c['phase_fit'].get('shaft_angle_fit', float('nan'))):.3f} deg).", "",
              "## Measured efficiency over whole revolutions", "",
              f"eta = W_out / W_in = **{s['measured_efficiency']:.4f}**, standard uncertainty "
              f"u = {s['measured_efficiency_u']:.4f} (GUM, first order)."]
    mc = s.get("monte_carlo") or {}
    if mc:
        lo, hi = mc["interval_95"]
        lines += [f"Monte Carlo ({mc['samples']} draws): std {mc['std']:.4f}, 95 % interval "
                  f"[{lo:.4f}, {hi:.4f}] - asymmetric: the input work is in the denominator with "
                  f"{100 * s['relative_u_torque_in']:.0f} % relative uncertainty."]
    lines += ["", f"Mean input speed {s['mean_speed_in']:.4g} rad/s, mean input torque "
              f"{s['mean_torque_in']:.4g} N m, output {s['mean_torque_out']:.4g} N m.", "",
              "| input quantity | standard uncertainty | sensitivity | contribution to u(eta) |",
              "|---|---|---|---|"]
    for b in s["uncertainty_budget"]:
        lines.append(f"| {b['quantity']} | {b['standard_uncertainty']:.3g} {b['unit']} | "
                     f"{b['sensitivity']:.3g} | {b['contribution']:.3g} |")
    lines += ["", f"**What the accuracy class does:** with the torques at "
              f"{s['mean_torque_in']:.3g} N m on transducers of "
              f"{s['transducer_in']['full_scale']:g} N m full scale, class "
              f"{100 * s['transducer_in']['accuracy_class']:g} % alone gives each torque a "
              f"{100 * s['relative_u_torque_in']:.0f} % standard uncertainty; the measured efficiency "
              f"cannot distinguish anything closer than 2u = {2 * s['measured_efficiency_u']:.2f}. For "
              f"u = 0.01 from the class the transducers would need class "
              f"{100 * s['accuracy_class_for_u_0.01']:.3g} % (or a full scale that much smaller), or "
              "a zero taken at standstill before the run removing the offset part.", "",
              "## Computed efficiency (model driven by the measurement)", "",
              "| engine | status | mean efficiency | W_out/W_in | difference | u(diff) | significant (k=2) |"
              " MC 95 % interval of diff |", "|---|---|---|---|---|---|---|---|"]
    for engine, comp in s["computed"].items():
        cmp = s["comparisons"].get(engine, {})
        interval = cmp.get("difference_interval_95_mc")
        lines.append(
            f"| {engine} | {comp['status']} | {_f(comp.get('mean_efficiency'))} | "
            f"{_f(comp.get('work_ratio'))} | {_f(cmp.get('difference'))} | {_f(cmp.get('difference_u'))} | "
            f"{cmp.get('significant_k2', '-')} | "
            + (f"[{interval[0]:.4f}, {interval[1]:.4f}]" if interval else "-") + " |")
    sens = s.get("model_sensitivities") or {}
    if sens:
        lines += ["", f"The model barely depends on the measured load: {sens['load']:.3g} per N m of "
                  f"output-torque offset (correlated with the measurement's own, propagated as such); "
                  f"the yoke half a turn away changes it by {sens['phase_ambiguity']:.2g}."]
    lines += ["", "![Figure 10](figure10.png)", "", "## Assumptions", ""]
    lines += [f"- `{k}`: {v}" for k, v in s["assumptions"].items()]
    return "\n".join(lines) + "\n"


def _f(x: Any) -> str:
    return f"{x:.5f}" if isinstance(x, (int, float)) and x is not None else "-"


def write_report(v: dict, out: str | os.PathLike) -> dict:
    """Write ``report.md``, ``validation.json``, ``figure10.png`` and ``signals.csv`` into
    ``out``, atomically: built in a temporary folder beside it and swapped in whole, so an
    interrupted or failed run leaves the previous report (or none), never half of one."""
    import pandas as pd

    s = summary(v)
    with atomic_directory(out) as tmp:
        (tmp / "validation.json").write_text(dumps(s), encoding="utf-8")
        (tmp / "report.md").write_text(markdown(s), encoding="utf-8")
        fig = figure(v)
        fig.savefig(tmp / "figure10.png", dpi=110)
        import matplotlib.pyplot as plt

        plt.close(fig)
        cond, inst = v["conditioned"], v["measured"].instantaneous
        table = {"t": cond.t, "angle_in": cond.angle_in, "speed_in": cond.speed_in,
                 "speed_out": cond.speed_out, "torque_in": cond.torque_in, "torque_out": cond.torque_out,
                 "efficiency_measured": inst["efficiency"], "efficiency_measured_u": inst["u"]}
        for engine, comp in v["computed"].items():
            if comp.get("series") is not None:
                table[f"efficiency_{engine}"] = np.interp(cond.t, comp["series"]["t"],
                                                          comp["series"]["efficiency"], left=np.nan,
                                                          right=np.nan)
        pd.DataFrame(table).to_csv(tmp / "signals.csv", index=False)
    return s
