"""Solver settings of the Exudyn engine (:class:`ExudynOptions`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from reference.results.summary import OptionsError
from reference.scene.scene import Scene

__all__ = ["ExudynOptions", "NODE_TYPES", "SENSOR_SCOPES"]

NODE_TYPES = ("Rxyz", "EP", "RotVecLG")
SENSOR_SCOPES = ("auto", "all")


@dataclass(frozen=True)
class ExudynOptions:
    """Solver settings of the Exudyn engine.

    Attributes
    ----------
    spectral_radius : float
        Generalized-alpha spectral radius at infinity, in [0, 1); lower damps more.
    modified_newton : bool
        Modified Newton (Jacobian reused) instead of full Newton.
    jacobian_every_step : bool
        With modified Newton: a Jacobian at the start of every step, not only when it stalls.
    newton_relative_tolerance, newton_absolute_tolerance : float
        Newton tolerances (relative to the initial residual, and absolute).
    node_type : str
        Node of spider and output: ``"Rxyz"`` (Tait-Bryan), ``"EP"`` (Euler parameters) or
        ``"RotVecLG"`` (rotation vector, Lie group; spectral radius <= 0.8).
    sensors : str
        ``"auto"``: pair reactions recorded only when read afterwards; ``"all"``: always.
    velocity_projection : bool
        Velocities projected onto the velocity constraints (post-processing): exact speed ratio for
        a prescribed input; torques, reactions and friction keep the integrator's error.
    error_estimate : bool
        With friction, the pilot and companion runs that choose the step and estimate the mean
        efficiency's error; False: no companion and no estimate.
    """

    spectral_radius: float = 0.6
    modified_newton: bool = False
    jacobian_every_step: bool = False
    newton_relative_tolerance: float = 1e-10
    newton_absolute_tolerance: float = 1e-10
    node_type: str = "Rxyz"
    sensors: str = "auto"
    velocity_projection: bool = False
    error_estimate: bool = True

    def __post_init__(self) -> None:
        for name in ("modified_newton", "jacobian_every_step", "velocity_projection", "error_estimate"):
            if not isinstance(getattr(self, name), bool):
                raise OptionsError(f"`{name}` must be true or false, got {getattr(self, name)!r}")
        if not 0.0 <= self.spectral_radius < 1.0:
            raise OptionsError(f"`spectral_radius` must be in [0, 1), got {self.spectral_radius!r}")
        for name in ("newton_relative_tolerance", "newton_absolute_tolerance"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and 0.0 < value < 1.0):
                raise OptionsError(f"`{name}` must be in (0, 1), got {value!r}")
        if self.node_type not in NODE_TYPES:
            raise OptionsError(f"`node_type` must be one of {list(NODE_TYPES)}, got {self.node_type!r}")
        if self.node_type == "RotVecLG" and self.spectral_radius > 0.8:
            # measured: docs/engines.md#exudyn-model-measurements
            raise OptionsError(f"`spectral_radius` must be <= 0.8 with node_type 'RotVecLG', got "
                             f"{self.spectral_radius!r}")
        if self.sensors not in SENSOR_SCOPES:
            raise OptionsError(f"`sensors` must be one of {list(SENSOR_SCOPES)}, got {self.sensors!r}")

    def to_dict(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}

    def records_reactions(self, scene: Scene) -> bool:
        """Whether a run of ``scene`` records the pair reactions: ``sensors="all"``, a time table, or
        ``uncoupled`` friction (evaluated afterwards on them)."""
        uncoupled = scene.has_friction and scene.friction.coupling == "uncoupled"
        return self.sensors == "all" or scene.record.timeseries or uncoupled
