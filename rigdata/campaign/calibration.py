"""Calibration: weighted non-linear least squares of simulated against measured efficiency over the
calibration recordings, within the parameters' bounds (``scipy.optimize.least_squares``, trust region
reflective: bounds handled by the method, not by clipping).

Residuals ``r_i = (S_i(p) - D_i) / sigma_i`` with ``sigma_i`` the recording's stated uncertainty of
``S - D`` at fixed parameters, taken as absolute: the covariance is ``(J^T J)^-1`` of the weighted
Jacobian and is never scaled by the fit's chi-square, so a misfit shows as a rejected fit, not as wider
parameters. Directions the data determine less well than the bounds do (a uniform over them) are not
identified: the parameters along them are reported as such, with the combinations the data do fix.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import optimize, stats

from rigdata.campaign.evaluate import ModelRun, Outcome
from rigdata.campaign.spec import Parameter

__all__ = ["IDENTIFIED_SHRINK", "RELATIVE_STEP", "XTOL", "Estimate", "Combination", "Calibration",
           "CalibrationFailed", "calibrate", "jacobian_runs", "propagation_covariance"]

IDENTIFIED_SHRINK = 0.5
"""A parameter is identified when its standard uncertainty from the data alone is below this fraction
of its bounds' (a uniform over them: width / sqrt(12)); the data must at least halve what the bounds say."""
RELATIVE_STEP = 1e-4
"""Forward-difference step of the Jacobian as a fraction of each parameter's bounds width [-]; the
reference engine's efficiency is exact to about 1e-10, so the step's truncation error dominates."""

XTOL = 1e-7
"""Relative step at which the fit stops: far below any parameter's uncertainty from rig data (1e-2 and
more), so the estimate's own error never shows in a budget."""

Evaluate = Callable[[Sequence[ModelRun]], list[Outcome]]


class CalibrationFailed(RuntimeError):
    """A model run of the fit did not end ``ok``; names the recording, the values and the reason."""


@dataclass(frozen=True)
class Estimate:
    """One calibrated parameter.

    ``standard_uncertainty`` is None when not ``identifiable``; ``at_bound`` when the estimate sits on
    a bound (its uncertainty from the Jacobian then is not a confidence statement).
    """

    name: str
    value: float
    standard_uncertainty: float | None
    identifiable: bool
    at_bound: bool
    bounds: tuple[float, float]


@dataclass(frozen=True)
class Combination:
    """A linear combination of the parameters that the data determine: ``sum(c_j p_j)``."""

    coefficients: dict[str, float]
    value: float
    standard_uncertainty: float


@dataclass(frozen=True)
class Calibration:
    """The fit and what it says.

    Attributes
    ----------
    estimates : tuple of Estimate
    covariance : ndarray, shape (p, p)
        For propagation: the data's where they determine a direction, the bounds' (uniform) where not.
    correlation : ndarray, shape (p, p)
    combinations : tuple of Combination
        The determined combinations, when some parameter is not identifiable.
    recordings : tuple of int
        Indexes of the calibration recordings.
    residuals : tuple of float
        ``(S_i - D_i) / sigma_i`` at the estimate [-].
    sigma : tuple of float
        The residuals' scales [-].
    chi_square : float
    dof : int
        Recordings minus identified directions.
    p_value : float or None
        None without degrees of freedom.
    rejected : bool or None
        True when ``p_value < 1 - coverage``: the calibration recordings reject the model.
    evaluations : int
        Residual evaluations of the fit.
    message : str
        The optimiser's.
    """

    estimates: tuple[Estimate, ...]
    covariance: np.ndarray
    correlation: np.ndarray
    combinations: tuple[Combination, ...]
    recordings: tuple[int, ...]
    residuals: tuple[float, ...]
    sigma: tuple[float, ...]
    chi_square: float
    dof: int
    p_value: float | None
    rejected: bool | None
    evaluations: int
    message: str

    @property
    def values(self) -> tuple[float, ...]:
        """The estimates' values, in the campaign's order."""
        return tuple(e.value for e in self.estimates)

    def as_dict(self) -> dict[str, Any]:
        """``calibration`` of ``results.json``."""
        return {"chi_square": self.chi_square, "dof": self.dof, "p_value": self.p_value,
                "rejected": self.rejected, "recordings": list(self.recordings),
                "residuals": list(self.residuals), "sigma": list(self.sigma),
                "evaluations": self.evaluations, "message": self.message,
                "combinations": [{"coefficients": c.coefficients, "value": c.value,
                                  "standard_uncertainty": c.standard_uncertainty}
                                 for c in self.combinations],
                "covariance": self.covariance.tolist()}


