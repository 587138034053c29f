"""One campaign from its file to its result (:func:`campaign`): measure every recording once, calibrate
on the calibration recordings, then every recording's comparison with its V&V 20 budget.

Every model run is journalled in the output folder as it finishes; the same call on the same folder
resumes without running any model again.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from cardan_exudyn.sweep.executors import default_workers
from rigdata.campaign.budget import Budget, BudgetRuns, budget, budget_runs, model_scatter
from rigdata.campaign.calibration import Calibration, CalibrationFailed, calibrate, jacobian_runs
from rigdata.campaign.evaluate import Evaluator, ModelRun, Outcome, model_pool
from rigdata.campaign.journal import Journal
from rigdata.campaign.prepare import Prepared, operating_point, prepare
from rigdata.campaign.result import CampaignResult, EngineComparison, RecordingResult
from rigdata.campaign.spec import CampaignSpec, load_campaign
from rigdata.reproduce import run_environment
from rigdata.validation import check_engines

__all__ = ["campaign", "coverage_factor"]

Progress = Callable[[str], None]


def coverage_factor(coverage: float) -> float:
    """``k`` of a normal distribution for a two-sided ``coverage`` probability (0.95: 1.96)."""
    return float(stats.norm.ppf(0.5 + coverage / 2.0))


@dataclass
class _Clock:
    """Wall time per stage [s]."""

    stages: dict[str, float]

    @contextlib.contextmanager
    def stage(self, name: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - start


def campaign(source: CampaignSpec | str | os.PathLike, out: str | os.PathLike | None = None, *,
             workers: int | None = None, scheduler: Any = None,
             progress: Progress | None = None) -> CampaignResult:
    """Run a validation campaign.

    Parameters
    ----------
    source : CampaignSpec, str or path-like
        The campaign, or its TOML file (:func:`rigdata.campaign.spec.load_campaign`).
    out : str or path-like, optional
        Folder of the journal (``runs.jsonl``): a second call with it reruns no model. Nothing else is
        written (see :func:`rigdata.campaign.report.write_report`).
    workers : int, optional
        Processes for the model runs (default: the cores available; 1: this process).
    scheduler : str or distributed.Client, optional
        A Dask scheduler's address (``tcp://host:port``) or client: the measurements and model runs go
        to its cluster instead (``workers`` is then ignored).
    progress : callable(str), optional
        Called with a line at each stage and model run.

    Returns
    -------
    CampaignResult

    Raises
    ------
    CampaignError
        A campaign file that cannot run.
    RigDataError
        A recording that cannot be read or measured, naming it.
    EngineUnavailable
        An engine of the campaign that is not installed.
    """
    say = progress or (lambda line: None)
    spec = source if isinstance(source, CampaignSpec) else load_campaign(source)
    check_engines(spec.engines)
    clock = _Clock({})
    workers = default_workers() if workers is None else max(1, int(workers))
    with model_pool(workers, scheduler) as pool:
        with clock.stage("measure"):
            prepared = _prepare_all(spec, pool, say)
        journal = _journal(out)  # only once every recording is measured: bad data leave nothing
        try:
            evaluate = Evaluator(prepared, spec.parameters, journal, pool,
                                 on_run=lambda n: say(f"model runs: {n}"))
            return _run(spec, prepared, evaluate, clock, say)
        finally:
            if journal is not None:
                journal.close()


def _journal(out: str | os.PathLike | None) -> Journal | None:
    """The journal in folder ``out`` (made if missing), None without one."""
    if out is None:
        return None
    Path(out).mkdir(parents=True, exist_ok=True)
    return Journal(out)


def _prepare_all(spec: CampaignSpec, pool, say: Progress) -> dict[int, Prepared]:
    """Every recording measured (in ``pool`` if any), by index; the first that cannot be raises."""
    total = len(spec.recordings)
    if pool is None:
        out = {}
        for rec in spec.recordings:
            say(f"measuring {rec.index}/{total}: {rec.label}")
            out[rec.index] = prepare(rec, spec)
        return out
    futures = {rec.index: pool.submit(prepare, rec, spec) for rec in spec.recordings}
    out = {}
    for index, future in futures.items():
        out[index] = future.result()
        say(f"measured {len(out)}/{total}: {out[index].spec.label}")
    return out


def _run(spec: CampaignSpec, prepared: dict[int, Prepared], evaluate: Evaluator, clock: _Clock,
         say: Progress) -> CampaignResult:
    """Calibration, then every recording's comparison."""
    k = coverage_factor(spec.coverage)
    usable = [p for p in prepared.values() if p.usable]
    cal = None
    error = None
    if spec.parameters:
        with clock.stage("calibrate"):
            say("calibrating")
            try:
                cal = _calibrate(spec, [p for p in usable if p.spec.use == "calibration"], evaluate)
            except CalibrationFailed as exc:
                error = str(exc)
    values = cal.values if cal is not None else spec.initial
    with clock.stage("validate"):
        say("validating")
        results = _compare_all(spec, prepared, evaluate, values, cal, k)
    timing = {**clock.stages, "model_runs": evaluate.runs, "model_runs_reused": evaluate.reused}
    return CampaignResult(spec, results, cal, tuple(values), k, error, timing, run_environment(spec.engines))


