"""Mounting-error tolerance studies: the paper's tolerance case and Monte Carlo analyses.

The paper's case (sections 4.2 and 5): the rig scene (15 deg, 6 rad/s, f = 0.42, 0.2 N m) with
and without ``a_i = 0.5 mm`` and twist errors of 6e-3 deg (i = 1, 2, 3); the paper reports that
such errors change the efficiency by about 0.15 %. :func:`paper_case` computes the change with
every engine, parameter set, friction law (``friction.law``) and coupling: ``converged`` (friction
fed back into the dynamics) or ``uncoupled`` (eqs. (3), (5) on the frictionless reactions), with
the per-pair breakdown and the sliding work of eq. (5); :func:`law_verdicts` says which matches.

Monte Carlo (:func:`monte_carlo`): each error drawn from a stated distribution
(:class:`cardan_exudyn.sweep.Distribution`), N samples reproducible from a seed, run through the
sweep runner (resumable, local cores or a Dask cluster). Output: the distribution of the mean
efficiency and its percentiles, and per error three sensitivity measures: Spearman's rank
correlation with the error and with its magnitude (an effect that depends on the size but not the
sign of an offset shows only in the second), and the correlation ratio (share of the efficiency's
variance explained by the error alone, from quantile-binned conditional means; it sees any
monotone or even dependence), plus plots.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.arguments import (
    COUNT_LIMITS,
    EXIT_FAILED,
    EXIT_OK,
    BadInput,
    count,
    out_folder,
    path_value,
    refuse_options,
)
from cardan_exudyn.scene_options import SCENE_OPTIONS, add_scene_options, scene_from_args
from cardan_exudyn.engines import ENGINES, run
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.sweep import Distribution, SweepError, run_sweep
from reference.paper import PARAMETER_SETS, paper_errors, rig_scene, value
from reference.results.summary import Status, Summary
from reference.scene import FRICTION_LAWS, Scene, replace
from reference.scene.joint import ERROR_NAMES, PAIR_NAMES

CYLINDRICAL = PAIR_NAMES[1:]
COUPLINGS = ("converged", "uncoupled")
LAWS = FRICTION_LAWS
MATCH_FACTOR = 2.0  # a change matches the paper's "about 0.15 %" within this factor of its magnitude:
# one rounded number for a sign combination the paper does not state (the signs alone move it more)
LEVELS = (1, 5, 25, 50, 75, 95, 99)  # percentiles reported [%]


def default_distributions() -> dict[str, dict[str, Any]]:
    """The paper's tolerances as symmetric uniform distributions (the paper states magnitudes).

    ``a1..a3`` uniform in [-0.5, 0.5] mm, ``alpha1..alpha3`` uniform in [-6e-3, 6e-3] deg.
    """
    a, alpha = value("case.rig.offset_error") * 1e3, value("case.rig.twist_error")
    out = {f"joint.errors.a{k}_mm": {"dist": "uniform", "low": -a, "high": a} for k in (1, 2, 3)}
    out.update({f"joint.errors.alpha{k}_deg": {"dist": "uniform", "low": -alpha, "high": alpha}
                for k in (1, 2, 3)})
    return out


def _value(x: float | None) -> float:
    return float("nan") if x is None else float(x)


def case_numbers(summary: Summary) -> dict[str, float]:
    """Mean efficiency and per-pair loss and sliding-loss shares of the input work [-] (NaN where
    the run has no value)."""
    w_in = _value(summary.input_work)
    out = {"mean_efficiency": _value(summary.mean_efficiency)}
    for pair in PAIR_NAMES:
        out[f"loss_{pair}"] = _value(summary.pair_loss_work.get(pair)) / w_in
        out[f"sliding_{pair}"] = _value(summary.pair_sliding_loss_work.get(pair, 0.0)) / w_in
    return out


def paper_row(parameters: str, coupling: str, engine: str, law: str = "paper") -> dict[str, Any]:
    """The rig case of one parameter set, friction law and coupling run by ``engine`` without and
    with the stated errors: statuses, efficiencies [-], their change and per-pair loss changes [-]."""
    ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling, "friction.law": law})
    with_errors = replace(ideal, **paper_errors())
    r0, r1 = run(ideal, engine).summary, run(with_errors, engine).summary
    row: dict[str, Any] = {"parameters": parameters, "law": law, "coupling": coupling, "engine": engine,
                           "status_ideal": r0.status.value, "status_errors": r1.status.value,
                           "reason": r1.reason if not r1.success else ""}
    a, b = case_numbers(r0), case_numbers(r1)
    row["eta_ideal"], row["eta_errors"] = a["mean_efficiency"], b["mean_efficiency"]
    row["change"] = b["mean_efficiency"] - a["mean_efficiency"]
    row["relative_change"] = row["change"] / a["mean_efficiency"]
    row["sliding_share"] = sum(b[f"sliding_{p}"] for p in CYLINDRICAL)
    for pair in PAIR_NAMES:
        row[f"d_loss_{pair}"] = b[f"loss_{pair}"] - a[f"loss_{pair}"]
    return row


def paper_case(engines: Sequence[str] = ("reference", "exudyn"),
               parameter_sets: Sequence[str] = PARAMETER_SETS,
               couplings: Sequence[str] = COUPLINGS,
               progress: Callable[[dict[str, Any]], None] | None = None,
               laws: Sequence[str] = LAWS):
    """The rig case with and without the stated errors, per engine, parameter set, law and coupling.

    Parameters
    ----------
    engines, parameter_sets, couplings, laws : sequence of str
        Keys of :data:`cardan_exudyn.engines.ENGINES`, parameter sets of
        :func:`reference.paper.scenes.rig_scene`, ``friction.coupling`` and ``friction.law`` values.
    progress : callable, optional
        Called with each row as it is computed.

    Returns
    -------
    pandas.DataFrame
        One row per (parameters, law, coupling, engine): statuses, ``eta_ideal``, ``eta_errors``,
        ``change`` (absolute) and ``relative_change``, ``sliding_share`` (sliding work over input
        work, with errors) and per pair ``d_loss_<pair>``: the change of that pair's loss as a
        share of the input work (they add up to minus the change of efficiency, up to the change
        of the input work itself); all [-].
    """
    import pandas as pd  # import cost: this module registers a CLI command

    rows = []
    for parameters, law, coupling, engine in itertools.product(parameter_sets, laws, couplings, engines):
        rows.append(paper_row(parameters, coupling, engine, law))
        if progress:
            progress(rows[-1])
    return pd.DataFrame(rows)


def law_verdicts(rows, paper: float) -> list[dict[str, Any]]:
    """Per parameter set and engine of :func:`paper_case` rows: the relative change (or status) of each
    (law, coupling), the closest to ``paper`` [-] in magnitude ratio, whether it is within MATCH_FACTOR."""
    out = []
    for (parameters, engine), group in rows.groupby(["parameters", "engine"], sort=False):
        cells = {}
        for r in group.itertuples():  # a failed run: its status
            bad = r.status_errors if r.status_ideal == Status.OK else r.status_ideal
            cells[f"{r.law}/{r.coupling}"] = float(r.relative_change) if bad == Status.OK else str(bad)
        ratio = {k: abs(v) / paper for k, v in cells.items() if isinstance(v, float) and v != 0.0}
        best = min(ratio, key=lambda k: abs(math.log(ratio[k])), default=None)  # None: nothing ran ok
        out.append({"parameters": parameters, "engine": engine, "cells": cells, "closest": best,
                    "matches": None if best is None else 1.0 / MATCH_FACTOR <= ratio[best] <= MATCH_FACTOR})
    return out


def verdict_line(v: Mapping[str, Any], paper: float) -> str:
    """One sentence: which law/coupling of a parameter set and engine matches the paper's change."""
    said = "matches" if v["matches"] else f"is the closest, but outside a factor {MATCH_FACTOR:g} of"
    return (f"{v['parameters']}, {v['engine']}: no combination ran ok" if v["closest"] is None else
            f"{v['parameters']}, {v['engine']}: {v['closest']} ({number(v['cells'][v['closest']], '+.3%')}) "
            f"{said} the paper's {number(paper, '.2%')}")


