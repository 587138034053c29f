"""The error of a finished run's mean values and time-table columns, for the pytest plugin's checks.

Reference engine: its quadrature's estimates (plus the ODE ``rtol`` for a torque drive). Exudyn:
step halving, ``2**p / (2**p - 1)`` times the change at half the step, ``p`` the convergence
order; the mean efficiency at least the run's own estimate, every mean scaled alike. Others
(MuJoCo): None. Measured: docs/pytest.md#what-the-default-tolerance-means.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from dataclasses import replace as replace_fields
from typing import Any

import numpy as np

from cardan_exudyn.engines import make_options, options_class
from cardan_exudyn.engines import run as run_engine
from cardan_exudyn.model.stepsize import convergence_order
from cardan_exudyn.report.format import is_number
from reference.results.means import after_revolutions
from reference.results.result import Result
from reference.results.summary import MEAN_KEYS, Summary
from reference.scene.mapping import replace, scene_from_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

__all__ = ["SAFETY_FACTOR", "STEP_ORDERS", "ESTIMATED_MEANS", "AccuracyError", "ErrorEstimate",
           "error_estimate", "mean_values", "scene_of", "options_of", "quadrature_estimate",
           "step_halving_estimate", "half_step_scene", "row_changes", "ratio_error"]

SAFETY_FACTOR = 5.0
"""What a check multiplies an error estimate by (a margin over the measured ratios of true to
estimated error). Measured: docs/pytest.md#what-the-default-tolerance-means."""
STEP_ORDERS = {"exudyn": 2}
"""Fixed-step engines whose error is estimated by step halving, with their order of convergence."""
ESTIMATED_MEANS = tuple(k for k in MEAN_KEYS if k not in ("revolutions", "window_start_s",
                                                          "window_duration_s"))
"""The summary's mean values an estimate covers (besides the per-pair ``loss_work_<pair>``)."""


class AccuracyError(ValueError):
    """The error of a run cannot be estimated (the run failed, or its half-step rerun did)."""


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated absolute error of a run's mean values and columns.

    Attributes
    ----------
    engine : str
    method : str
        ``"quadrature"`` or ``"step halving"``.
    means : mapping
        Mean-value name (:data:`ESTIMATED_MEANS`, ``loss_work_<pair>``) -> error, in its units.
    columns : mapping
        Time-table column -> largest error over the rows, in its units (empty without a table).
    detail : str
        How the estimate was made, for messages.
    """

    engine: str
    method: str
    means: Mapping[str, float] = field(default_factory=dict)
    columns: Mapping[str, float] = field(default_factory=dict)
    detail: str = ""

    def of(self, name: str) -> float | None:
        """The estimated error of mean value or column ``name``, None when there is none."""
        return self.means.get(name, self.columns.get(name))


def mean_values(summary: Summary) -> dict[str, float]:
    """The summary's finite mean values by name: :data:`ESTIMATED_MEANS` and ``loss_work_<pair>*``."""
    return {key: float(value) for key, value in summary.to_dict().items()
            if (key in ESTIMATED_MEANS or key.startswith("loss_work_")) and is_number(value)}


def scene_of(result: Result) -> Scene:
    """The scene a result was computed for, rebuilt from its summary."""
    return scene_from_dict(result.summary.scene)


def options_of(result: Result) -> Any:
    """The engine options a result was computed with, rebuilt from its summary."""
    engine = result.summary.engine
    known = options_class(engine).__dataclass_fields__
    return make_options(engine, **{k: v for k, v in result.summary.options.items() if k in known})


def error_estimate(result: Result, run: Callable[..., Result] | None = None,
                   skip_revolutions: float = 0.0) -> ErrorEstimate | None:
    """Estimate the error of a successful run's mean values and columns.

    Parameters
    ----------
    result : Result
        A run that ended ``ok``.
    run : callable, optional
        ``run(scene, engine, options) -> Result`` for a half-step rerun (default
        :func:`cardan_exudyn.engines.run`; a caching runner makes repeated estimates free).
    skip_revolutions : float
        Input revolutions [-] at the start left out of the columns' estimates.

    Returns
    -------
    ErrorEstimate or None
        None for an engine that offers no estimate.

    Raises
    ------
    AccuracyError
        The run did not end ``ok``, or the half-step rerun failed.
    """
    summary = result.summary
    if not result.success:
        raise AccuracyError(f"the run ended {summary.status}: {summary.reason}")
    if "quadrature" in summary.extras:
        return quadrature_estimate(result)
    if summary.engine not in STEP_ORDERS:
        return None
    scene = scene_of(result)
    order = STEP_ORDERS[summary.engine]
    if summary.dt:  # 1 with the lagged coupling or while friction sign ramps are unresolved
        order = min(order, convergence_order(scene))
    estimate = step_halving_estimate(result, scene, options_of(result), order, run or run_engine,
                                     skip_revolutions)
    own = summary.efficiency_error_estimate
    halving = estimate.means.get("mean_efficiency", 0.0)
    if is_number(own) and own > halving:  # the run's own estimate is larger: step halving under-reads
        # every mean is integrated over the same unresolved sign ramps: scale them alike
        factor = own / halving if halving > 0 else 1.0
        means = {k: v * factor for k, v in estimate.means.items()}
        means["mean_efficiency"] = float(own)
        detail = (estimate.detail + f"; means scaled by {factor:.3g} to the run's own mean-efficiency "
                  f"estimate ({own:.3g})")
        estimate = ErrorEstimate(estimate.engine, estimate.method, means, estimate.columns, detail)
    return estimate