def jacobian_runs(point: ModelRun, parameters: tuple[Parameter, ...]) -> tuple[list[ModelRun], np.ndarray]:
    """The runs of a forward-difference Jacobian at ``point`` and their signed steps (backwards at an
    upper bound).
    """
    runs = []
    steps = np.empty(len(parameters))
    for j, p in enumerate(parameters):
        h = RELATIVE_STEP * (p.bounds[1] - p.bounds[0])
        if point.values[j] + h > p.bounds[1]:
            h = -h
        values = list(point.values)
        values[j] += h
        runs.append(ModelRun(point.recording, point.engine, tuple(values), point.changes,
                             point.load_offset, point.phase_shift))
        steps[j] = h
    return runs, steps


class _Problem:
    """The residual and Jacobian functions of the fit over the calibration recordings."""

    def __init__(self, evaluate: Evaluate, engine: str, parameters: tuple[Parameter, ...],
                 recordings: Sequence[int], measured: np.ndarray, sigma: np.ndarray) -> None:
        self.evaluate = evaluate
        self.engine = engine
        self.parameters = parameters
        self.recordings = tuple(recordings)
        self.measured = measured
        self.sigma = sigma

    def points(self, x: np.ndarray) -> list[ModelRun]:
        """One run per calibration recording at parameter values ``x``."""
        return [ModelRun(i, self.engine, tuple(float(v) for v in x)) for i in self.recordings]

    def simulated(self, runs: Sequence[ModelRun]) -> np.ndarray:
        """The efficiency of each run; CalibrationFailed if one did not end ``ok``."""
        out = self.evaluate(runs)
        for r, o in zip(runs, out, strict=True):
            if not o.ok:
                raise CalibrationFailed(f"recording {r.recording} at {self._text(r.values)}: the model "
                                        f"ended {o.status}: {o.reason}")
        return np.array([o.efficiency for o in out])

    def _text(self, values: Sequence[float]) -> str:
        """``name = value`` for each parameter."""
        return ", ".join(f"{p.name} = {v:.6g}" for p, v in zip(self.parameters, values, strict=True))

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """``(S - D) / sigma`` at ``x``."""
        return (self.simulated(self.points(x)) - self.measured) / self.sigma

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Weighted Jacobian of the residuals at ``x``, all runs in one request."""
        base = self.points(x)
        pairs = [jacobian_runs(point, self.parameters) for point in base]
        runs = [r for point_runs, _ in pairs for r in point_runs]
        s0 = self.simulated(base)
        s1 = self.simulated(runs).reshape(len(base), len(self.parameters))
        steps = np.array([st for _, st in pairs])
        return (s1 - s0[:, None]) / steps / self.sigma[:, None]


def propagation_covariance(jw: np.ndarray, parameters: tuple[Parameter, ...]) -> tuple[np.ndarray, list]:
    """The parameters' covariance and the identified directions ``(v, data_std)`` from the weighted
    Jacobian ``jw``: along each right singular vector the data's ``1 / s`` where it is below the bounds'
    spread along that vector, else the bounds'.
    """
    prior = np.array([(p.bounds[1] - p.bounds[0]) / math.sqrt(12.0) for p in parameters])
    _, s, vt = np.linalg.svd(jw, full_matrices=False)
    variances = []
    identified = []
    for k, v in enumerate(vt):
        spread = float(np.sqrt(np.sum((v * prior) ** 2)))
        data = 1.0 / s[k] if s[k] > 0 else math.inf
        variances.append(min(data, spread) ** 2)
        if data < spread:
            identified.append((v, data))
    return vt.T @ np.diag(variances) @ vt, identified


def _data_std(jw: np.ndarray) -> np.ndarray:
    """Each parameter's standard uncertainty from the data alone (inf where they do not determine it)."""
    info = jw.T @ jw
    try:
        cov = np.linalg.inv(info)
    except np.linalg.LinAlgError:
        return np.full(info.shape[0], math.inf)
    if np.linalg.cond(info) > 1e14:
        return np.full(info.shape[0], math.inf)
    return np.sqrt(np.maximum(np.diag(cov), 0.0))


