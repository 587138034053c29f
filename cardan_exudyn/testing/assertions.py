"""Assertions for a test suite: a run's mean efficiency, and engines agreeing on a scene.

Default tolerance: :data:`~cardan_exudyn.model.error_estimate.SAFETY_FACTOR` times the runs' estimated
error (summed over both runs). A tolerance given (``rtol``, ``atol``) is used as given, never
widened: below what the runs resolve, the check fails. No estimate, an estimate over
:data:`MAX_RELATIVE_ERROR` of the scale, a run not ``ok`` or opposite power flows: the check fails.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cardan_exudyn.comparison import COMPARED, check_request, join_on_input_angle
from cardan_exudyn.comparison import run_engines as comparison_runs  # with the session cache
from cardan_exudyn.engines import run as run_engine
from cardan_exudyn.model.error_estimate import (
    ESTIMATED_MEANS,
    SAFETY_FACTOR,
    AccuracyError,
    ErrorEstimate,
    error_estimate,
    mean_values,
)
from cardan_exudyn.report.format import is_number, markdown_table, number
from reference.results.means import after_revolutions
from reference.results.result import Result
from reference.scene.scene import Scene

__all__ = ["MAX_RELATIVE_ERROR", "ROUNDING", "DEFAULT_COLUMNS", "CardanToleranceWarning", "Limit",
           "Check", "assert_efficiency", "assert_engines_agree", "tolerance"]

MAX_RELATIVE_ERROR = 1e-2
"""Largest tolerance an error estimate may set, relative to the value's scale: beyond it a check
would hardly fail, and it fails instead, asking for a finer run or an explicit tolerance."""
ROUNDING = 1e-12
"""Tolerance floor relative to the value's scale (an exact run still carries rounding)."""
DEFAULT_COLUMNS = ("mean_efficiency", "work_ratio", "input_work", "output_work", "loss_work")
"""What :func:`assert_engines_agree` compares unless told otherwise: the mean values."""


class CardanToleranceWarning(UserWarning):
    """Not emitted; defined so that warning filters naming it still load."""


@dataclass(frozen=True)
class Limit:
    """A tolerance and where it comes from: ``value`` (the largest difference that passes), ``asked``
    (``max(atol, rtol * scale)``, or None) and ``estimated`` (``SAFETY_FACTOR`` times the estimate, or None).
    """

    value: float
    asked: float | None
    estimated: float | None

    def describe(self) -> str:
        """Which term set the tolerance: the one asked, the estimate, or the rounding floor."""
        if self.asked is not None and self.value == self.asked:
            return "asked"
        if self.estimated is not None and self.value == self.estimated:
            return f"{SAFETY_FACTOR:g} x estimated error"
        return "rounding"


@dataclass(frozen=True)
class Check:
    """One value compared: the two values, their difference, the tolerance, or ``problem``."""

    name: str
    values: tuple[float | None, float | None]
    difference: float | None = None
    limit: Limit | None = None
    problem: str = ""

    @property
    def failed(self) -> bool:
        return bool(self.problem) or abs(self.difference) > self.limit.value

    def row(self, labels: Sequence[str]) -> dict[str, Any]:
        """The check as a row of the failure table."""
        limit = self.limit
        note = self.problem or (limit.describe() if limit else "")
        return {"quantity": self.name, labels[0]: self.values[0], labels[1]: self.values[1],
                "difference": self.difference, "tolerance": limit.value if limit else None,
                "from": note}


def tolerance(scale: float, errors: Sequence[float | None], rtol: float | None = None,
              atol: float | None = None) -> Limit | str:
    """The :class:`Limit` of a difference at ``scale`` with estimated ``errors`` (None: none) and the
    test's ``rtol``, ``atol``; or, as a str, why the value cannot be checked.
    """
    asked = None if rtol is None and atol is None else max(atol or 0.0, (rtol or 0.0) * scale)
    estimated = SAFETY_FACTOR * float(sum(errors)) if all(e is not None for e in errors) else None
    if asked is not None:
        if estimated is not None and estimated > asked:
            relative = f" (rtol {number(estimated / scale, '.3g')})" if scale > 0.0 else ""
            return (f"the tolerance asked, {number(asked, '.3g')}, is below what the runs resolve, "
                    f"{SAFETY_FACTOR:g} x estimated error = {number(estimated, '.3g')}{relative}: give "
                    f"at least that, or refine the runs (numerics.accuracy, dt)")
        return Limit(asked, asked, estimated)
    if estimated is None:
        return "no error estimate: give rtol or atol"
    if not estimated <= MAX_RELATIVE_ERROR * scale:
        return (f"{SAFETY_FACTOR:g} x estimated error = {number(estimated, '.3g')} is over "
                f"{MAX_RELATIVE_ERROR:g} of the value: refine the run (numerics.accuracy, dt)")
    return Limit(max(estimated, ROUNDING * scale), None, estimated)