def sign_envelope(parameters: str = "matched", coupling: str = "converged",
                  engine: str = "reference") -> dict[str, Any]:
    """Range of the efficiency change [-] over the 64 sign combinations of the stated errors.

    The paper gives the tolerances as magnitudes; this is the spread their signs alone make.
    """
    ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling})
    eta0 = _value(run(ideal, engine).mean_efficiency)
    base = paper_errors()
    changes = []
    for signs in itertools.product((1.0, -1.0), repeat=len(base)):
        errors = {k: s * v for (k, v), s in zip(base.items(), signs, strict=True)}
        changes.append(_value(run(replace(ideal, **errors), engine).mean_efficiency) - eta0)
    changes = np.array(changes)
    ok = np.isfinite(changes)
    return {"parameters": parameters, "coupling": coupling, "engine": engine,
            "combinations": len(changes), "ok": int(ok.sum()), "eta_ideal": eta0,
            "change_min": float(changes[ok].min()) if ok.any() else float("nan"),
            "change_max": float(changes[ok].max()) if ok.any() else float("nan")}


def correlation_ratio(x: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Share of ``var(y)`` explained by ``E[y | x]``, with ``x`` cut into quantile bins [-].

    A first-order sensitivity index: 0 when ``y`` does not depend on ``x`` alone (up to the
    sampling noise of about ``bins / n``), 1 when it is a function of ``x``.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    if y.size < 2 * bins or np.var(y) == 0.0:
        return float("nan")
    edges = np.quantile(x, np.linspace(0.0, 1.0, bins + 1))
    which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, bins - 1)
    means = np.array([y[which == b].mean() if np.any(which == b) else y.mean() for b in range(bins)])
    counts = np.bincount(which, minlength=bins)
    return float(np.sum(counts * (means - y.mean()) ** 2) / (y.size * np.var(y)))


