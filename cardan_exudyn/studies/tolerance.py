"""Mounting-error tolerance studies: the paper's tolerance case and Monte Carlo analyses.

The paper's case (sections 4.2 and 5): the rig scene (15 deg, 6 rad/s, f = 0.42, 0.2 N m) with
and without ``a_i = 0.5 mm`` and twist errors of 6e-3 deg (i = 1, 2, 3); the paper reports that
such errors change the efficiency by about 0.15 %. :func:`paper_case` computes the change with
every engine asked for, under both parameter sets (plain, calibrated) and two friction
couplings: ``converged`` (friction applied to the dynamics, the model of this project) and
``uncoupled`` (eqs. (3), (5) evaluated on the frictionless reactions, a first-order estimate),
with the per-pair breakdown of where the change comes from and the sliding work of eq. (5).

Monte Carlo (:func:`monte_carlo`): each error drawn from a stated distribution
(:class:`cardan_exudyn.sweep.runner.Distribution`), N samples reproducible from a seed, run through the
sweep runner (resumable, local cores or a Dask cluster). Output: the distribution of the mean
efficiency and its percentiles, and per error three sensitivity measures: Spearman's rank
correlation with the error and with its magnitude (an effect that depends on the size but not the
sign of an offset shows only in the second), and the correlation ratio (share of the efficiency's
variance explained by the error alone, from quantile-binned conditional means; it sees any
monotone or even dependence), plus plots.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.engines import run_scene
from reference.paper import paper_errors, rig_scene, value
from reference.scene import ERROR_NAMES, PAIR_NAMES, Scene, replace

CYLINDRICAL = PAIR_NAMES[1:]
PARAMETER_SETS = ("plain", "calibrated")
COUPLINGS = ("converged", "uncoupled")


def default_distributions() -> dict[str, dict[str, Any]]:
    """The paper's tolerances as symmetric uniform distributions (the paper states magnitudes).

    ``a1..a3`` uniform in [-0.5, 0.5] mm, ``alpha1..alpha3`` uniform in [-6e-3, 6e-3] deg.
    """
    a, alpha = value("case.rig.offset_error") * 1e3, value("case.rig.twist_error")
    out = {f"joint.errors.a{k}_mm": {"dist": "uniform", "low": -a, "high": a} for k in (1, 2, 3)}
    out.update({f"joint.errors.alpha{k}_deg": {"dist": "uniform", "low": -alpha, "high": alpha}
                for k in (1, 2, 3)})
    return out


def _case_numbers(summary: Mapping[str, Any]) -> dict[str, float]:
    """Mean efficiency and per-pair loss shares (of the input work) from a summary."""
    w_in = summary.get("input_work", float("nan"))
    out = {"mean_efficiency": summary.get("mean_efficiency", float("nan"))}
    for pair in PAIR_NAMES:
        out[f"loss_{pair}"] = summary.get(f"loss_work_{pair}", float("nan")) / w_in
        out[f"sliding_{pair}"] = summary.get(f"loss_work_{pair}_sliding", 0.0) / w_in
    return out


def paper_case(engines: Sequence[str] = ("reference", "exudyn"),
               parameter_sets: Sequence[str] = PARAMETER_SETS,
               couplings: Sequence[str] = COUPLINGS, progress=None):
    """The rig case with and without the stated errors, per engine, parameter set and coupling.

    Returns
    -------
    pandas.DataFrame
        One row per (parameters, coupling, engine): statuses, ``eta_ideal``, ``eta_errors``,
        ``change`` (absolute) and ``relative_change``, ``sliding_share`` (sliding work over input
        work, with errors) and per pair ``d_loss_<pair>``: the change of that pair's loss as a
        share of the input work (they add up to minus the change of efficiency, up to the change
        of the input work itself).
    """
    import pandas as pd

    rows = []
    for parameters, coupling, engine in itertools.product(parameter_sets, couplings, engines):
        ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling})
        with_errors = replace(ideal, **paper_errors())
        r0, r1 = run_scene(ideal, engine).summary, run_scene(with_errors, engine).summary
        row: dict[str, Any] = {"parameters": parameters, "coupling": coupling, "engine": engine,
                               "status_ideal": r0["status"], "status_errors": r1["status"],
                               "reason": r1.get("reason", "") if r1["status"] != "ok" else ""}
        a, b = _case_numbers(r0), _case_numbers(r1)
        row["eta_ideal"], row["eta_errors"] = a["mean_efficiency"], b["mean_efficiency"]
        row["change"] = b["mean_efficiency"] - a["mean_efficiency"]
        row["relative_change"] = row["change"] / a["mean_efficiency"]
        row["sliding_share"] = sum(b[f"sliding_{p}"] for p in CYLINDRICAL)
        for pair in PAIR_NAMES:
            row[f"d_loss_{pair}"] = b[f"loss_{pair}"] - a[f"loss_{pair}"]
        rows.append(row)
        if progress:
            progress(row)
    return pd.DataFrame(rows)


def sign_envelope(parameters: str = "calibrated", coupling: str = "converged",
                  engine: str = "reference") -> dict[str, Any]:
    """Range of the efficiency change over the 64 sign combinations of the stated errors.

    The paper gives the tolerances as magnitudes; this is the spread their signs alone make.
    """
    ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling})
    eta0 = run_scene(ideal, engine).summary["mean_efficiency"]
    base = paper_errors()
    changes, statuses = [], []
    for signs in itertools.product((1.0, -1.0), repeat=len(base)):
        errors = {k: s * v for (k, v), s in zip(base.items(), signs, strict=True)}
        summary = run_scene(replace(ideal, **errors), engine).summary
        statuses.append(summary["status"])
        changes.append(summary.get("mean_efficiency", float("nan")) - eta0)
    changes = np.array(changes)
    ok = np.isfinite(changes)
    return {"parameters": parameters, "coupling": coupling, "engine": engine, "combinations": len(changes),
            "ok": int(ok.sum()), "eta_ideal": eta0,
            "change_min": float(changes[ok].min()) if ok.any() else float("nan"),
            "change_max": float(changes[ok].max()) if ok.any() else float("nan")}


# ----------------------------------------------------------------------------- Monte Carlo


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
    """Per parameter: Spearman rho with the value and with its magnitude, correlation ratio."""
    import pandas as pd
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
        Passed to :func:`cardan_exudyn.sweep.runner.run_sweep` (``method``: ``lhs`` or ``random``).

    Returns
    -------
    dict
        Counts per status, the ideal joint's efficiency, percentiles of the mean efficiency and of
        its change, sensitivities, wall times.
    """
    import pandas as pd

    from cardan_exudyn.io import atomic_directory, dumps
    from cardan_exudyn.sweep.runner import run_sweep

    distributions = dict(distributions or default_distributions())
    out = Path(out)
    ideal_scene = replace(scene, **{f"joint.errors.{n}": 0.0 for n in ERROR_NAMES})
    spec = {"scene": scene, "engine": engine,
            "random": {"samples": samples, "seed": seed, "method": method,
                       "parameters": distributions}}
    sweep = run_sweep(spec, out / "cases", workers=workers, scheduler=scheduler, restart=restart,
                      progress=progress)
    ideal = run_scene(ideal_scene, engine).summary
    table = pd.read_csv(out / "cases" / "results.csv")
    ok = table["status"] == "ok"
    # no column when no case ran to status ok
    eta = table.loc[ok, "mean_efficiency"].to_numpy(float) if "mean_efficiency" in table else np.zeros(0)
    eta0 = ideal.get("mean_efficiency", float("nan"))
    levels = (1, 5, 25, 50, 75, 95, 99)
    params = list(distributions)
    sens = sensitivities(table[ok], params) if ok.sum() >= 3 else pd.DataFrame()
    summary = {
        "scene": scene.name, "engine": engine, "samples": int(samples), "seed": int(seed),
        "method": method, "distributions": distributions,
        "status_counts": {str(k): int(v) for k, v in table["status"].value_counts().items()},
        "ideal_status": ideal["status"], "ideal_reason": ideal.get("reason", ""),
        "ideal_mean_efficiency": eta0,
        "mean_efficiency": {"mean": float(eta.mean()), "std": float(eta.std(ddof=1)) if eta.size > 1 else 0.0,
                            "min": float(eta.min()), "max": float(eta.max()),
                            **{f"p{q}": float(np.percentile(eta, q)) for q in levels}} if eta.size else {},
        "change": ({f"p{q}": float(np.percentile(eta - eta0, q)) for q in levels}
                   if eta.size and math.isfinite(eta0) else {}),
        "sensitivity": sens.to_dict(orient="records"),
        "sweep_wall_time_s": sweep["wall_time_s"], "run_now": sweep["run_now"],
        "executor": sweep.get("executor"),
        "case_wall_s_median": float(table["case_wall_s"].median()),
    }
    with atomic_directory(out / "study") as tmp:
        table.to_csv(tmp / "samples.csv", index=False)
        sens.to_csv(tmp / "sensitivity.csv", index=False)
        (tmp / "tolerance.json").write_text(dumps(summary), encoding="utf-8")
        _plots(tmp, table[ok], params, eta0)
        (tmp / "report.md").write_text(_report(summary, sens), encoding="utf-8")
    return summary