def _calibrate(spec: CampaignSpec, recordings: Sequence[Prepared], evaluate: Evaluator) -> Calibration:
    """The fit over the calibration recordings whose model runs at the initial values."""
    engine = spec.engines[0]
    plans = _plans(spec, recordings, spec.initial, engine, propagate=False, inputs=False)
    outcomes = _outcomes(evaluate, [r for plan in plans for r in plan.all])
    budgets = _budgets(spec, recordings, plans, outcomes, None, inputs=False)
    kept = [(p, b, u) for p, (b, u) in zip(recordings, budgets, strict=True) if b is not None]
    if not kept:
        raise CalibrationFailed("no calibration recording has a model run that ends ok at the initial values")
    sigma = [b.u_val(u) for _, b, u in kept]
    return calibrate(evaluate, engine, spec.parameters, [p.spec.index for p, _, _ in kept],
                     [p.measured.efficiency for p, _, _ in kept], sigma, spec.coverage)


def _plans(spec: CampaignSpec, recordings: Sequence[Prepared], values: Sequence[float], engine: str,
           propagate: bool, inputs: bool) -> list[BudgetRuns]:
    """The runs of each recording's budget at ``values`` (parameter steps when ``propagate``, stated-input
    steps when ``inputs``)."""
    parameters = spec.parameters if propagate else ()
    stated = spec.inputs if inputs else ()
    plans = []
    for p in recordings:
        point = ModelRun(p.spec.index, engine, tuple(values))
        steps = jacobian_runs(point, parameters) if propagate else ([], np.empty(0))
        plans.append(budget_runs(p, engine, tuple(values), parameters, stated, steps))
    return plans


def _budgets(spec: CampaignSpec, recordings: Sequence[Prepared], plans: Sequence[BudgetRuns],
             outcomes: dict[ModelRun, Outcome], covariance: np.ndarray | None,
             inputs: bool) -> list[tuple[Budget | None, float | None]]:
    """Each recording's budget and its ``u_num`` from its plan's ``outcomes`` (``(None, None)`` when its
    run fails)."""
    parameters = spec.parameters if covariance is not None else ()
    stated = spec.inputs if inputs else ()
    out = []
    for p, plan in zip(recordings, plans, strict=True):
        if not outcomes[plan.point].ok:
            out.append((None, None))
            continue
        out.append((budget(p, plan, outcomes, parameters, covariance, stated), _u_num(outcomes[plan.point])))
    return out


def _outcomes(evaluate: Evaluator, runs: list[ModelRun]) -> dict[ModelRun, Outcome]:
    """The outcome of each run, by run."""
    return dict(zip(runs, evaluate(runs), strict=True))


def _u_num(outcome: Outcome) -> float:
    """The engine's error estimate as a standard uncertainty (0 when it gives none)."""
    u = outcome.error_estimate
    return float(abs(u)) if u is not None and math.isfinite(u) else 0.0


