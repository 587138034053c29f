"""What a campaign returns (:class:`CampaignResult`): per recording the comparison error and its
validation uncertainty for each engine, the calibration, and the JSON that other tools read
(``results.json``; the key names are an interface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cardan_exudyn.jsonable import to_jsonable
from rigdata.campaign.budget import Budget
from rigdata.campaign.calibration import Calibration
from rigdata.campaign.spec import CampaignSpec

__all__ = ["EngineComparison", "RecordingResult", "CampaignResult", "TABLE_COLUMNS"]

TABLE_COLUMNS = ("label", "use", "shaft_angle_deg", "speed_in_rpm", "torque_in", "status", "simulated",
                 "measured", "comparison_error", "u_num", "u_input", "u_D", "u_val", "k",
                 "interval_low", "interval_high", "resolvable", "dominant")
"""The columns of :meth:`CampaignResult.table` and ``results.csv``."""


def _pair(interval: tuple[float, float] | None) -> list[float] | None:
    """An interval as a JSON list."""
    return list(interval) if interval is not None else None


@dataclass(frozen=True)
class EngineComparison:
    """One engine's simulated efficiency ``S`` against the measured ``D`` of one recording.

    ``comparison_error`` is ``E = S - D``; ``model_error_interval`` is ``E -+ k u_val`` (the model
    error ``delta_model`` lies in it with the stated coverage); ``resolvable`` when ``|E| > k u_val``.
    ``difference_from_first`` is ``S`` minus the first engine's ``S``. Values are None unless the run
    ended ``ok``.
    """

    engine: str
    status: str
    reason: str | None
    simulated: float | None
    u_num: float | None
    comparison_error: float | None = None
    u_val: float | None = None
    model_error_interval: tuple[float, float] | None = None
    resolvable: bool | None = None
    difference_from_first: float | None = None

    def as_dict(self) -> dict[str, Any]:
        """JSON fields."""
        return {"engine": self.engine, "status": self.status, "reason": self.reason,
                "simulated": self.simulated, "comparison_error": self.comparison_error,
                "u_num": self.u_num, "u_val": self.u_val,
                "model_error_interval": _pair(self.model_error_interval),
                "resolvable": self.resolvable, "difference_from_first": self.difference_from_first}


@dataclass(frozen=True)
class RecordingResult:
    """One recording of the campaign: measurement, budget and each engine's comparison.

    Attributes
    ----------
    index : int
    label : str
    file : Path
    sha256 : str
    use : {"calibration", "validation"}
    shaft_angle_deg : float
    status : str
        ``ok``; ``measurement`` (the data are unusable: no comparison); ``model`` (the first engine's
        run did not end ``ok``: reported, the campaign goes on).
    reason : str or None
    operating_point : dict
        :func:`rigdata.campaign.prepare.operating_point`.
    measured : float
        ``D`` [-].
    u_D : float
    findings : tuple of dict
        The measurement's checks.
    k : float
    budget : Budget or None
    engines : dict of str to EngineComparison
        In the campaign's engine order; the first is the one reported at the top level.
    provenance : dict
    monte_carlo : dict
        The Monte Carlo check of ``D``'s GUM uncertainty (``samples``, ``std``, ``interval_95``); empty
        without draws.
    """

    index: int
    label: str
    file: Path
    sha256: str
    use: str
    shaft_angle_deg: float
    status: str
    reason: str | None
    operating_point: dict[str, float]
    measured: float
    u_D: float
    findings: tuple[dict, ...]
    k: float
    budget: Budget | None = None
    engines: dict[str, EngineComparison] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)
    monte_carlo: dict[str, Any] = field(default_factory=dict)

    @property
    def first(self) -> EngineComparison | None:
        """The first engine's comparison."""
        return next(iter(self.engines.values()), None)

    @property
    def resolvable(self) -> bool | None:
        """``|E| > k u_val`` for the first engine (None without a comparison)."""
        return self.first.resolvable if self.first else None

    @property
    def dominant(self) -> str | None:
        """The largest of ``u_num``, ``u_input``, ``u_D`` (first engine)."""
        first = self.first
        if self.budget is None or first is None or first.u_num is None:
            return None
        return self.budget.dominant(first.u_num)

    def as_dict(self) -> dict[str, Any]:
        """One entry of ``recordings`` in ``results.json``."""
        first = self.first or EngineComparison("", "", None, None, None)
        return {"index": self.index, "label": self.label, "file": str(self.file), "sha256": self.sha256,
                "use": self.use, "shaft_angle_deg": self.shaft_angle_deg, "status": self.status,
                "reason": self.reason, "operating_point": self.operating_point,
                "simulated": first.simulated, "measured": self.measured,
                "comparison_error": first.comparison_error, "u_num": first.u_num,
                "u_input": self.budget.u_input if self.budget else None, "u_D": self.u_D,
                "u_val": first.u_val, "k": self.k,
                "model_error_interval": _pair(first.model_error_interval),
                "resolvable": first.resolvable, "dominant": self.dominant,
                "budget": self.budget.as_dict() if self.budget else None,
                "by_engine": {name: c.as_dict() for name, c in self.engines.items()},
                "checks": list(self.findings), "measured_monte_carlo": self.monte_carlo,
                "provenance": self.provenance}

    def row(self) -> dict[str, Any]:
        """One row of :meth:`CampaignResult.table`."""
        data = self.as_dict()
        interval = data["model_error_interval"] or [math.nan, math.nan]
        return {"label": self.label, "use": self.use, "shaft_angle_deg": self.shaft_angle_deg,
                "speed_in_rpm": self.operating_point.get("speed_in_rpm"),
                "torque_in": self.operating_point.get("torque_in"), "status": self.status,
                **{key: data[key] for key in ("simulated", "measured", "comparison_error", "u_num", "u_input",
                                              "u_D", "u_val", "k")},
                "interval_low": interval[0], "interval_high": interval[1], "resolvable": data["resolvable"],
                "dominant": data["dominant"]}