def _plots(folder: Path, table, params: Sequence[str], eta0: float) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if "mean_efficiency" not in table or table.empty:
        return
    eta = table["mean_efficiency"].to_numpy(float)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.hist(eta, bins=max(10, int(math.sqrt(eta.size))), color="0.6")
    ax.axvline(eta0, color="k", ls="--", label=f"ideal joint {eta0:.5f}")
    for q, style in ((5, ":"), (50, "-"), (95, ":")):
        ax.axvline(np.percentile(eta, q), color="C0", ls=style, label=f"p{q}")
    ax.set(xlabel="mean efficiency [-]", ylabel="samples", title="Monte Carlo: mean efficiency")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(folder / "efficiency_histogram.png", dpi=120)
    plt.close(fig)
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
    fig.savefig(folder / "efficiency_vs_errors.png", dpi=120)
    plt.close(fig)


def _report(summary: Mapping[str, Any], sens) -> str:
    m, c = summary["mean_efficiency"], summary["change"]
    lines = [f"# Monte Carlo tolerance study: {summary['scene']} ({summary['engine']})", "",
             f"{summary['samples']} samples ({summary['method']}, seed {summary['seed']}); "
             f"statuses {summary['status_counts']}; ideal joint "
             + (f"{summary['ideal_mean_efficiency']:.6f}." if summary["ideal_status"] == "ok"
                else f"{summary['ideal_status']}: {summary.get('ideal_reason', '')}."),
             "", "| parameter | distribution |", "|---|---|"]
    lines += [f"| `{p}` | {d} |" for p, d in summary["distributions"].items()]
    if m:
        lines += ["", "| statistic | mean efficiency | change from ideal |", "|---|---|---|"]
        lines += [f"| p{q} | {m[f'p{q}']:.6f} | "
                  + (f"{c[f'p{q}']:+.3e} |" if c else "- |") for q in (1, 5, 25, 50, 75, 95, 99)]
        lines += [f"| mean / std | {m['mean']:.6f} / {m['std']:.2e} | |"]
    if len(sens):
        lines += ["", "| parameter | Spearman rho | rho with magnitude | correlation ratio |",
                  "|---|---|---|---|"]
        lines += [f"| `{r.parameter}` | {r.spearman:+.3f} | {r.spearman_magnitude:+.3f} | "
                  f"{r.correlation_ratio:.3f} |" for r in sens.itertuples()]
    lines += ["", "Plots: `efficiency_histogram.png`, `efficiency_vs_errors.png`.", ""]
    return "\n".join(lines)


