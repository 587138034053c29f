"""The summary every engine reports about a run: :class:`Summary`, its :class:`Status` and its JSON
shape on disk (:data:`SCHEMA_VERSION`). Means are those of the direction the power flows.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from enum import Enum
from typing import Any

import numpy as np

from reference.results.accuracy import RunAccuracy
from reference.results.friction_diagnostics import FrictionDiagnostics
from reference.results.means import mean_values
from reference.results.power_flow import PowerFlow, classify_works

__all__ = ["SCHEMA_VERSION", "Status", "OptionsError", "MEAN_KEYS", "FLOW_KEYS", "RECORD_FIELDS", "Summary"]

SCHEMA_VERSION = 3
"""Version of the summary written to disk (``summary.json``, sweep records): 2 adds
``schema_version`` and writes every common key (``null`` where a run has no value); 3 adds
``power_flow``, ``power_reversals``, ``warnings``, ``efficiency_error_estimate`` and
``accuracy_met``, takes the efficiencies in the direction the
power flows, and never writes one outside [0, 1] with status ``ok`` (status ``unphysical``).
:meth:`Summary.from_dict` reads 1 and 2 and applies version 3's rules to their works."""


class Status(str, Enum):
    """How a run ended; only :attr:`OK` carries mean values, every other status has a ``reason``.
    A ``str`` enum: ``Status.OK == "ok"`` and JSON writes the plain value.
    """

    OK = "ok"
    SELF_LOCKING = "self_locking"  # friction has no consistent value (loop gain >= 1)
    INTEGRATION_FAILURE = "integration_failure"  # the solver stopped (Newton, step size)
    DIVERGED = "diverged"  # the solver finished but produced non-finite values
    INCOMPLETE = "incomplete"  # a torque drive did not turn the asked revolutions in time
    NO_WHOLE_REVOLUTION = "no_whole_revolution"  # nothing to average over after the skip
    LOOP_DOES_NOT_CLOSE = "loop_does_not_close"  # mounting errors the loop cannot assemble with
    CONSTRAINT_VIOLATED = "constraint_violated"  # a soft constraint (MuJoCo) left its tolerance
    UNPHYSICAL = "unphysical"  # means no physical run can have (an efficiency outside [0, 1])

    def __str__(self) -> str:
        return self.value


class OptionsError(ValueError):
    """An engine's options are out of range or of the wrong type (the message names the option)."""


MEAN_KEYS = ("revolutions", "window_start_s", "window_duration_s", "input_work", "output_work",
             "loss_work", "mean_efficiency", "mean_instantaneous_efficiency", "work_ratio",
             "mean_torque_in", "mean_speed_in")
FLOW_KEYS = ("power_flow", "power_reversals")
"""Keys of the power flow over the window (:mod:`reference.results.power_flow`), set and cleared
with the means."""


_RECORDS: dict[str, Any] = {"friction": FrictionDiagnostics, "accuracy": RunAccuracy}
RECORD_FIELDS = tuple(_RECORDS)
"""The summary's typed records of a time-stepping engine's run, each a table of its own on disk,
written only when the run has it (engine-specific, like :attr:`Summary.extras`)."""