def sensitivities(table, parameters: Sequence[str], output: str = "mean_efficiency"):
    """Per parameter: Spearman rho with the value and with its magnitude, correlation ratio [-].

    Returns
    -------
    pandas.DataFrame
        Columns ``parameter``, ``spearman``, ``spearman_magnitude``, ``correlation_ratio``.
    """
    import pandas as pd  # import cost: this module registers a CLI command
    from scipy.stats import spearmanr

    y = table[output].to_numpy(float)
    rows = []
    for p in parameters:
        x = table[p].to_numpy(float)
        rho = spearmanr(x, y).statistic if np.ptp(x) > 0 else float("nan")
        rho_abs = spearmanr(np.abs(x), y).statistic if np.ptp(np.abs(x)) > 0 else float("nan")
        rows.append({"parameter": p, "spearman": float(rho), "spearman_magnitude": float(rho_abs),
                     "correlation_ratio": correlation_ratio(x, y)})
    return pd.DataFrame(rows)


def efficiency_statistics(eta: np.ndarray, eta0: float) -> dict[str, dict[str, float]]:
    """``mean_efficiency``: mean, std, min, max and percentiles of ``eta`` [-]; ``change``: the
    percentiles of ``eta - eta0`` [-] (empty without samples, or without ``eta0``)."""
    if not eta.size:
        return {"mean_efficiency": {}, "change": {}}
    m = {"mean": float(eta.mean()), "std": float(eta.std(ddof=1)) if eta.size > 1 else 0.0,
         "min": float(eta.min()), "max": float(eta.max()),
         **{f"p{q}": float(np.percentile(eta, q)) for q in LEVELS}}
    change = ({f"p{q}": float(np.percentile(eta - eta0, q)) for q in LEVELS}
              if math.isfinite(eta0) else {})
    return {"mean_efficiency": m, "change": change}


