"""The validation uncertainty of one recording (ASME V&V 20): ``E = S - D`` and
``u_val^2 = u_num^2 + u_input^2 + u_D^2 - 2 cov(S, D)``.

- ``u_num``: the engine's own estimate of its mean efficiency's error, taken as a standard uncertainty.
- ``u_input``: what the model's uncertain inputs do to ``S``, by sensitivity coefficients (forward
  differences): the calibrated parameters (their covariance), the stated inputs (one standard
  uncertainty each), the measured load that drives the model (the output transducer's constant errors)
  and the yoke phase's half-turn ambiguity (rectangular, half width ``|dS| / 2``).
- ``u_D``: the measured efficiency's GUM uncertainty.
- ``cov(S, D)``: the output transducer's constant errors move ``D`` and, through the load, ``S``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rigdata.campaign.evaluate import ModelRun, Outcome
from rigdata.campaign.prepare import Prepared
from rigdata.campaign.spec import InputUncertainty, Parameter, scene_value
from rigdata.efficiency import SQRT3
from rigdata.validation import CONSTANT_OUTPUT_ERRORS

__all__ = ["Budget", "BudgetRuns", "budget_runs", "budget", "model_scatter", "PHASE_SHIFT"]

PHASE_SHIFT = math.pi
"""The other yoke-phase fit: half a turn of the input yoke."""


@dataclass(frozen=True)
class Budget:
    """The uncertainty budget of one recording's comparison (first engine).

    Attributes
    ----------
    u_D : float
    u_input : float
        Root sum of squares of the four parts below [-].
    u_parameters, u_inputs, u_load, u_phase : float
        Calibrated parameters, stated inputs, measured load, yoke-phase ambiguity [-].
    covariance_SD : float
        ``cov(S, D)`` from the shared output transducer [-^2].
    sensitivities : dict of str to float
        ``dS/dp`` of each calibrated parameter [-/unit].
    input_effects : dict of str to float
        ``S(x + u) - S(x)`` of each stated input [-].
    load_sensitivity : float
        ``dS/dT_load`` [1/(N m)].
    u_input_sampled : float or None
        The sampling check of ``u_input`` (without the load and phase parts), when asked for.
    """

    u_D: float
    u_input: float
    u_parameters: float
    u_inputs: float
    u_load: float
    u_phase: float
    covariance_SD: float
    sensitivities: dict[str, float]
    input_effects: dict[str, float]
    load_sensitivity: float
    u_input_sampled: float | None = field(default=None)

    def u_val(self, u_num: float) -> float:
        """``sqrt(u_num^2 + u_input^2 + u_D^2 - 2 cov(S, D))`` [-]."""
        return math.sqrt(max(u_num**2 + self.u_input**2 + self.u_D**2 - 2.0 * self.covariance_SD, 0.0))

    def dominant(self, u_num: float) -> str:
        """The largest of ``u_num``, ``u_input`` and ``u_D``."""
        parts = {"u_num": u_num, "u_input": self.u_input, "u_D": self.u_D}
        return max(parts, key=parts.__getitem__)

    def as_dict(self) -> dict[str, Any]:
        """JSON fields."""
        return {"u_D": self.u_D, "u_input": self.u_input, "u_parameters": self.u_parameters,
                "u_inputs": self.u_inputs, "u_load": self.u_load, "u_phase": self.u_phase,
                "covariance_SD": self.covariance_SD, "sensitivities": self.sensitivities,
                "input_effects": self.input_effects, "load_sensitivity": self.load_sensitivity,
                "u_input_sampled": self.u_input_sampled}


@dataclass(frozen=True)
class BudgetRuns:
    """The runs a budget needs at one recording: the point, the parameter steps, the stated inputs'
    steps, the load offset and the other yoke phase.
    """

    point: ModelRun
    parameter_runs: tuple[ModelRun, ...]
    steps: np.ndarray
    input_runs: tuple[ModelRun, ...]
    load_run: ModelRun
    load_delta: float
    phase_run: ModelRun

    @property
    def all(self) -> list[ModelRun]:
        """Every run, the point first."""
        return [self.point, *self.parameter_runs, *self.input_runs, self.load_run, self.phase_run]


def budget_runs(prepared: Prepared, engine: str, values: tuple[float, ...], parameters: tuple[Parameter, ...],
                inputs: Sequence[InputUncertainty], parameter_runs: tuple[list, np.ndarray]) -> BudgetRuns:
    """The runs of :func:`budget` at recording ``prepared`` with parameter ``values``; ``parameter_runs`` is
    :func:`rigdata.campaign.calibration.jacobian_runs` of the point.
    """
    index = prepared.spec.index
    point = ModelRun(index, engine, values)
    output = prepared.spec.transducers[1]
    delta = output.accuracy_limit / SQRT3 or 1e-3 * output.full_scale
    input_runs = tuple(ModelRun(index, engine, values, ((i.key, scene_value(prepared.scene, i.key) + i.std),))
                       for i in inputs)
    runs, steps = parameter_runs
    load_run = ModelRun(index, engine, values, load_offset=delta)
    phase_run = ModelRun(index, engine, values, phase_shift=PHASE_SHIFT)
    return BudgetRuns(point, tuple(runs), steps, input_runs, load_run, delta, phase_run)


def _efficiency(outcome: Outcome) -> float:
    """The run's efficiency, NaN unless ``ok``."""
    return float(outcome.efficiency) if outcome.ok else math.nan