def ratio_error(numerator: float, denominator: float, numerator_error: float,
                denominator_error: float) -> float:
    """First-order absolute error [-] of ``numerator / denominator`` (and of one minus it) from their
    absolute errors."""
    d = abs(denominator)
    return numerator_error / d + abs(numerator) * denominator_error / d ** 2


def quadrature_estimate(result: Result) -> ErrorEstimate:
    """The reference engine's estimate: its quadrature's, the ODE's tolerance for a torque drive."""
    s = result.summary
    q = s.extras["quadrature"]
    w_in = s.input_work
    w_out = s.output_work
    w_loss = s.loss_work
    # a constant-speed run integrates one revolution and repeats it: so do its errors
    repeats = s.revolutions / q["revolutions_integrated"] if q.get("revolutions_integrated") else 1
    e_in = repeats * float(q["input_work_error_estimate"])
    e_loss = repeats * float(q["loss_work_error_estimate"])
    bound = float(q["rtol"]) * abs(w_in)  # per-panel acceptance: rtol times the input work
    means = {key: bound for key in mean_values(s) if key.startswith("loss_work_")}
    means.update({"input_work": e_in, "loss_work": e_loss, "output_work": bound})
    if w_in:  # no ratio to a zero input work
        means.update({"mean_efficiency": ratio_error(w_loss, w_in, e_loss, e_in),
                      "work_ratio": ratio_error(w_out, w_in, bound, e_in),
                      "mean_torque_in": abs(s.mean_torque_in) * e_in / abs(w_in)})
    ode_rtol = float(s.options.get("ode_rtol", 0.0)) if s.ode_evaluations is not None else 0.0
    values = mean_values(s)
    means = {k: e + ode_rtol * abs(values.get(k, 0.0)) for k, e in means.items()}
    columns = {}
    if result.has_table:
        columns = {c: ode_rtol * float(np.nanmax(np.abs(result.table[c].to_numpy(float)), initial=0.0))
                   for c in result.table.columns if c != "t"}
    detail = (f"quadrature rtol {q['rtol']:g}"
              + (f", ODE rtol {ode_rtol:g}" if ode_rtol else ", table rows exact"))
    return ErrorEstimate(s.engine, "quadrature", means, columns, detail)


def half_step_scene(scene: Scene, dt: float, table: bool) -> Scene:
    """``scene`` at half the step ``dt`` [s], its table (when ``table``) recorded at the rows of ``dt``."""
    every = 2 * scene.record.every if table else 1
    return replace(scene, **{"numerics.dt": 0.5 * dt, "record.every": every,
                             "record.timeseries": table})


def step_halving_estimate(result: Result, scene: Scene, options: Any, order: int,
                          run: Callable[..., Result], skip_revolutions: float = 0.0) -> ErrorEstimate:
    """Estimate by a rerun at half the step through ``run``: ``2**order / (2**order - 1)`` times the
    changes (columns after ``skip_revolutions``); :class:`AccuracyError` without a step or when the
    rerun is refused or fails."""
    s = result.summary
    if not is_number(s.dt) or s.dt <= 0:
        raise AccuracyError(f"the {s.engine} run reports no time step to halve")
    if "error_estimate" in getattr(options, "__dataclass_fields__", {}):
        options = replace_fields(options, error_estimate=False)  # no companion: it would be
        # the run being halved
    try:
        finer = run(half_step_scene(scene, s.dt, result.has_table), s.engine, options)
    except SceneError as exc:
        raise AccuracyError(f"cannot rerun at half the step: {exc}") from None
    if not finer.success:
        raise AccuracyError(f"the rerun at half the step (dt = {0.5 * s.dt:.4g} s) ended "
                            f"{finer.status}: {finer.message}")
    factor = 2.0 ** order / (2.0 ** order - 1.0)
    coarse = mean_values(s)
    fine = mean_values(finer.summary)
    means = {k: factor * abs(v - fine[k]) for k, v in coarse.items() if k in fine}
    columns = {}
    if result.has_table and finer.has_table:
        changes = row_changes(result.table, finer.table, s.dt, skip_revolutions)
        columns = {c: factor * d for c, d in changes.items()}
    detail = f"step halving: dt = {s.dt:.4g} s and {0.5 * s.dt:.4g} s, order {order}"
    return ErrorEstimate(s.engine, "step halving", means, columns, detail)


def row_changes(coarse: Any, fine: Any, dt: float, skip_revolutions: float = 0.0) -> dict[str, float]:
    """Per column (``t`` aside) the largest absolute change between two tables with the same rows (times
    agreeing to 1e-6 ``dt`` [s], else empty), after ``skip_revolutions``."""
    n = min(len(coarse), len(fine))
    t_coarse = coarse["t"].to_numpy(float)[:n]
    t_fine = fine["t"].to_numpy(float)[:n]
    if n == 0 or np.max(np.abs(t_coarse - t_fine)) > 1e-6 * dt:
        return {}
    keep = after_revolutions(coarse["theta_in"].to_numpy(float)[:n], skip_revolutions)
    out = {}
    for c in coarse.columns:
        if c == "t" or c not in fine:
            continue
        d = (coarse[c].to_numpy(float)[:n] - fine[c].to_numpy(float)[:n])[keep]
        d = d[np.isfinite(d)]
        if d.size:
            out[c] = float(np.max(np.abs(d)))
    return out
