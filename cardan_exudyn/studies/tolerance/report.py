"""The folders of ``cardan tolerance`` (Monte Carlo study, paper case), each written atomically."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.studies.tolerance.montecarlo import LEVELS, MonteCarlo
from cardan_exudyn.studies.tolerance.paper_case import COUPLINGS, LAWS, MATCH_FACTOR
from reference.results.summary import Status
from reference.scene.joint import PAIR_NAMES

__all__ = ["write_monte_carlo", "monte_carlo_plots", "monte_carlo_markdown", "percentile_table",
           "verdict_line", "write_paper_case", "breakdown_plot", "paper_markdown", "PAPER_COLUMNS",
           "PAPER_HEADERS", "PAPER_FORMATS", "ENVELOPE_COLUMNS"]

PAPER_COLUMNS = ["parameters", "law", "coupling", "engine", "eta_ideal", "eta_errors", "change",
                 "relative_change", "sliding_share", *(f"d_loss_{p}" for p in PAIR_NAMES)]
PAPER_HEADERS = ["parameters", "law", "coupling", "engine", "eta ideal", "eta errors", "change", "relative",
                 "sliding work / W_in", *(f"d loss {p}" if k == 0 else p for k, p in enumerate(PAIR_NAMES))]
PAPER_FORMATS = {"eta_ideal": ".6f", "eta_errors": ".6f", "change": "+.2e", "relative_change": "+.3%",
                 "sliding_share": ".2e", **{f"d_loss_{p}": "+.2e" for p in PAIR_NAMES}}
ENVELOPE_COLUMNS = ["parameters", "coupling", "combinations ok", "change min", "change max"]
SENSITIVITY_FORMATS = {"Spearman rho": "+.3f", "rho with magnitude": "+.3f", "correlation ratio": ".3f"}


def write_monte_carlo(study: MonteCarlo, folder: str | Path) -> Path:
    """The ``study``'s folder (replaced atomically): ``samples.csv``, ``sensitivity.csv``,
    ``tolerance.json``, the plots of :func:`monte_carlo_plots` and ``report.md``.
    """
    summary = study.summary
    with atomic_directory(Path(folder)) as tmp:
        study.table.to_csv(tmp / "samples.csv", index=False)
        study.sensitivity.to_csv(tmp / "sensitivity.csv", index=False)
        (tmp / "tolerance.json").write_text(dumps(summary), encoding="utf-8")
        monte_carlo_plots(tmp, study.ok_table, list(summary["distributions"]),
                          summary["ideal_mean_efficiency"])
        (tmp / "report.md").write_text(monte_carlo_markdown(summary, study.sensitivity), encoding="utf-8")
    return Path(folder)


def monte_carlo_plots(folder: Path, table, params: Sequence[str], eta0: float) -> None:
    """``efficiency_histogram.png`` and ``efficiency_vs_errors.png`` into ``folder`` from the ok samples
    ``table``, errors ``params`` and ideal efficiency ``eta0`` [-]; nothing without a sample.
    """
    # import cost: matplotlib only when a study is written
    from cardan_exudyn.report.plots import plt, save

    if "mean_efficiency" not in table or table.empty:
        return
    eta = table["mean_efficiency"].to_numpy(float)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.hist(eta, bins=max(10, int(math.sqrt(eta.size))), color="0.6")
    ax.axvline(eta0, color="k", ls="--", label=f"ideal joint {number(eta0, '.5f')}")
    for q, style in ((5, ":"), (50, "-"), (95, ":")):
        ax.axvline(np.percentile(eta, q), color="C0", ls=style, label=f"p{q}")
    ax.set(xlabel="mean efficiency [-]", ylabel="samples", title="Monte Carlo: mean efficiency")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, folder / "efficiency_histogram.png", dpi=120)
    _scatter(folder / "efficiency_vs_errors.png", table, params, eta, eta0)


def _scatter(path: Path, table, params: Sequence[str], eta: np.ndarray, eta0: float) -> None:
    """Mean efficiency ``eta`` against each error of ``params``, ``eta0`` dashed, into ``path``."""
    from cardan_exudyn.report.plots import plt, save  # import cost, as above

    cols = min(3, len(params))
    rows = math.ceil(len(params) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows), squeeze=False)
    for ax, p in zip(axes.ravel(), params, strict=False):
        ax.plot(table[p], eta, ".", ms=3, alpha=0.5)
        ax.axhline(eta0, color="k", ls="--", lw=0.8)
        ax.set(xlabel=p.split(".")[-1], ylabel="mean efficiency [-]")
    for ax in axes.ravel()[len(params):]:
        ax.set_visible(False)
    fig.tight_layout()
    save(fig, path, dpi=120)


def monte_carlo_markdown(summary: Mapping[str, Any], sens) -> str:
    """``report.md`` of the Monte Carlo study: ``summary`` and sensitivities ``sens`` (empty: none)."""
    ideal = (f"{number(summary['ideal_mean_efficiency'], '.6f')}." if summary["ideal_status"] == Status.OK
             else f"{summary['ideal_status']}: {summary.get('ideal_reason', '')}.")
    parts = [f"# Monte Carlo tolerance study: {summary['scene']} ({summary['engine']})\n\n"
             f"{summary['samples']} samples ({summary['method']}, seed {summary['seed']}); "
             f"statuses {summary['status_counts']}; ideal joint {ideal}\n\n",
             markdown_table([{"parameter": f"`{p}`", "distribution": str(d)}
                             for p, d in summary["distributions"].items()],
                            ["parameter", "distribution"])]
    if summary["mean_efficiency"]:
        parts += ["\n", percentile_table(summary["mean_efficiency"], summary["change"])]
    if len(sens):
        rows = [{"parameter": f"`{r.parameter}`", "Spearman rho": r.spearman,
                 "rho with magnitude": r.spearman_magnitude, "correlation ratio": r.correlation_ratio}
                for r in sens.itertuples()]
        parts += ["\n", markdown_table(rows, list(rows[0]), SENSITIVITY_FORMATS)]
    parts.append("\nPlots: `efficiency_histogram.png`, `efficiency_vs_errors.png`.\n")
    return "".join(parts)


def percentile_table(m: Mapping[str, float], change: Mapping[str, float]) -> str:
    """Markdown table of the percentiles, mean and std of the mean efficiency ``m`` and of its
    ``change`` from the ideal joint [-].
    """
    rows = [{"statistic": f"p{q}", "mean efficiency": m[f"p{q}"], "change from ideal": change.get(f"p{q}")}
            for q in LEVELS]
    rows.append({"statistic": "mean / std", "change from ideal": "",
                 "mean efficiency": f"{number(m['mean'], '.6f')} / {number(m['std'], '.2e')}"})
    return markdown_table(rows, ["statistic", "mean efficiency", "change from ideal"],
                          {"mean efficiency": ".6f", "change from ideal": "+.3e"})


def verdict_line(v: Mapping[str, Any], paper: float) -> str:
    """One sentence: which law/coupling of verdict ``v`` matches the paper's relative change ``paper``."""
    if v["closest"] is None:
        return f"{v['parameters']}, {v['engine']}: no combination ran ok"
    said = "matches" if v["matches"] else f"is the closest, but outside a factor {MATCH_FACTOR:g} of"
    change = number(v["cells"][v["closest"]], "+.3%")
    return (f"{v['parameters']}, {v['engine']}: {v['closest']} ({change}) "
            f"{said} the paper's {number(paper, '.2%')}")


