"""The campaign report's figures, drawn from ``results.json`` (:meth:`CampaignResult.as_dict`): each
function takes that mapping and an optional Axes and returns the Figure; efficiencies and their
uncertainties are dimensionless [-].
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["FIGURES", "efficiency_figure", "model_error_figure", "budget_figure", "residuals_figure", "png"]

#: Colour of a validation recording's resolvable model error, of an unresolvable one, of calibration.
RESOLVABLE = "#c62828"
NOT_RESOLVABLE = "#1565c0"
CALIBRATION = "0.55"
#: Background of a calibration recording's column.
CALIBRATION_SHADE = "0.91"
#: The budget's parts in the order drawn, with their colours (the parts of u_input in one hue).
BUDGET_PARTS = {"u_num": "#1f77b4", "u_parameters": "#8c2d04", "u_inputs": "#d94801", "u_load": "#fd8d3c",
                "u_phase": "#fdd0a2", "u_D": "#2ca02c"}
_MARKERS = ("o", "^", "D", "v", "s")


def _pyplot() -> Any:
    """matplotlib's pyplot on the file backend."""
    import matplotlib  # imported on first use: only the report draws (0.3 s and a backend choice)

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _axes(ax: Any, width: float = 10.5, height: float = 5.4) -> tuple[Any, Any]:
    """``ax``'s figure and ``ax``, or a new figure of ``width`` x ``height`` inches with one Axes."""
    if ax is not None:
        return ax.figure, ax
    fig, ax = _pyplot().subplots(figsize=(width, height), constrained_layout=True)
    return fig, ax


def _num(value: Any) -> float:
    """``value`` as a float, NaN for None."""
    return math.nan if value is None else float(value)


def _tick_label(rec: Mapping[str, Any]) -> str:
    """A recording's tick: label, shaft angle [deg], input speed [rpm] and, without a comparison, why."""
    rpm = (rec.get("operating_point") or {}).get("speed_in_rpm")
    speed = f", {rpm:.0f} rpm" if rpm is not None and math.isfinite(rpm) else ""
    failed = f"\nno comparison ({rec['status']})" if rec["status"] != "ok" else ""
    return f"{rec['label']}\n{rec['shaft_angle_deg']:g} deg{speed}{failed}"


def _recording_axis(ax: Any, recs: Sequence[Mapping[str, Any]]) -> None:
    """Recordings along x in the campaign's order, calibration ones shaded, failed ones' ticks in red."""
    for i, rec in enumerate(recs):
        if rec["use"] == "calibration":
            ax.axvspan(i - 0.5, i + 0.5, color=CALIBRATION_SHADE, zorder=0, lw=0)
    ax.set_xticks(range(len(recs)))
    ticks = ax.set_xticklabels([_tick_label(r) for r in recs], fontsize=8,
                               rotation=30 if len(recs) > 10 else 0)
    for tick, rec in zip(ticks, recs, strict=True):
        if rec["status"] != "ok":
            tick.set_color(RESOLVABLE)
    ax.set_xlim(-0.5, len(recs) - 0.5)
    ax.set_xlabel("recording (shaft angle, mean input speed), in the campaign's order")
    ax.grid(axis="y", alpha=0.3)


def _patch(colour: str, label: str) -> Any:
    """A legend entry: a filled box of ``colour``."""
    from matplotlib.patches import Patch  # matplotlib loads on first use (see _pyplot)

    return Patch(facecolor=colour, edgecolor="0.4", label=label)


def _shade_handle() -> Any:
    """The legend entry of the shaded calibration columns."""
    return _patch(CALIBRATION_SHADE, "calibration recording (shaded)")


def _legend(ax: Any, extra: Sequence[Any] = (), **kwargs: Any) -> None:
    """The Axes' legend with one entry per label, ``extra`` handles appended."""
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles, strict=True))
    for handle in extra:
        unique[handle.get_label()] = handle
    ax.legend(unique.values(), unique.keys(), fontsize=8, **kwargs)


def _engine_values(recs: Sequence[Mapping[str, Any]], engine: str) -> np.ndarray:
    """Each recording's simulated efficiency on ``engine`` (NaN unless its run ended ``ok``)."""
    out = []
    for rec in recs:
        comp = rec.get("by_engine", {}).get(engine) or {}
        out.append(_num(comp.get("simulated")) if comp.get("status") == "ok" else math.nan)
    return np.array(out)