@dataclass
class Summary:
    """What every engine reports about a run, the same fields for every engine, in :meth:`to_dict`'s order.

    Attributes
    ----------
    status : Status
    reason : str
        Why the run did not end ``ok`` (empty when it did).
    engine, engine_version : str
    scene, options : dict
        The scene (:func:`reference.scene.mapping.scene_to_dict`) and the engine's options.
    wall_time_s : float
        Wall time of the whole run [s].
    dt, dt_choice : float or None, str or None
        Time step [s] (the reference engine: the table's sample spacing) and how it was chosen.
    steps, newton_iterations, jacobian_evaluations, ode_evaluations : int or None
        Cost counters (None where an engine has none).
    max_constraint_violation_m, max_constraint_violation_rad : float or None
        Largest violation of the pair constraints over the run [m], [rad].
    max_friction_loop_gain : float or None
        Largest gain of the friction feedback loop (>= 1: no consistent friction).
    efficiency_error_estimate : float or None
        Estimated absolute error of ``mean_efficiency`` [-] (Exudyn: Richardson from a coarser
        companion run; reference: its quadrature's estimate).
    accuracy_met : bool or None
        Estimate within ``numerics.accuracy``; ``cardan run`` exits 5 when False (``docs/accuracy.md``).
    revolutions : int
        Whole input revolutions averaged over.
    window_start_s, window_duration_s : float or None
        The averaging window [s].
    input_work, output_work, loss_work : float or None
        Works over the window [J].
    mean_efficiency : float or None
        One minus lost over supplied work in [0, 1] (input work, or ``-output_work`` when power flows
        from the output); 0 when no shaft takes net work; None (with a warning) when nothing is
        transmitted or lost.
    mean_instantaneous_efficiency : float or None
        Time average of eq. (18) for the direction of ``power_flow``; None, with a warning, where
        the source power changes sign within the window or the average is outside [0, 1].
    work_ratio : float or None
        Received over supplied work.
    mean_torque_in, mean_speed_in : float or None
        Input work over input angle [N m], input angle over time [rad/s].
    power_flow : str or None
        ``input_to_output``, ``output_to_input`` or ``none``
        (:class:`reference.results.power_flow.PowerFlow`).
    power_reversals : int or None
        Sign changes of the source power within the window (table rows).
    pair_loss_work, pair_sliding_loss_work : dict[str, float]
        Loss work per pair and its axial-friction part [J] (``loss_work_<pair>[_sliding]`` on disk).
    warnings : list of str
        What a reader of the means must know.
    friction : FrictionDiagnostics or None
        The friction coupling's counters and loop gains (Exudyn with friction).
    extras : dict
        Engine-specific diagnostics (the reference's ``quadrature``, ...), top level of the JSON.
    accuracy : RunAccuracy or None
        How :attr:`efficiency_error_estimate` was made (Exudyn).
    """

    status: Status
    reason: str = ""
    engine: str = ""
    engine_version: str = ""
    scene: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = math.nan
    dt: float | None = None
    dt_choice: str | None = None
    steps: int | None = None
    newton_iterations: int | None = None
    jacobian_evaluations: int | None = None
    ode_evaluations: int | None = None
    max_constraint_violation_m: float | None = None
    max_constraint_violation_rad: float | None = None
    max_friction_loop_gain: float | None = None
    efficiency_error_estimate: float | None = None
    accuracy_met: bool | None = None
    revolutions: int = 0
    window_start_s: float | None = None
    window_duration_s: float | None = None
    input_work: float | None = None
    output_work: float | None = None
    loss_work: float | None = None
    mean_efficiency: float | None = None
    mean_instantaneous_efficiency: float | None = None
    work_ratio: float | None = None
    mean_torque_in: float | None = None
    mean_speed_in: float | None = None
    power_flow: str | None = None
    power_reversals: int | None = None
    pair_loss_work: dict[str, float] = field(default_factory=dict)
    pair_sliding_loss_work: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    friction: FrictionDiagnostics | None = None
    extras: dict[str, Any] = field(default_factory=dict)
    accuracy: RunAccuracy | None = None

    def __post_init__(self) -> None:
        self.status = Status(self.status)

    @property
    def success(self) -> bool:
        """True when the run ended ``ok`` (its means are defined)."""
        return self.status is Status.OK

    def set_means(self, means: Mapping[str, Any]) -> None:
        """Take the keys of :func:`mean_values` (or the same keys from another integration)."""
        for key, value in means.items():
            if key in MEAN_KEYS or key in FLOW_KEYS:
                setattr(self, key, value)
            elif key == "warnings":
                self.warn(*value)
            elif key.startswith("loss_work_") and key.endswith("_sliding"):
                self.pair_sliding_loss_work[key[len("loss_work_"):-len("_sliding")]] = value
            elif key.startswith("loss_work_"):
                self.pair_loss_work[key[len("loss_work_"):]] = value
            else:
                self.extras[key] = value

    def whole_revolution_means(self, columns: Mapping[str, np.ndarray], skip_revolutions: float,
                               works: Mapping[str, float] | None = None) -> dict[str, Any] | None:
        """:func:`~reference.results.means.mean_values` of ``columns`` after ``skip_revolutions`` (with the
        window's better ``works``); None, with status and reason set, when there is no whole revolution or
        the means are ``unphysical``. Their warnings join :attr:`warnings` either way.
        """
        means = mean_values(columns, skip_revolutions, works)
        if means["revolutions"] < 1:
            self.fail(Status.NO_WHOLE_REVOLUTION, means["mean_status"])
            return None
        self.warn(*means.pop("warnings"))
        problem = means.pop("unphysical")
        if problem:
            self.fail(Status.UNPHYSICAL, problem)
            return None
        return means

    def warn(self, *messages: str) -> None:
        """Add ``messages`` to :attr:`warnings` (each once)."""
        self.warnings.extend(m for m in dict.fromkeys(messages) if m not in self.warnings)

    def clear_means(self) -> None:
        """Forget the means (a run that turned out not ``ok`` after averaging)."""
        for key in MEAN_KEYS + FLOW_KEYS:
            setattr(self, key, 0 if key == "revolutions" else None)
        self.pair_loss_work.clear()
        self.pair_sliding_loss_work.clear()

    def fail(self, status: Status | str, reason: str) -> None:
        """End the run with ``status`` (not ``ok``) and a one-sentence ``reason``, forgetting its means."""
        self.status = Status(status)
        self.reason = reason
        self.clear_means()

    def to_dict(self) -> dict[str, Any]:
        """The JSON shape written to disk: flat keys, ``schema_version`` first."""
        out: dict[str, Any] = {"schema_version": SCHEMA_VERSION}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "status":
                out["status"] = value.value
            elif f.name == "pair_loss_work":
                out.update({f"loss_work_{p}": v for p, v in value.items()})
            elif f.name == "pair_sliding_loss_work":
                out.update({f"loss_work_{p}_sliding": v for p, v in value.items()})
            elif f.name == "extras":
                out.update(value)
            elif f.name in _RECORDS:
                if value is not None:
                    out[f.name] = value.to_dict()
            else:
                out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Summary:
        """Inverse of :meth:`to_dict`; reads schema versions 1 and 2 too, re-deriving their efficiencies
        (:meth:`upgrade`). ``accuracy`` or ``friction`` tables with unknown keys stay in :attr:`extras`.
        """
        names = {f.name for f in fields(cls)} - {"pair_loss_work", "pair_sliding_loss_work", "extras",
                                                 *_RECORDS}
        summary = cls(status=Status(data["status"]))
        for key, value in data.items():
            if key == "schema_version":
                continue
            record = None
            if key in _RECORDS and isinstance(value, Mapping):
                record = _RECORDS[key].from_dict(value)
            if record is not None:
                setattr(summary, key, record)
            elif key in _RECORDS:  # a shape this version does not know: kept unchanged
                summary.extras[key] = value
            elif key in names:
                setattr(summary, key, list(value) if key == "warnings" else value)
            else:
                summary.set_means({key: value})
        summary.status = Status(summary.status)
        if data.get("schema_version", 1) < 3:
            summary.upgrade()
        return summary

    def upgrade(self) -> None:
        """Schema version 3's rules on an ``ok`` version 1 or 2 summary with its three works: power flow,
        efficiencies, ``unphysical`` out of [0, 1]; the eq. (18) average is kept only within [0, 1].
        """
        works = (self.input_work, self.output_work, self.loss_work)
        if not self.success or any(w is None for w in works):
            return
        verdict = classify_works(*works)
        if verdict.problem:
            self.fail(Status.UNPHYSICAL, verdict.problem)
            return
        self.power_flow = None if verdict.power_flow is None else verdict.power_flow.value
        self.mean_efficiency = verdict.mean_efficiency
        self.work_ratio = verdict.work_ratio
        self.warn(*[verdict.note] if verdict.note else [])
        eta = self.mean_instantaneous_efficiency
        if eta is not None and not (verdict.power_flow == PowerFlow.INPUT_TO_OUTPUT and 0.0 <= eta <= 1.0):
            self.mean_instantaneous_efficiency = None
            self.warn(f"the time average of eq. (18) read from a version-2 summary ({eta:.6g}) "
                      "is not reported: it may span a reversal of the power flow")