def monte_carlo(scene: Scene, engine: str, samples: int, seed: int,
                distributions: Mapping[str, Mapping[str, Any]] | None = None, *,
                out: str | Path, method: str = "lhs", workers: int | None = None,
                scheduler: Any = None, restart: bool = False, progress: bool | None = None) -> dict:
    """Monte Carlo tolerance study of ``scene`` (resumable; results in ``out``).

    Parameters
    ----------
    scene : Scene
        The base scene; its own errors are replaced where a distribution is given.
    engine : str
    samples, seed : int
        N and the seed of the draws (same seed, same samples).
    distributions : dict, optional
        Scene path (e.g. ``joint.errors.a1_mm``) -> distribution table (``dist``, ``low``,
        ``high``, ``mean``, ``std``); default :func:`default_distributions`.
    out : path
        Folder: ``cases/`` (the sweep: one record per sample as it finishes), ``samples.csv``,
        ``tolerance.json``, ``sensitivity.csv``, ``report.md`` and plots.
    method, workers, scheduler, restart, progress
        Passed to :func:`cardan_exudyn.sweep.run_sweep` (``method``: ``lhs`` or ``random``).

    Returns
    -------
    dict
        Counts per status, the ideal joint's efficiency, percentiles of the mean efficiency and of
        its change, sensitivities, wall times.
    """
    import pandas as pd  # import cost: this module registers a CLI command

    distributions = dict(distributions or default_distributions())
    out = Path(out)
    spec = {"scene": scene, "engine": engine, "fixed": {"record.timeseries": False},  # summaries only
            "random": {"samples": samples, "seed": seed, "method": method,
                       "parameters": distributions}}
    sweep = run_sweep(spec, out / "cases", workers=workers, scheduler=scheduler, restart=restart,
                      progress=progress)
    ideal = run(replace(scene, **{f"joint.errors.{n}": 0.0 for n in ERROR_NAMES}), engine).summary
    table = pd.read_csv(out / "cases" / "results.csv")
    ok = table["status"] == Status.OK
    # no column when no case ran to status ok
    eta = table.loc[ok, "mean_efficiency"].to_numpy(float) if "mean_efficiency" in table else np.zeros(0)
    eta0 = _value(ideal.mean_efficiency)
    params = list(distributions)
    sens = sensitivities(table[ok], params) if ok.sum() >= 3 else pd.DataFrame()
    summary = {
        "scene": scene.name, "engine": engine, "samples": int(samples), "seed": int(seed),
        "method": method, "distributions": distributions,
        "status_counts": {str(k): int(v) for k, v in table["status"].value_counts().items()},
        "ideal_status": ideal.status.value, "ideal_reason": ideal.reason,
        "ideal_mean_efficiency": eta0, **efficiency_statistics(eta, eta0),
        "sensitivity": sens.to_dict(orient="records"),
        "sweep_wall_time_s": sweep["wall_time_s"], "run_now": sweep["run_now"],
        "executor": sweep.get("executor"),
        "case_wall_s_median": float(table["case_wall_s"].median()),
    }
    write_monte_carlo(out / "study", table, table[ok], sens, summary)
    return summary


def write_monte_carlo(folder: Path, table, ok_table, sens, summary: Mapping[str, Any]) -> None:
    """The study folder (atomically): ``samples.csv``, ``sensitivity.csv``, ``tolerance.json``,
    the plots and ``report.md``."""
    with atomic_directory(folder) as tmp:
        table.to_csv(tmp / "samples.csv", index=False)
        sens.to_csv(tmp / "sensitivity.csv", index=False)
        (tmp / "tolerance.json").write_text(dumps(summary), encoding="utf-8")
        _plots(tmp, ok_table, list(summary["distributions"]), summary["ideal_mean_efficiency"])
        (tmp / "report.md").write_text(_report(summary, sens), encoding="utf-8")


def _plots(folder: Path, table, params: Sequence[str], eta0: float) -> None:
    """The histogram of the mean efficiency and its scatter against each error."""
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
    # import cost: matplotlib only when a study is written
    from cardan_exudyn.report.plots import plt, save

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


def _report(summary: Mapping[str, Any], sens) -> str:
    """``report.md`` of the Monte Carlo study."""
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
        parts += ["\n", markdown_table(rows, list(rows[0]), {"Spearman rho": "+.3f",
                                                              "rho with magnitude": "+.3f",
                                                              "correlation ratio": ".3f"})]
    parts.append("\nPlots: `efficiency_histogram.png`, `efficiency_vs_errors.png`.\n")
    return "".join(parts)