def efficiency_figure(data: Mapping[str, Any], ax: Any = None) -> Any:
    """Measured ``D`` (error bars +-k u_D) and each engine's simulated ``S`` (the first engine's with
    +-k u_input) per recording.
    """
    fig, ax = _axes(ax)
    recs = data["recordings"]
    k = data["campaign"]["k"]
    x = np.arange(len(recs))
    engines = data["campaign"]["engines"]
    step = 0.5 / (len(engines) + 1)
    measured = np.array([_num(r["measured"]) for r in recs])
    u_d = np.array([_num(r["u_D"]) for r in recs])
    ax.errorbar(x - step, measured, yerr=k * u_d, fmt="s", color="k", ms=6, capsize=4,
                label="measured D, error bar ±k u_D")
    for j, engine in enumerate(engines):
        s = _engine_values(recs, engine)
        yerr = None
        label = f"simulated S ({engine})"
        if j == 0:
            yerr = k * np.array([_num((r.get("budget") or {}).get("u_input")) for r in recs])
            label += ", error bar ±k u_input"
        ax.errorbar(x + j * step, s, yerr=yerr, fmt=_MARKERS[j % len(_MARKERS)], color=f"C{j}", ms=6,
                    capsize=4, mfc="white" if j else f"C{j}", label=label)
    _recording_axis(ax, recs)
    ax.set_ylabel("mean efficiency over whole revolutions [-]")
    ax.set_title(f"Measured and simulated efficiency per recording (k = {k:.3g}, "
                 f"{100 * data['campaign']['coverage']:g} % coverage)")
    _legend(ax, [_shade_handle()], loc="best")
    return fig


def _error_style(rec: Mapping[str, Any]) -> tuple[str, str]:
    """Colour and legend label of a recording's comparison error."""
    if rec["use"] == "calibration":
        return CALIBRATION, "calibration: not a validation"
    if rec.get("resolvable"):
        return RESOLVABLE, "resolvable model error: |E| > k u_val"
    return NOT_RESOLVABLE, "not resolvable: |E| ≤ k u_val"


def model_error_figure(data: Mapping[str, Any], ax: Any = None) -> Any:
    """The comparison error ``E = S - D`` of the first engine per recording with +-k u_val, the
    resolvable ones in red, the calibration ones in grey.
    """
    fig, ax = _axes(ax)
    recs = data["recordings"]
    k = data["campaign"]["k"]
    ax.axhline(0.0, color="k", lw=0.8)
    for i, rec in enumerate(recs):
        if rec["status"] != "ok":
            continue
        colour, label = _error_style(rec)
        ax.errorbar([i], [_num(rec["comparison_error"])], yerr=[k * _num(rec["u_val"])], fmt="o",
                    color=colour, ms=7, capsize=5, lw=2, label=label)
    _recording_axis(ax, recs)
    ax.set_ylabel("comparison error E = S - D [-]")
    coverage = 100 * data["campaign"]["coverage"]
    ax.set_title(f"Model error estimate E = S - D ({data['campaign']['engines'][0]}) with ±k u_val, "
                 f"k = {k:.3g}: the interval holds the model error with {coverage:g} % coverage", fontsize=10)
    _legend(ax, [_shade_handle()], loc="best")
    return fig


def _budget_parts(rec: Mapping[str, Any]) -> dict[str, float]:
    """A recording's u_num, the four parts of u_input and u_D [-] (NaN where missing)."""
    b = rec.get("budget") or {}
    return {part: _num(rec.get("u_num") if part == "u_num" else b.get(part)) for part in BUDGET_PARTS}


def _floor(recs: Sequence[Mapping[str, Any]]) -> float:
    """The log axis' bottom: a third of the smallest positive part, at least 1e-16."""
    values = [v for r in recs for v in _budget_parts(r).values() if math.isfinite(v) and v > 0]
    return max(min(values, default=1e-12) / 3.0, 1e-16)