def check_values(name: str, values: tuple[Any, Any], scale: float | None,
                 errors: Sequence[float | None], rtol: float | None, atol: float | None) -> Check:
    """Compare ``values[1]`` with ``values[0]`` (``scale``: default ``|values[0]|``)."""
    if not (is_number(values[0]) and is_number(values[1])):
        return Check(name, values, problem="no finite value to compare")
    first, second = float(values[0]), float(values[1])
    limit = tolerance(abs(first) if scale is None else scale, errors, rtol, atol)
    if isinstance(limit, str):
        return Check(name, (first, second), second - first, problem=limit)
    return Check(name, (first, second), second - first, limit)


def check_tolerances(rtol: float | None, atol: float | None) -> None:
    """Raise ValueError unless ``rtol`` and ``atol`` are None or finite numbers >= 0."""
    for name, value in (("rtol", rtol), ("atol", atol)):
        if value is not None and not (is_number(value) and value >= 0):
            raise ValueError(f"`{name}` must be a finite number >= 0 or None, got {value!r}")


def estimate_of(result: Result, run: Callable[..., Result] | None,
                skip_revolutions: float = 0.0) -> ErrorEstimate | str | None:
    """The run's error estimate, or why it could not be made."""
    try:
        return error_estimate(result, run, skip_revolutions)
    except AccuracyError as exc:
        return f"cannot estimate the error of the {result.summary.engine} run: {exc}"


def failed_runs(results: Mapping[str, Result]) -> str:
    """One line per run that did not end ``ok`` (empty when all did)."""
    return "\n".join(f"the {engine} run of scene {result.summary.scene.get('name', '?')!r} ended "
                     f"{result.status}: {result.message}"
                     for engine, result in results.items() if not result.success)


def failure_message(title: str, checks: Sequence[Check], labels: Sequence[str],
                    estimates: Mapping[str, ErrorEstimate | None]) -> str:
    """The assertion message: ``title``, the failed ``checks`` as a table with value columns ``labels``,
    and each engine's error ``estimates``.
    """
    columns = ["quantity", *labels, "difference", "tolerance", "from"]
    formats = {labels[0]: ".8g", labels[1]: ".8g", "difference": "+.3e", "tolerance": ".3e"}
    table = markdown_table([c.row(labels) for c in checks if c.failed], columns, formats)
    notes = [f"{engine}: {e.detail}" if e is not None else f"{engine}: no error estimate"
             for engine, e in estimates.items()]
    return f"{title}\n\n{table}\nerror estimates: {'; '.join(notes)}"


def assert_efficiency(result: Result, expected: float, *, rtol: float | None = None,
                      atol: float | None = None, run: Callable[..., Result] | None = None) -> None:
    """Assert that a run's mean efficiency is ``expected``, within the run's accuracy.

    Parameters
    ----------
    result : Result
    expected : float
        The expected mean efficiency [-].
    rtol, atol : float, optional
        Relative (to ``|expected|``) and absolute tolerances [-], used as given. Default:
        ``SAFETY_FACTOR`` times the run's estimated error.
    run : callable, optional
        ``run(scene, engine, options) -> Result`` for the half-step rerun that estimates a
        fixed-step engine's error; pass the plugin's ``cardan_run`` to reuse its cache.

    Raises
    ------
    AssertionError
        With a table: value, expected, difference, tolerance and its origin.
    """
    __tracebackhide__ = True
    check_tolerances(rtol, atol)
    if not is_number(expected):
        raise ValueError(f"`expected` must be a finite number, got {expected!r}")
    engine, scene = result.summary.engine, result.summary.scene.get("name", "?")
    if not result.success:
        raise AssertionError(f"{failed_runs({engine: result})}: no mean efficiency to compare "
                             f"with {expected!r}")
    if result.mean_efficiency is None:
        raise AssertionError(f"the {engine} run of scene {scene!r} has no mean efficiency to compare "
                             f"with {expected!r}: {'; '.join(result.summary.warnings)}")
    estimate = estimate_of(result, run)
    if isinstance(estimate, str):
        raise AssertionError(estimate)
    error = estimate.of("mean_efficiency") if estimate is not None else None
    check = check_values("mean_efficiency", (expected, result.mean_efficiency), abs(expected),
                         [error, 0.0], rtol, atol)
    if check.failed:
        raise AssertionError(failure_message(
            f"mean efficiency of scene {scene!r} ({engine}) is not {expected!r}:", [check],
            ["expected", engine], {engine: estimate}))


def mean_scale(name: str, values: Mapping[str, float]) -> float | None:
    """Scale [J] of mean value ``name`` in the base run's ``values``: for a work, the larger of input
    and output works; else None (the value's own magnitude).
    """
    if name.endswith("_work") or name.startswith("loss_work_"):
        return max(abs(values.get(name, 0.0)), abs(values.get("input_work", 0.0)),
                   abs(values.get("output_work", 0.0)))
    return None


def check_flow(base: Result, other: Result) -> list[Check]:
    """One failed :class:`Check` when runs ``base`` and ``other`` have opposite power flows, else none."""
    flows = (base.summary.power_flow, other.summary.power_flow)
    if flows[0] == flows[1]:
        return []
    return [Check("power_flow", flows, problem="the power flows a different way")]