def percentile_table(m: Mapping[str, float], change: Mapping[str, float]) -> str:
    """Percentiles of the mean efficiency and of its change from the ideal joint, mean and std."""
    rows = [{"statistic": f"p{q}", "mean efficiency": m[f"p{q}"], "change from ideal": change.get(f"p{q}")}
            for q in LEVELS]
    rows.append({"statistic": "mean / std", "change from ideal": "",
                 "mean efficiency": f"{number(m['mean'], '.6f')} / {number(m['std'], '.2e')}"})
    return markdown_table(rows, ["statistic", "mean efficiency", "change from ideal"],
                          {"mean efficiency": ".6f", "change from ideal": "+.3e"})


def paper_report(out: str | Path, engines: Sequence[str] = ("reference", "exudyn"),
                 progress: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """:func:`paper_case` and :func:`sign_envelope` into ``out`` (report.md, CSV, JSON, plot).

    Returns
    -------
    dict
        ``paper_change`` (the paper's relative change [-]), ``cases`` (the rows of
        :func:`paper_case`) and ``sign_envelope`` (one :func:`sign_envelope` per parameter set
        and coupling).
    """
    rows = paper_case(engines, progress=progress)
    envelope = [sign_envelope(p, c) for p in PARAMETER_SETS for c in COUPLINGS]
    paper = value("case.rig.tolerance_effect")
    verdicts = law_verdicts(rows, paper)
    summary = {"paper_change": paper, "cases": rows.to_dict(orient="records"), "sign_envelope": envelope,
               "verdicts": verdicts}
    with atomic_directory(Path(out)) as tmp:
        rows.to_csv(tmp / "paper_case.csv", index=False)
        (tmp / "paper_case.json").write_text(dumps(summary), encoding="utf-8")
        _breakdown_plot(tmp / "paper_case_breakdown.png", rows)
        (tmp / "report.md").write_text(_paper_markdown(rows, envelope, paper, verdicts), encoding="utf-8")
    return summary


def _breakdown_plot(path: Path, rows) -> None:
    """Stacked bars of each pair's loss change per (parameters, coupling, engine) that ran ok."""
    # import cost: matplotlib only when a report is written
    from cardan_exudyn.report.plots import plt, save

    ok = rows[(rows.status_errors == Status.OK) & (rows.status_ideal == Status.OK)]
    if ok.empty:
        return
    fig, ax = plt.subplots(figsize=(max(8, 0.6 * len(ok)), 4))
    labels = [f"{r.parameters}\n{r.law}\n{r.coupling}\n{r.engine}" for r in ok.itertuples()]
    bottom_pos, bottom_neg = np.zeros(len(ok)), np.zeros(len(ok))
    for k, pair in enumerate(PAIR_NAMES):
        v = ok[f"d_loss_{pair}"].to_numpy(float)
        base = np.where(v >= 0, bottom_pos, bottom_neg)
        ax.bar(range(len(ok)), v, bottom=base, color=f"C{k}", label=pair)
        bottom_pos, bottom_neg = bottom_pos + np.maximum(v, 0), bottom_neg + np.minimum(v, 0)
    ax.set_xticks(range(len(ok)), labels, fontsize=7)
    ax.set_yscale("symlog", linthresh=1e-4)
    ax.set_ylabel("change of pair loss / input work [-]")
    ax.set_title("Where the stated errors' efficiency change comes from (rig case)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path, dpi=120)


PAPER_COLUMNS = ["parameters", "law", "coupling", "engine", "eta_ideal", "eta_errors", "change",
                 "relative_change", "sliding_share", *(f"d_loss_{p}" for p in PAIR_NAMES)]
PAPER_HEADERS = ["parameters", "law", "coupling", "engine", "eta ideal", "eta errors", "change", "relative",
                 "sliding work / W_in", *(f"d loss {p}" if k == 0 else p for k, p in enumerate(PAIR_NAMES))]
PAPER_FORMATS = {"eta_ideal": ".6f", "eta_errors": ".6f", "change": "+.2e", "relative_change": "+.3%",
                 "sliding_share": ".2e", **{f"d_loss_{p}": "+.2e" for p in PAIR_NAMES}}
ENVELOPE_COLUMNS = ["parameters", "coupling", "combinations ok", "change min", "change max"]


def _law_tables(verdicts: Sequence[Mapping[str, Any]], paper: float) -> str:
    """Per parameter set and engine: the 2x2 table of relative changes (coupling x law), the verdict."""
    return "".join(f"`{v['parameters']}`, {v['engine']}:\n\n" + markdown_table(
        [{"coupling": c, **{law: v["cells"].get(f"{law}/{c}", "-") for law in LAWS}} for c in COUPLINGS],
        ["coupling", *LAWS], {law: "+.3%" for law in LAWS}) + f"\n{verdict_line(v, paper)}.\n\n"
        for v in verdicts)


def _paper_markdown(rows, envelope: Sequence[Mapping[str, Any]], paper: float,
                    verdicts: Sequence[Mapping[str, Any]] = ()) -> str:
    """``report.md`` of the paper's case: law x coupling tables, the cases, the sign envelope."""
    cases = []
    for r in rows.to_dict(orient="records"):
        if r["status_errors"] != Status.OK or r["status_ideal"] != Status.OK:
            # a failed run has no numbers: its status in place of the efficiency with errors
            r = {**{c: None for c in PAPER_COLUMNS}, **{c: r[c] for c in PAPER_COLUMNS[:5]},
                 "eta_errors": r["status_errors"]}
        cases.append(r)
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
            + _law_tables(verdicts, paper)
            + markdown_table(cases, PAPER_COLUMNS, PAPER_FORMATS, PAPER_HEADERS)
            + "\nRange of the change over the 64 sign combinations of the six errors (reference "
              "engine, the paper's friction law):\n\n"
            + markdown_table(envelope_rows, ENVELOPE_COLUMNS, {"change min": "+.2e", "change max": "+.2e"})
            + "\nPlot: `paper_case_breakdown.png` (change of each pair's loss, share of the input "
              "work).\n")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan tolerance`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("tolerance", help="mounting-error studies: the paper's case, Monte Carlo",
                              description="`paper`: the rig case with and without the paper's tolerances "
                                          "(every parameter set, friction law and coupling). "
                                          "`montecarlo`: errors drawn from distributions (default: the "
                                          "paper's tolerances, uniform with both signs), resumable.")
    p.add_argument("study", choices=("paper", "montecarlo"))
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--engines", help="paper: engines to compare (default reference,exudyn)")
    p.add_argument("--engine", help="montecarlo: engine (default reference)")
    p.add_argument("--samples", type=count("--samples"),
                   help=f"montecarlo: N (default 1000, at most {COUNT_LIMITS['--samples']})")
    p.add_argument("--seed", type=count("--seed", minimum=0), help="montecarlo: seed of the draws (1)")
    p.add_argument("--method", choices=("lhs", "random"),
                   help="montecarlo: Latin hypercube (default) or independent draws")
    p.add_argument("--error", action="append", metavar="PATH=DIST:...",
                   help="montecarlo: e.g. joint.errors.a1_mm=uniform:-0.5:0.5, "
                        "joint.errors.alpha2_deg=normal:0:0.002:-0.006:0.006; repeatable")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=count("--workers"), metavar="N",
                       help="local processes (default: all cores; 1 runs in this process)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="Dask scheduler to run on")
    p.add_argument("--restart", action="store_true", help="montecarlo: discard earlier samples in --out")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    add_scene_options(p)
    p.set_defaults(func=handler)


#: Options of ``cardan tolerance montecarlo`` only (``paper`` runs its fixed cases), and defaults.
MONTE_CARLO_ONLY = {"engine": "reference", "samples": 1000, "seed": 1, "method": "lhs", "error": None,
                    "workers": None, "scheduler": None, "restart": False}
PAPER_ONLY = {"engines": "reference,exudyn"}


def error_distribution(text: str) -> tuple[str, dict[str, Any]]:
    """``PATH=uniform:LOW:HIGH`` or ``PATH=normal:MEAN:STD[:LOW:HIGH]`` of ``--error``: the scene
    path and its distribution table."""
    path, spec = path_value("--error", text, "PATH=uniform:LOW:HIGH or PATH=normal:MEAN:STD[:LOW:HIGH]")
    kind, *numbers = spec.split(":")
    names = {"uniform": ("low", "high"), "normal": ("mean", "std", "low", "high")}.get(kind)
    if names is None or not (2 <= len(numbers) <= len(names)) or (kind == "normal" and len(numbers) == 3):
        raise BadInput(f"--error {text!r}: give uniform:LOW:HIGH or normal:MEAN:STD[:LOW:HIGH]")
    try:
        table = {"dist": kind, **{n: float(v) for n, v in zip(names, numbers, strict=False)}}
        Distribution(**table)
    except (ValueError, SweepError) as exc:
        raise BadInput(f"--error {text!r}: {exc}") from None
    return path, table


def handler(args: argparse.Namespace) -> int:
    """``cardan tolerance``: exit 0 when every run ended ok, 3 otherwise."""
    if args.study == "paper":
        refuse_options(args, [*MONTE_CARLO_ONLY, *SCENE_OPTIONS],
                       "to `cardan tolerance paper` (it runs the paper's rig case; use montecarlo)")
    else:
        refuse_options(args, list(PAPER_ONLY), "to `cardan tolerance montecarlo` (use --engine)")
    for key, default in {**MONTE_CARLO_ONLY, **PAPER_ONLY}.items():
        if getattr(args, key) is None or getattr(args, key) is False:
            setattr(args, key, default)
    if args.study == "montecarlo" and args.name is None and args.scene is None:
        args.name = "rig-matched"
    out_folder(args.out, replace=args.study == "paper")
    if args.study == "paper":
        return paper_handler(args)
    return monte_carlo_handler(args)


def paper_handler(args: argparse.Namespace) -> int:
    """``cardan tolerance paper``: the report folder, a line per case on stderr as it finishes."""
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    unknown = [e for e in engines if e not in ENGINES]
    if not engines or unknown:
        raise BadInput(f"--engines must name engines of {sorted(ENGINES)}, got {args.engines!r}")
    summary = paper_report(args.out, engines, progress=None if args.json else _show_row)
    if args.json:
        print(dumps(summary))
    else:
        for v in summary["verdicts"]:
            print(verdict_line(v, summary["paper_change"]), file=sys.stderr)
        print(f"wrote {args.out}/report.md", file=sys.stderr)
    failed = [c for c in summary["cases"]
              if c["status_ideal"] != Status.OK or c["status_errors"] != Status.OK]
    return EXIT_FAILED if failed else EXIT_OK


def _show_row(row: Mapping[str, Any]) -> None:
    print(f"  {row['parameters']:10s} {row['law']:9s} {row['coupling']:9s} {row['engine']:9s} "
          f"{row['status_errors']:12s} change {number(row['relative_change'], '+.3%')}",
          file=sys.stderr)


def monte_carlo_handler(args: argparse.Namespace) -> int:
    """``cardan tolerance montecarlo``: the study folder, a closing line on stderr."""
    scene = scene_from_args(args)
    distributions = (dict(error_distribution(t) for t in args.error) if args.error
                     else default_distributions())
    try:
        summary = monte_carlo(scene, args.engine, args.samples, args.seed, distributions, out=args.out,
                              method=args.method, workers=args.workers, scheduler=args.scheduler,
                              restart=args.restart, progress=False if args.json else None)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    if args.json:
        print(dumps(summary))
    else:
        print(monte_carlo_line(summary, args.out), file=sys.stderr)
    every_ok = (summary["status_counts"].get(Status.OK.value, 0) == summary["samples"]
                and summary["ideal_status"] == Status.OK)
    return EXIT_OK if every_ok else EXIT_FAILED


def monte_carlo_line(summary: Mapping[str, Any], out: str) -> str:
    """Statuses, the ideal joint's efficiency and the 5/50/95 percentiles, in one line."""
    m = summary["mean_efficiency"]
    ideal = (number(summary["ideal_mean_efficiency"], ".6f") if summary["ideal_status"] == Status.OK
             else f"{summary['ideal_status']}: {summary.get('ideal_reason', '')}")
    return (f"{summary['status_counts']}; ideal {ideal}; "
            f"p5/p50/p95 {number(m.get('p5'), '.6f')} / {number(m.get('p50'), '.6f')} / "
            f"{number(m.get('p95'), '.6f')}; wrote {out}/study/report.md")


__all__ = ["correlation_ratio", "default_distributions", "error_distribution", "law_verdicts", "monte_carlo",
           "paper_case", "paper_report", "register", "handler", "sensitivities", "sign_envelope",
           "verdict_line"]