def _compare_all(spec: CampaignSpec, prepared: dict[int, Prepared], evaluate: Evaluator,
                 values: Sequence[float], cal: Calibration | None, k: float) -> tuple[RecordingResult, ...]:
    """Every recording's result: budget on the first engine, ``S`` on each; all runs in one request."""
    usable = [p for p in prepared.values() if p.usable]
    cov = cal.covariance if cal is not None else None
    first = spec.engines[0]
    plans = _plans(spec, usable, values, first, propagate=cov is not None, inputs=True)
    others = [ModelRun(p.spec.index, e, tuple(values)) for p in usable for e in spec.engines[1:]]
    scatter = {p.spec.index: model_scatter(p, first, np.asarray(values), cov, spec.parameters, spec.inputs,
                                           spec.input_samples, spec.seed + p.spec.index)
               for p in usable if spec.input_samples}
    runs = [r for plan in plans for r in plan.all] + others + [r for rs in scatter.values() for r in rs]
    outcomes = _outcomes(evaluate, runs)
    budgets = dict(zip([p.spec.index for p in usable],
                       _budgets(spec, usable, plans, outcomes, cov, inputs=True), strict=True))
    out = []
    for index, p in prepared.items():
        if not p.usable:
            out.append(_unusable(p, k))
            continue
        b = budgets[index][0]
        if b is not None and index in scatter:
            b = _with_sampled(b, [outcomes[r] for r in scatter[index]])
        out.append(_recording(spec, p, b, values, outcomes, k))
    return tuple(out)


def _with_sampled(b: Budget, outcomes: list[Outcome]) -> Budget:
    """``b`` with the sampling check of ``u_parameters`` and ``u_inputs`` (std of the sampled ``S``)."""
    s = np.array([o.efficiency for o in outcomes if o.ok])
    return dataclasses.replace(b, u_input_sampled=float(np.std(s, ddof=1)) if s.size > 1 else None)


def _unusable(p: Prepared, k: float) -> RecordingResult:
    """A recording whose measurement is an error in the data: reported, not compared."""
    reason = next(f.message for f in p.findings if f.status in ("unphysical", "inconsistent"))
    return RecordingResult(p.spec.index, p.spec.label, p.spec.file, p.sha256, p.spec.use,
                           p.spec.shaft_angle_deg, "measurement", reason, operating_point(p.conditioned),
                           p.measured.efficiency, p.measured.u, tuple(f.as_dict() for f in p.findings), k,
                           provenance=p.provenance, monte_carlo=p.measured.monte_carlo)


def _recording(spec: CampaignSpec, p: Prepared, b: Budget | None, values: Sequence[float],
               outcomes: dict[ModelRun, Outcome], k: float) -> RecordingResult:
    """One recording's result from its budget and each engine's run (in ``outcomes``)."""
    d = p.measured.efficiency
    engines = {}
    s_first = None
    for engine in spec.engines:
        outcome = outcomes[ModelRun(p.spec.index, engine, tuple(values))]
        comparison = _compare(engine, outcome, d, b, k, s_first)
        if s_first is None:
            s_first = comparison.simulated
        engines[engine] = comparison
    first = engines[spec.engines[0]]
    status = "ok" if first.status == "ok" else "model"
    reason = None if status == "ok" else f"{spec.engines[0]}: {first.status}: {first.reason}"
    return RecordingResult(p.spec.index, p.spec.label, p.spec.file, p.sha256, p.spec.use,
                           p.spec.shaft_angle_deg, status, reason, operating_point(p.conditioned), d,
                           p.measured.u, tuple(f.as_dict() for f in p.findings), k, b, engines, p.provenance,
                           p.measured.monte_carlo)


def _compare(engine: str, outcome: Outcome, d: float, b: Budget | None, k: float,
             s_first: float | None) -> EngineComparison:
    """One engine's comparison with ``D`` under budget ``b``."""
    if not outcome.ok or b is None:
        return EngineComparison(engine, str(outcome.status), outcome.reason, outcome.efficiency,
                                None if outcome.error_estimate is None else _u_num(outcome))
    s = float(outcome.efficiency)
    u_num = _u_num(outcome)
    e = s - d
    u_val = b.u_val(u_num)
    return EngineComparison(engine, "ok", None, s, u_num, e, u_val, (e - k * u_val, e + k * u_val),
                            bool(abs(e) > k * u_val), None if s_first is None else s - s_first)