def write_paper_case(study: Mapping[str, Any], out: str | Path) -> dict[str, Any]:
    """The paper case's folder ``out`` (replaced atomically) from ``study``: ``paper_case.csv``,
    ``paper_case.json``, ``paper_case_breakdown.png``, ``report.md``; returns the JSON's content.
    """
    rows = study["rows"]
    summary = {"paper_change": study["paper_change"], "cases": rows.to_dict(orient="records"),
               "sign_envelope": study["sign_envelope"], "verdicts": study["verdicts"]}
    with atomic_directory(Path(out)) as tmp:
        rows.to_csv(tmp / "paper_case.csv", index=False)
        (tmp / "paper_case.json").write_text(dumps(summary), encoding="utf-8")
        breakdown_plot(tmp / "paper_case_breakdown.png", rows)
        text = paper_markdown(rows, study["sign_envelope"], study["paper_change"], study["verdicts"])
        (tmp / "report.md").write_text(text, encoding="utf-8")
    return summary


def breakdown_plot(path: Path, rows) -> None:
    """Stacked bars of each pair's loss change per ok row of ``rows`` into ``path`` (none ok: nothing)."""
    # import cost: matplotlib only when a report is written
    from cardan_exudyn.report.plots import plt, save

    ok = rows[(rows.status_errors == Status.OK) & (rows.status_ideal == Status.OK)]
    if ok.empty:
        return
    fig, ax = plt.subplots(figsize=(max(8, 0.6 * len(ok)), 4))
    labels = [f"{r.parameters}\n{r.law}\n{r.coupling}\n{r.engine}" for r in ok.itertuples()]
    bottom_pos = np.zeros(len(ok))
    bottom_neg = np.zeros(len(ok))
    for k, pair in enumerate(PAIR_NAMES):
        v = ok[f"d_loss_{pair}"].to_numpy(float)
        base = np.where(v >= 0, bottom_pos, bottom_neg)
        ax.bar(range(len(ok)), v, bottom=base, color=f"C{k}", label=pair)
        bottom_pos = bottom_pos + np.maximum(v, 0)
        bottom_neg = bottom_neg + np.minimum(v, 0)
    ax.set_xticks(range(len(ok)), labels, fontsize=7)
    ax.set_yscale("symlog", linthresh=1e-4)
    ax.set_ylabel("change of pair loss / input work [-]")
    ax.set_title("Where the stated errors' efficiency change comes from (rig case)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path, dpi=120)


def law_table(v: Mapping[str, Any], paper: float) -> str:
    """Verdict ``v``'s table of relative changes (coupling x law) and its sentence against ``paper``."""
    rows = [{"coupling": c, **{law: v["cells"].get(f"{law}/{c}", "-") for law in LAWS}}
            for c in COUPLINGS]
    table = markdown_table(rows, ["coupling", *LAWS], {law: "+.3%" for law in LAWS})
    return f"`{v['parameters']}`, {v['engine']}:\n\n{table}\n{verdict_line(v, paper)}.\n\n"


def _case_rows(rows) -> list[dict[str, Any]]:
    """The cases table's rows; a failed run's status stands in for the efficiency with errors."""
    cases = []
    for r in rows.to_dict(orient="records"):
        if r["status_errors"] != Status.OK or r["status_ideal"] != Status.OK:
            r = {**{c: None for c in PAPER_COLUMNS}, **{c: r[c] for c in PAPER_COLUMNS[:5]},
                 "eta_errors": r["status_errors"]}
        cases.append(r)
    return cases


def paper_markdown(rows, envelope: Sequence[Mapping[str, Any]], paper: float,
                   verdicts: Sequence[Mapping[str, Any]] = ()) -> str:
    """``report.md`` of the paper's case: law x coupling tables, the cases, the sign ``envelope``."""
    envelope_rows = [{"parameters": e["parameters"], "coupling": e["coupling"],
                      "combinations ok": f"{e['ok']}/{e['combinations']}",
                      "change min": e["change_min"], "change max": e["change_max"]} for e in envelope]
    return ("# The paper's tolerance case (sections 4.2, 5)\n\n"
            "Rig scene (15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m) without and with "
            "a1 = a2 = a3 = 0.5 mm and alpha1..3 errors of 6e-3 deg (all positive; the paper gives "
            f"magnitudes). The paper: efficiency change about {number(paper, '.2%')}. Relative change "
            "of the mean efficiency, fed back (`converged`) or not (`uncoupled`), under the paper's "
            "friction law (eqs. (3), (5) as written) and the resultant-slip law (`friction.law`; a "
            f"match: within a factor {MATCH_FACTOR:g} of the paper's):\n\n"
            + "".join(law_table(v, paper) for v in verdicts)
            + markdown_table(_case_rows(rows), PAPER_COLUMNS, PAPER_FORMATS, PAPER_HEADERS)
            + "\nRange of the change over the 64 sign combinations of the six errors (reference "
              "engine, the paper's friction law):\n\n"
            + markdown_table(envelope_rows, ENVELOPE_COLUMNS, {"change min": "+.2e", "change max": "+.2e"})
            + "\nPlot: `paper_case_breakdown.png` (change of each pair's loss, share of the input "
              "work).\n")
