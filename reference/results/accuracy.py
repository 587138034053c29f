"""How a run's estimate of its mean-efficiency error was made: :class:`RunAccuracy`.

The estimate itself and the verdict are the summary's common fields
(``efficiency_error_estimate``, ``accuracy_met``); this record says how they came about: the
target, the method, the a-priori model, the companion run the estimate compares with and the
pilot run that planned an automatic step. On disk it is the summary's ``accuracy`` table, with the
companion's fields flattened as ``companion_<field>`` and the pilot nested (``docs/outputs.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

__all__ = ["CompanionRun", "PilotRun", "RunAccuracy"]


@dataclass(frozen=True)
class CompanionRun:
    """The run at a coarser step that the main run's estimate compares with.

    Attributes
    ----------
    dt : float or None
        Its time step [s] (None: it never integrated, e.g. the loop did not close).
    status : str
        How it ended (a :class:`reference.results.summary.Status` value).
    mean_efficiency : float or None
        Its mean efficiency [-] (None unless it ended ``ok``).
    wall_time_s : float
        Its wall time [s].
    """

    dt: float | None
    status: str
    mean_efficiency: float | None
    wall_time_s: float


@dataclass(frozen=True)
class PilotRun:
    """The coarse run whose losses planned an automatic step.

    Attributes
    ----------
    dt : float or None
        Its time step [s].
    mean_efficiency : float or None
        Its mean efficiency [-] (None unless it ended ``ok``).
    wall_time_s : float
        Its wall time [s].
    is_companion : bool
        Whether it also served as the companion of the main run.
    """

    dt: float | None
    mean_efficiency: float | None
    wall_time_s: float
    is_companion: bool


@dataclass(frozen=True)
class RunAccuracy:
    """How a run's mean-efficiency error was estimated; a field is None where the run did not
    get that far (an automatic step without an estimate records only its pilot).

    Attributes
    ----------
    target : float or None
        The scene's ``numerics.accuracy`` [-].
    order : int or None
        Order of convergence of the mean efficiency in the step the estimate assumes [-].
    loss_fraction : float or None
        ``1 - mean_efficiency`` of the main run [-].
    steps_per_revolution : float or None
        The main run's steps per input revolution at the drive's top speed [-].
    model : float or None
        The a-priori error of the mean efficiency at those steps and losses [-].
    companion : CompanionRun or None
        The run at a coarser step the estimate compares with.
    richardson : float or None
        The Richardson estimate from the two runs [-] (None when the companion failed).
    method : str or None
        How the estimate was made, or why there is none, in one sentence.
    pilot : PilotRun or None
        The run that planned an automatic step.
    """

    target: float | None = None
    order: int | None = None
    loss_fraction: float | None = None
    steps_per_revolution: float | None = None
    model: float | None = None
    companion: CompanionRun | None = None
    richardson: float | None = None
    method: str | None = None
    pilot: PilotRun | None = None

    def to_dict(self) -> dict[str, Any]:
        """The summary's ``accuracy`` table: the fields that are set, in order, the companion's
        as ``companion_<field>``, the pilot as a nested table."""
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            if f.name == "companion":
                out.update({f"companion_{g.name}": getattr(value, g.name) for g in fields(value)})
            elif f.name == "pilot":
                out["pilot"] = {g.name: getattr(value, g.name) for g in fields(value)}
            else:
                out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunAccuracy | None:
        """Inverse of :meth:`to_dict`; None for a table with keys this version does not know."""
        own = {f.name for f in fields(cls)} - {"companion", "pilot"}
        companion = {f"companion_{f.name}": f.name for f in fields(CompanionRun)}
        if not set(data) <= own | set(companion) | {"pilot"}:
            return None
        values = {k: v for k, v in data.items() if k in own}
        if any(k in data for k in companion):
            values["companion"] = CompanionRun(**{name: data.get(key) for key, name in companion.items()})
        if data.get("pilot") is not None:
            values["pilot"] = PilotRun(**{f.name: data["pilot"].get(f.name) for f in fields(PilotRun)})
        return cls(**values)