def paper_report(out: str | Path, engines: Sequence[str] = ("reference", "exudyn"),
                 progress=None) -> dict[str, Any]:
    """:func:`paper_case` and :func:`sign_envelope` into ``out`` (report.md, CSV, JSON, plot)."""
    from cardan_exudyn.io import atomic_directory, dumps

    rows = paper_case(engines, progress=progress)
    envelope = [sign_envelope(p, c) for p in PARAMETER_SETS for c in COUPLINGS]
    paper = value("case.rig.tolerance_effect")
    summary = {"paper_change": paper, "cases": rows.to_dict(orient="records"), "sign_envelope": envelope}
    with atomic_directory(Path(out)) as tmp:
        rows.to_csv(tmp / "paper_case.csv", index=False)
        (tmp / "paper_case.json").write_text(dumps(summary), encoding="utf-8")
        _breakdown_plot(tmp / "paper_case_breakdown.png", rows)
        (tmp / "report.md").write_text(_paper_markdown(rows, envelope, paper), encoding="utf-8")
    return summary


def _breakdown_plot(path: Path, rows) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = rows[(rows.status_errors == "ok") & (rows.status_ideal == "ok")]
    if ok.empty:
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    labels = [f"{r.parameters}\n{r.coupling}\n{r.engine}" for r in ok.itertuples()]
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
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _paper_markdown(rows, envelope, paper: float) -> str:
    lines = ["# The paper's tolerance case (sections 4.2, 5)", "",
             "Rig scene (15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m) without and with "
             "a1 = a2 = a3 = 0.5 mm and alpha1..3 errors of 6e-3 deg (all positive; the paper gives "
             f"magnitudes). The paper: efficiency change about {paper:.2%}.", "",
             "| parameters | coupling | engine | eta ideal | eta with errors | change | relative | "
             "sliding work / W_in | d loss frame_input | input_spider | spider_output | output_frame |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows.itertuples():
        if r.status_errors != "ok" or r.status_ideal != "ok":
            lines.append(f"| {r.parameters} | {r.coupling} | {r.engine} | {r.eta_ideal:.6f} | "
                         f"{r.status_errors} | | | | | | | |")
            continue
        lines.append(f"| {r.parameters} | {r.coupling} | {r.engine} | {r.eta_ideal:.6f} | "
                     f"{r.eta_errors:.6f} | {r.change:+.2e} | {r.relative_change:+.3%} | "
                     f"{r.sliding_share:.2e} | {r.d_loss_frame_input:+.2e} | {r.d_loss_input_spider:+.2e} | "
                     f"{r.d_loss_spider_output:+.2e} | {r.d_loss_output_frame:+.2e} |")
    lines += ["", "Range of the change over the 64 sign combinations of the six errors (reference engine):",
              "", "| parameters | coupling | combinations ok | change min | change max |",
              "|---|---|---|---|---|"]
    lines += [f"| {e['parameters']} | {e['coupling']} | {e['ok']}/{e['combinations']} | "
              f"{e['change_min']:+.2e} | {e['change_max']:+.2e} |" for e in envelope]
    lines += ["", "Plot: `paper_case_breakdown.png` (change of each pair's loss, share of the input "
              "work).", ""]
    return "\n".join(lines)


__all__ = ["correlation_ratio", "default_distributions", "monte_carlo", "paper_case", "paper_report",
           "sensitivities", "sign_envelope"]