def check_means(names: Sequence[str], base: Result, other: Result,
                errors: tuple[ErrorEstimate | None, ErrorEstimate | None],
                rtol: float | None, atol: float | None) -> list[Check]:
    """The mean values ``names`` of two runs compared."""
    a, b = mean_values(base.summary), mean_values(other.summary)
    return [check_values(name, (a.get(name), b.get(name)), mean_scale(name, a),
                         [e.of(name) if e is not None else None for e in errors], rtol, atol)
            for name in names]


def check_columns(names: Sequence[str], base: Result, other: Result,
                  errors: tuple[ErrorEstimate | None, ErrorEstimate | None],
                  rtol: float | None, atol: float | None, skip_revolutions: float) -> list[Check]:
    """The time-table columns ``names`` of two runs compared where they differ most (rows joined on
    the input angle; the first ``skip_revolutions`` left out).
    """
    if not names:
        return []
    joined, _ = join_on_input_angle(base.table, other.table)
    theta = base.table["theta_in"].to_numpy(float)
    keep = after_revolutions(theta, skip_revolutions)
    checks = []
    for name in names:
        first = base.table[name].to_numpy(float)[keep]
        second = joined.get(name, np.full(theta.shape, np.nan))[keep]
        finite = np.isfinite(first) & np.isfinite(second)
        if not np.any(finite):
            checks.append(Check(name, (None, None), problem="no row where both are finite"))
            continue
        worst = int(np.argmax(np.where(finite, np.abs(second - first), -1.0)))
        scale = float(np.max(np.abs(first[np.isfinite(first)])))
        estimated = [e.columns.get(name) if e is not None else None for e in errors]
        checks.append(check_values(f"{name} (largest difference)", (first[worst], second[worst]),
                                   scale, estimated, rtol, atol))
    return checks


def check_names(columns: Sequence[str]) -> tuple[list[str], list[str]]:
    """Split ``columns`` into mean values and time-table columns; unknown names are refused."""
    means = [c for c in columns if c not in COMPARED]
    unknown = [c for c in means if c not in ESTIMATED_MEANS and not c.startswith("loss_work_")]
    if unknown:
        raise ValueError(f"unknown column(s) {unknown}: give mean values {list(ESTIMATED_MEANS)} "
                         "or loss_work_<pair>, or time-table columns")
    return means, [c for c in columns if c in COMPARED]


def assert_engines_agree(scene: Scene, engines: Sequence[str] = ("exudyn", "reference"),
                         columns: Sequence[str] | None = None, *, rtol: float | None = None,
                         atol: float | None = None, options: Mapping[str, Any] | None = None,
                         skip_revolutions: float = 0.0,
                         run: Callable[..., Result] | None = None) -> None:
    """Assert that engines agree on a scene, within their own accuracy.

    Each engine after the first is compared with the first, as :func:`cardan_exudyn.compare` does
    (every step recorded, rows joined on the input angle).

    Parameters
    ----------
    scene : Scene
    engines : sequence of str
        At least two; the first is the base.
    columns : sequence of str, optional
        Mean values (default :data:`DEFAULT_COLUMNS`) and time-table columns (``omega_out``, ...;
        compared where the two differ most, after ``skip_revolutions``).
    rtol, atol : float, optional
        Relative (a work: to the base's input work; a column: its largest magnitude) and absolute
        tolerances, used as given. Default: ``SAFETY_FACTOR`` times the sum of the runs' errors.
    options : mapping, optional
        Engine name -> its options.
    skip_revolutions : float
        Input revolutions left out of the time-table comparisons [-].
    run : callable, optional
        ``run(scene, engine, options) -> Result`` (default :func:`cardan_exudyn.engines.run`);
        pass the plugin's ``cardan_run`` to reuse its cache.

    Raises
    ------
    AssertionError
        With a table of the failed values: each engine's value, difference, tolerance, origin.
    ValueError
        Fewer than two engines, an engine twice, an unknown column or a bad tolerance.
    """
    __tracebackhide__ = True
    check_tolerances(rtol, atol)
    engines, options = list(engines), dict(options or {})
    check_request(engines, options, skip_revolutions)
    means, table_columns = check_names(list(columns or DEFAULT_COLUMNS))
    run = run or run_engine
    results = comparison_runs(scene, engines, options, runner=run)[0]
    if failed_runs(results):
        raise AssertionError(failed_runs(results))
    estimates = {engine: estimate_of(result, run, skip_revolutions) for engine, result in results.items()}
    problems = [e for e in estimates.values() if isinstance(e, str)]
    if problems:
        raise AssertionError("\n".join(problems))
    base, *others = engines
    for other in others:
        errors = (estimates[base], estimates[other])
        checks = (check_flow(results[base], results[other])
                  + check_means(means, results[base], results[other], errors, rtol, atol)
                  + check_columns(table_columns, results[base], results[other], errors, rtol, atol,
                                  skip_revolutions))
        if any(c.failed for c in checks):
            raise AssertionError(failure_message(
                f"engine {other} disagrees with engine {base} on scene {scene.name!r}:", checks,
                [base, other], {base: estimates[base], other: estimates[other]}))
