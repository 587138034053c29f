"""How a run's estimate of its mean-efficiency error was made: :class:`RunAccuracy`, the summary's
``accuracy`` table (companion fields flattened as ``companion_<field>``, the pilot nested;
``docs/outputs.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

__all__ = ["CompanionRun", "PilotRun", "RunAccuracy"]


@dataclass(frozen=True)
class CompanionRun:
    """The coarser-step run the estimate compares with: ``dt`` [s] (None: it never integrated),
    ``status``, ``mean_efficiency`` [-] (None unless ``ok``), ``wall_time_s`` [s].
    """

    dt: float | None
    status: str
    mean_efficiency: float | None
    wall_time_s: float


@dataclass(frozen=True)
class PilotRun:
    """The coarse run that planned an automatic step: ``dt`` [s], ``mean_efficiency`` [-] (None unless
    ``ok``), ``wall_time_s`` [s], ``is_companion`` (it also served as companion).
    """

    dt: float | None
    mean_efficiency: float | None
    wall_time_s: float
    is_companion: bool


@dataclass(frozen=True)
class RunAccuracy:
    """How a run's mean-efficiency error was estimated; a field is None where the run did not get
    that far.

    Attributes
    ----------
    target : float or None
        The scene's ``numerics.accuracy`` [-].
    order : int or None
        Order of convergence in the step the estimate assumes [-].
    loss_fraction : float or None
        ``1 - mean_efficiency`` of the main run [-].
    steps_per_revolution : float or None
        Steps per input revolution at the drive's top speed [-].
    model : float or None
        The a-priori error at those steps and losses [-].
    companion : CompanionRun or None
    richardson : float or None
        The Richardson estimate from the two runs [-] (None when the companion failed).
    method : str or None
        How the estimate was made, or why there is none, in one sentence.
    pilot : PilotRun or None
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
        """The summary's ``accuracy`` table: the set fields in order, the companion's as
        ``companion_<field>``, the pilot nested.
        """
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