def budget(prepared: Prepared, runs: BudgetRuns, outcomes: Mapping[ModelRun, Outcome],
           parameters: tuple[Parameter, ...], covariance: np.ndarray | None,
           inputs: Sequence[InputUncertainty]) -> Budget:
    """The :class:`Budget` of ``prepared`` from the outcomes of ``runs`` (``covariance``: the calibrated
    parameters', None without calibration).
    """
    s0 = _efficiency(outcomes[runs.point])
    stepped = zip(runs.parameter_runs, runs.steps, strict=True)
    c = np.array([(_efficiency(outcomes[r]) - s0) / h for r, h in stepped])
    u_par = math.sqrt(max(float(c @ covariance @ c), 0.0)) if covariance is not None and c.size else 0.0
    effects = {i.key: _efficiency(outcomes[r]) - s0 for i, r in zip(inputs, runs.input_runs, strict=True)}
    c_load = (_efficiency(outcomes[runs.load_run]) - s0) / runs.load_delta
    u_phase = 0.5 * abs(_efficiency(outcomes[runs.phase_run]) - s0) / SQRT3
    shared = [row for row in prepared.measured.budget if row["quantity"] in CONSTANT_OUTPUT_ERRORS]
    u_load = math.sqrt(sum((c_load * row["standard_uncertainty"]) ** 2 for row in shared))
    cov = sum(c_load * row["sensitivity"] * row["standard_uncertainty"] ** 2 for row in shared)
    u_inputs = math.sqrt(sum(e * e for e in effects.values()))
    u_input = math.sqrt(u_par**2 + u_inputs**2 + u_load**2 + u_phase**2)
    return Budget(prepared.measured.u, u_input, u_par, u_inputs, u_load, u_phase, float(cov),
                  {p.name: float(x) for p, x in zip(parameters, c, strict=True)}, effects, float(c_load))


def model_scatter(prepared: Prepared, engine: str, values: np.ndarray, covariance: np.ndarray | None,
                  parameters: tuple[Parameter, ...], inputs: Sequence[InputUncertainty], samples: int,
                  seed: int) -> list[ModelRun]:
    """``samples`` runs of recording ``prepared`` with the parameters drawn from N(values, covariance)
    (kept within the bounds) and each stated input from its distribution: the sampling check of
    ``u_parameters`` and ``u_inputs`` together.
    """
    rng = np.random.default_rng(seed)
    low = np.array([p.bounds[0] for p in parameters])
    high = np.array([p.bounds[1] for p in parameters])
    out = []
    for _ in range(samples):
        drawn = values
        if covariance is not None and len(parameters):
            drawn = np.clip(rng.multivariate_normal(values, covariance), low, high)
        changes = tuple((i.key, scene_value(prepared.scene, i.key) + _draw(rng, i)) for i in inputs)
        out.append(ModelRun(prepared.spec.index, engine, tuple(float(v) for v in drawn), changes))
    return out


def _draw(rng: np.random.Generator, item: InputUncertainty) -> float:
    """One draw of a stated input's error."""
    if item.distribution == "uniform":
        return float(rng.uniform(-SQRT3 * item.std, SQRT3 * item.std))
    return float(rng.normal(0.0, item.std))