def calibrate(evaluate: Evaluate, engine: str, parameters: tuple[Parameter, ...], recordings: Sequence[int],
              measured: Sequence[float], sigma: Sequence[float], coverage: float) -> Calibration:
    """Fit ``parameters`` so that the simulated efficiency of ``recordings`` matches ``measured``.

    ``evaluate`` runs model requests (:class:`rigdata.campaign.evaluate.Evaluator`); ``sigma`` the
    residuals' scales [-]; ``coverage`` sets the chi-square test's level. CalibrationFailed if a model run
    of the fit fails.
    """
    problem = _Problem(evaluate, engine, parameters, recordings, np.asarray(measured, float),
                       np.asarray(sigma, float))
    low = np.array([p.bounds[0] for p in parameters])
    high = np.array([p.bounds[1] for p in parameters])
    fit = optimize.least_squares(problem.residuals, np.array([p.initial for p in parameters]),
                                 jac=problem.jacobian, bounds=(low, high), method="trf",
                                 x_scale=high - low, xtol=XTOL, ftol=1e-10, gtol=1e-10)
    jw = problem.jacobian(fit.x)
    residuals = problem.residuals(fit.x)
    return _summarise(fit, jw, residuals, problem, coverage)


def _summarise(fit: Any, jw: np.ndarray, residuals: np.ndarray, problem: _Problem,
               coverage: float) -> Calibration:
    """The :class:`Calibration` of an optimiser result."""
    parameters = problem.parameters
    cov, identified = propagation_covariance(jw, parameters)
    data_std = _data_std(jw)
    found = zip(parameters, fit.x, data_std, strict=True)
    estimates = tuple(_estimate(p, float(x), float(u)) for p, x, u in found)
    combos = () if all(e.identifiable for e in estimates) else _combinations(identified, fit.x, parameters)
    chi2 = float(residuals @ residuals)
    dof = len(residuals) - len(identified)
    p_value = float(stats.chi2.sf(chi2, dof)) if dof > 0 else None
    rejected = None if p_value is None else bool(p_value < 1.0 - coverage)
    std = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    return Calibration(estimates, cov, corr, combos, problem.recordings, tuple(residuals.tolist()),
                       tuple(problem.sigma.tolist()), chi2, dof, p_value, rejected, int(fit.nfev),
                       str(fit.message))


def _estimate(p: Parameter, value: float, data_std: float) -> Estimate:
    """The estimate of ``p`` with its identifiability."""
    prior = (p.bounds[1] - p.bounds[0]) / math.sqrt(12.0)
    identifiable = bool(data_std < IDENTIFIED_SHRINK * prior)
    edge = 1e-6 * (p.bounds[1] - p.bounds[0])
    at_bound = bool(value - p.bounds[0] < edge or p.bounds[1] - value < edge)
    return Estimate(p.name, value, data_std if identifiable else None, identifiable, at_bound, p.bounds)


def _combinations(identified: list, x: np.ndarray, parameters: tuple[Parameter, ...]) -> tuple:
    """The identified directions as combinations, scaled so the largest coefficient is 1."""
    out = []
    for v, data_std in identified:
        scale = float(v[np.argmax(np.abs(v))])
        coefficients = {p.name: float(c / scale) for p, c in zip(parameters, v, strict=True)}
        out.append(Combination(coefficients, float(v @ x / scale), float(data_std / abs(scale))))
    return tuple(out)
