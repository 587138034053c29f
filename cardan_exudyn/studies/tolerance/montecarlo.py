"""Monte Carlo tolerance study: mounting errors drawn from stated distributions, N samples from a
seed, run as a sweep. Per error: Spearman's rho with the error and with its magnitude (an effect
of size but not sign shows only there) and the correlation ratio (share of variance explained by
the error alone).
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
    """The paper's tolerances (magnitudes) as symmetric uniforms: ``a1..a3`` in [-0.5, 0.5] mm,
    ``alpha1..alpha3`` in [-6e-3, 6e-3] deg.
    """
    a = value("case.rig.offset_error") * 1e3
    alpha = value("case.rig.twist_error")
    out = {f"joint.errors.a{k}_mm": {"dist": "uniform", "low": -a, "high": a} for k in (1, 2, 3)}
    out.update({f"joint.errors.alpha{k}_deg": {"dist": "uniform", "low": -alpha, "high": alpha}
                for k in (1, 2, 3)})
    return out


def correlation_ratio(x: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Share [-] of ``var(y)`` explained by ``E[y | x]``, ``x`` cut into ``bins`` quantile bins: 0 when
    ``y`` does not depend on ``x`` alone (noise about ``bins / n``), 1 when a function of it; NaN
    with fewer than ``2 bins`` samples or a constant ``y``.
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
    """Per drawn parameter (columns of ``table``): ``spearman``, ``spearman_magnitude`` and
    ``correlation_ratio`` [-] of column ``output``, as a DataFrame.
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
    """``mean_efficiency``: mean, std, min, max and percentiles of ``eta`` [-]; ``change``: percentiles
    of ``eta - eta0`` [-] (empty without samples or ``eta0``).
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
    """A Monte Carlo study's outcome: ``table`` (the sweep's ``results.csv``), ``sensitivity``
    (:func:`sensitivities` of the ok samples, empty with fewer than three) and ``summary`` (counts,
    ideal efficiency, :func:`efficiency_statistics`, sensitivities, wall times).
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
    """Monte Carlo tolerance study of ``scene`` with ``engine``: the samples as a sweep in ``out/cases``
    (resumable), the ideal joint, the statistics.

    ``samples``, ``seed``: N and the draws' seed; ``distributions``: scene path -> distribution table
    (default :func:`default_distributions`), replacing the scene's own errors; ``method`` (``lhs``,
    ``random``), ``workers``, ``scheduler``, ``restart``, ``progress``: to
    :func:`cardan_exudyn.sweep.run_sweep`.
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