def budget_figure(data: Mapping[str, Any], ax: Any = None) -> Any:
    """Per recording a group of bars on a log axis: u_num, u_input's parts (u_parameters, u_inputs,
    u_load, u_phase) and u_D, with u_input and u_val as lines across the group.
    """
    fig, ax = _axes(ax, height=6.4)
    recs = data["recordings"]
    width = 0.8 / len(BUDGET_PARTS)
    for i, rec in enumerate(recs):
        parts = _budget_parts(rec)
        for j, (part, colour) in enumerate(BUDGET_PARTS.items()):
            if math.isfinite(parts[part]) and parts[part] > 0:
                ax.bar(i - 0.4 + (j + 0.5) * width, parts[part], width, color=colour, edgecolor="0.3",
                       lw=0.4)
        if rec.get("budget"):
            ax.hlines(_num(rec["budget"]["u_input"]), i - 0.4 + width, i - 0.4 + 5 * width, color="#8c2d04",
                      lw=1.5, ls="--", label="u_input (root sum of squares of its parts)")
        ax.hlines(_num(rec.get("u_val")), i - 0.45, i + 0.45, color="k", lw=2, label="u_val")
    parts = [_patch(colour, part) for part, colour in BUDGET_PARTS.items()]
    ax.set_yscale("log")
    ax.set_ylim(bottom=_floor(recs))
    _recording_axis(ax, recs)
    ax.set_ylabel("standard uncertainty of efficiency [-] (log)")
    ax.set_title(f"Validation uncertainty budget per recording ({data['campaign']['engines'][0]}); "
                 "a part equal to 0 has no bar", fontsize=10)
    _legend(ax, [*parts, _shade_handle()], loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=5)
    return fig


def _rejection_text(cal: Mapping[str, Any], coverage: float) -> str:
    """The chi-square test in a line."""
    level = f"{100 * (1 - coverage):.3g} %"
    p = cal.get("p_value")
    verdict = {True: f"the model is rejected at the {level} level",
               False: f"not rejected at the {level} level"}.get(cal.get("rejected"), "no test (no dof)")
    p_text = f"{p:.2g}" if p is not None else "-"
    return f"chi-square = {cal['chi_square']:.3g}, dof = {cal['dof']}, p = {p_text}: {verdict}"


def residuals_figure(data: Mapping[str, Any], ax: Any = None) -> Any:
    """The calibration residuals ``(S - D) / sigma`` at the estimate per calibration recording, with
    +-1 and +-k lines and the chi-square test in the title. ValueError without a calibration.
    """
    cal = data.get("calibration")
    if not cal:
        raise ValueError("`data` has no calibration: no residuals to draw")
    k = data["campaign"]["k"]
    labels = {r["index"]: r["label"] for r in data["recordings"]}
    names = [labels.get(i, str(i)) for i in cal["recordings"]]
    residuals = np.asarray(cal["residuals"], dtype=float)
    fig, ax = _axes(ax, width=max(6.0, 1.3 * len(names) + 2.5), height=4.8)
    colours = [RESOLVABLE if abs(r) > k else NOT_RESOLVABLE for r in residuals]
    ax.bar(range(len(names)), residuals, 0.6, color=colours, edgecolor="0.3")
    beyond = _patch(RESOLVABLE, "|residual| > k")
    for level, style, label in ((1.0, "--", "±1"), (k, ":", f"±k = ±{k:.3g}")):
        ax.axhline(level, color="0.3", ls=style, lw=1.2, label=label)
        ax.axhline(-level, color="0.3", ls=style, lw=1.2)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, fontsize=8)
    ax.set_xlabel("calibration recording")
    ax.set_ylabel("residual (S - D) / sigma [-]")
    bound = max(float(np.max(np.abs(residuals), initial=0.0)), k) * 1.2
    ax.set_ylim(-bound, bound)
    ax.grid(axis="y", alpha=0.3)
    test = _rejection_text(cal, data["campaign"]["coverage"])
    ax.set_title(f"Calibration residuals at the estimate\n{test}", fontsize=10)
    _legend(ax, [beyond], loc="best")
    return fig


FIGURES = {"efficiency": efficiency_figure, "model_error": model_error_figure, "budget": budget_figure,
           "residuals": residuals_figure}
"""The report's figures by file stem (``efficiency.png`` ...), in the report's order."""


def png(fig: Any, dpi: int = 100) -> bytes:
    """``fig`` as PNG bytes at ``dpi`` (100: the figure's inches are its size on screen at 100 % zoom);
    the figure is closed.
    """
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    _pyplot().close(fig)
    return buffer.getvalue()
