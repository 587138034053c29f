"""Monte Carlo tolerance study: each mounting error drawn from a stated distribution
(:class:`cardan_exudyn.sweep.Distribution`), N samples reproducible from a seed, run through the
sweep runner (resumable, local cores or a Dask cluster).

Output: the distribution of the mean efficiency and its percentiles, and per error three
sensitivity measures: Spearman's rank correlation with the error and with its magnitude (an
effect that depends on the size but not the sign of an offset shows only in the second), and the
correlation ratio (share of the efficiency's variance explained by the error alone, from
quantile-binned conditional means; it sees any monotone or even dependence).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.engines import run
from cardan_exudyn.sweep import run_sweep
from reference.paper import value
from reference.results.summary import Status
from reference.scene import replace
from reference.scene.joint import ERROR_NAMES
from reference.scene.scene import Scene

__all__ = ["LEVELS", "default_distributions", "correlation_ratio", "sensitivities",
           "efficiency_statistics", "MonteCarlo", "run_monte_carlo"]


def _value(x: float | None) -> float:
    return float("nan") if x is None else float(x)


LEVELS = (1, 5, 25, 50, 75, 95, 99)
"""Percentiles reported [%]."""


def default_distributions() -> dict[str, dict[str, Any]]:
    """The paper's tolerances as symmetric uniform distributions (the paper states magnitudes).

    ``a1..a3`` uniform in [-0.5, 0.5] mm, ``alpha1..alpha3`` uniform in [-6e-3, 6e-3] deg.
    """
    a = value("case.rig.offset_error") * 1e3
    alpha = value("case.rig.twist_error")
    out = {f"joint.errors.a{k}_mm": {"dist": "uniform", "low": -a, "high": a} for k in (1, 2, 3)}
    out.update({f"joint.errors.alpha{k}_deg": {"dist": "uniform", "low": -alpha, "high": alpha}
                for k in (1, 2, 3)})
    return out


def correlation_ratio(x: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Share of ``var(y)`` explained by ``E[y | x]``, with ``x`` cut into quantile bins [-].

    A first-order sensitivity index: 0 when ``y`` does not depend on ``x`` alone (up to the
    sampling noise of about ``bins / n``), 1 when it is a function of ``x``.

    Parameters
    ----------
    x, y : ndarray, shape (n,)
        The input and the output samples.
    bins : int
        Quantile bins of ``x``; NaN with fewer than ``2 bins`` samples or a constant ``y``.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if y.size < 2 * bins or np.var(y) == 0.0:
        return float("nan")
    edges = np.quantile(x, np.linspace(0.0, 1.0, bins + 1))
    which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, bins - 1)
    means = np.array([y[which == b].mean() if np.any(which == b) else y.mean() for b in range(bins)])
    counts = np.bincount(which, minlength=bins)
    return float(np.sum(counts * (means - y.mean()) ** 2) / (y.size * np.var(y)))


def sensitivities(table, parameters: Sequence[str], output: str = "mean_efficiency"):
    """Per parameter: Spearman rho with the value and with its magnitude, correlation ratio [-].

    Parameters
    ----------
    table : pandas.DataFrame
        The samples that ran ok: one column per parameter and ``output``.
    parameters : sequence of str
        The drawn parameters (scene paths).
    output : str
        The column whose sensitivity is measured.

    Returns
    -------
    pandas.DataFrame
        Columns ``parameter``, ``spearman``, ``spearman_magnitude``, ``correlation_ratio``.
    """
    import pandas as pd  # import cost: pandas and scipy for this study only
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
    """The distribution of the mean efficiency.

    Parameters
    ----------
    eta : ndarray, shape (n,)
        The samples' mean efficiencies [-].
    eta0 : float
        The ideal joint's [-] (NaN: no change reported).

    Returns
    -------
    dict
        ``mean_efficiency``: mean, std, min, max and percentiles of ``eta`` [-]; ``change``: the
        percentiles of ``eta - eta0`` [-] (empty without samples, or without ``eta0``).
    """
    if not eta.size:
        return {"mean_efficiency": {}, "change": {}}
    m = {"mean": float(eta.mean()), "std": float(eta.std(ddof=1)) if eta.size > 1 else 0.0,
         "min": float(eta.min()), "max": float(eta.max()),
         **{f"p{q}": float(np.percentile(eta, q)) for q in LEVELS}}
    change = ({f"p{q}": float(np.percentile(eta - eta0, q)) for q in LEVELS}
              if math.isfinite(eta0) else {})
    return {"mean_efficiency": m, "change": change}


@dataclass
class MonteCarlo:
    """A Monte Carlo study's outcome.

    Attributes
    ----------
    table : pandas.DataFrame
        The sweep's ``results.csv``: one row per sample, its drawn errors, status and numbers.
    sensitivity : pandas.DataFrame
        :func:`sensitivities` of the samples that ran ok (empty with fewer than three).
    summary : dict
        Counts per status, the ideal joint's efficiency, percentiles of the mean efficiency and
        of its change (:func:`efficiency_statistics`), sensitivities, wall times.
    """

    table: Any
    sensitivity: Any
    summary: dict[str, Any]

    @property
    def ok_table(self) -> Any:
        """The rows of :attr:`table` that ran to status ok."""
        return self.table[self.table["status"] == Status.OK]


def run_monte_carlo(scene: Scene, engine: str, samples: int, seed: int,
                    distributions: Mapping[str, Mapping[str, Any]] | None = None, *,
                    out: str | Path, method: str = "lhs", workers: int | None = None,
                    scheduler: Any = None, restart: bool = False,
                    progress: bool | None = None) -> MonteCarlo:
    """Monte Carlo tolerance study of ``scene``: the samples as a sweep in ``out/cases``
    (resumable), the ideal joint, the statistics.

    Parameters
    ----------
    scene : Scene
        The base scene; its own errors are replaced where a distribution is given.
    engine : str
        A key of :data:`cardan_exudyn.engines.ENGINES`.
    samples, seed : int
        N and the seed of the draws (same seed, same samples).
    distributions : dict, optional
        Scene path (e.g. ``joint.errors.a1_mm``) -> distribution table (``dist``, ``low``,
        ``high``, ``mean``, ``std``); default :func:`default_distributions`.
    out : path
        Folder of the sweep, ``cases/``: one record per sample as it finishes.
    method, workers, scheduler, restart, progress
        Passed to :func:`cardan_exudyn.sweep.run_sweep` (``method``: ``lhs`` or ``random``).
    """
    import pandas as pd  # import cost: pandas for this study only

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
    return MonteCarlo(table, sens, summary)