@dataclass(frozen=True)
class CampaignResult:
    """A whole campaign (what ``cardan rig campaign`` reports).

    Attributes
    ----------
    spec : CampaignSpec
    recordings : tuple of RecordingResult
        In the campaign file's order.
    calibration : Calibration or None
        None without ``[parameters]`` or when the fit failed (see ``calibration_error``).
    parameter_values : tuple of float
        The values every validation run used: calibrated, else initial.
    k : float
    calibration_error : str or None
    timing : dict
        Wall time [s] per stage, model runs made and reused.
    environment : dict
        Package versions.
    """

    spec: CampaignSpec
    recordings: tuple[RecordingResult, ...]
    calibration: Calibration | None
    parameter_values: tuple[float, ...]
    k: float
    calibration_error: str | None = None
    timing: dict[str, Any] = field(default_factory=dict)
    environment: dict[str, Any] = field(default_factory=dict)

    @property
    def validation(self) -> tuple[RecordingResult, ...]:
        """The validation recordings (never the calibration ones)."""
        return tuple(r for r in self.recordings if r.use == "validation")

    @property
    def resolvable(self) -> tuple[RecordingResult, ...]:
        """Validation recordings whose model error is resolvable: ``|E| > k u_val``."""
        return tuple(r for r in self.validation if r.resolvable)

    @property
    def failed(self) -> tuple[RecordingResult, ...]:
        """Recordings without a comparison (measurement unusable or model run not ``ok``)."""
        return tuple(r for r in self.recordings if r.status != "ok")

    def table(self) -> Any:
        """One row per recording (:data:`TABLE_COLUMNS`), a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame([r.row() for r in self.recordings], columns=list(TABLE_COLUMNS))

    def parameters(self) -> list[dict[str, Any]]:
        """``parameters`` of ``results.json``."""
        if self.calibration is None:
            return [{"name": p.name, "value": v, "standard_uncertainty": None, "identifiable": None,
                     "calibrated": False, "keys": list(p.keys), "bounds": list(p.bounds)}
                    for p, v in zip(self.spec.parameters, self.parameter_values, strict=True)]
        return [{"name": e.name, "value": e.value, "standard_uncertainty": e.standard_uncertainty,
                 "identifiable": e.identifiable, "at_bound": e.at_bound, "calibrated": True,
                 "keys": list(p.keys), "bounds": list(e.bounds)}
                for p, e in zip(self.spec.parameters, self.calibration.estimates, strict=True)]

    def as_dict(self) -> dict[str, Any]:
        """``results.json``: ``recordings``, ``parameters``, ``correlation``, ``calibration``, campaign."""
        spec = self.spec
        cal = self.calibration
        return to_jsonable({
            "campaign": {"file": str(spec.path) if spec.path else None, "title": spec.title,
                         "scene": spec.scene_source, "engines": list(spec.engines),
                         "coverage": spec.coverage, "k": self.k, "monte_carlo": spec.monte_carlo,
                         "seed": spec.seed, "input_samples": spec.input_samples,
                         "inputs": [{"key": i.key, "distribution": i.distribution, "std": i.std}
                                    for i in spec.inputs]},
            "recordings": [r.as_dict() for r in self.recordings],
            "parameters": self.parameters(),
            "correlation": cal.correlation.tolist() if cal is not None else None,
            "calibration": cal.as_dict() if cal is not None else None,
            "calibration_error": self.calibration_error,
            "summary": {"validation_recordings": len(self.validation),
                        "resolvable": [r.label for r in self.resolvable],
                        "failed": [r.label for r in self.failed]},
            "timing": self.timing, "environment": self.environment,
        })
