"""The input drives of a scene: constant speed, an angle history, or a constant torque."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Union

import numpy as np

from reference.scene.histories import CubicPieces, first_turn, largest_slope
from reference.scene.validation import SceneError, check_history, finite, float_array, set_field

__all__ = ["DRIVES", "AngleDrive", "Drive", "SpeedDrive", "TorqueDrive"]


@dataclass(frozen=True)
class SpeedDrive:
    """Input shaft held at constant angular speed ``speed`` [rad/s] (non-zero), from angle 0."""

    speed: float
    kind: str = field(default="speed", init=False)

    def __post_init__(self) -> None:
        speed = finite("speed", self.speed)
        if speed == 0.0:
            raise SceneError("`speed` of a constant-speed drive must be non-zero, got 0.0")
        set_field(self, "speed", speed)

    def max_speed(self) -> float:
        """The drive's speed magnitude [rad/s]."""
        return abs(self.speed)


@dataclass(frozen=True)
class AngleDrive:
    """Input angle prescribed by a history, interpolated by a C2 cubic spline: ``time`` [s] strictly
    increasing, at least 4 samples (any start: engines run on :func:`reference.scene.histories.run_clock`),
    ``angle`` [rad].
    """

    time: tuple
    angle: tuple
    kind: str = field(default="angle", init=False)

    def __post_init__(self) -> None:
        t = float_array("`time`", self.time)
        a = float_array("`angle`", self.angle)
        check_history(t, a, self.time, self.angle, "angle", minimum=4)
        set_field(self, "time", tuple(t.tolist()))
        set_field(self, "angle", tuple(a.tolist()))

    def spline(self) -> Any:
        """The history as a cached ``CubicSpline``: angle [rad] of time [s]."""
        cached = self.__dict__.get("_spline")
        if cached is None:
            from scipy.interpolate import CubicSpline  # scipy.interpolate takes ~1 s to import

            cached = CubicSpline(np.asarray(self.time), np.asarray(self.angle))
            object.__setattr__(self, "_spline", cached)
        return cached

    def evaluator(self) -> CubicPieces:
        """The spline at one instant in plain floats, O(log n) per call
        (:class:`reference.scene.histories.CubicPieces`).
        """
        return CubicPieces(self.spline())

    def shifted(self, origin: float) -> AngleDrive:
        """The same history on a clock that reads ``t - origin`` [s]."""
        return AngleDrive(tuple((np.asarray(self.time) - origin).tolist()), self.angle)

    def max_speed(self) -> float:
        """Largest input speed of the history [rad/s] (exact, from the spline's pieces)."""
        return largest_slope(self.spline())

    def time_to_turn(self, angle: float) -> float:
        """First time [s] the input has turned ``angle`` [rad] either way from its start; the last time if
        it never does.
        """
        t = first_turn(self.spline(), angle)
        return float(self.time[-1]) if t is None else t


@dataclass(frozen=True)
class TorqueDrive:
    """Constant ``torque`` [N m] on the input shaft about its axis, free speed, from a non-zero
    ``initial_speed`` [rad/s] (so the span in revolutions is finite).
    """

    torque: float
    initial_speed: float
    kind: str = field(default="torque", init=False)

    def __post_init__(self) -> None:
        set_field(self, "torque", finite("torque", self.torque))
        speed = finite("initial_speed", self.initial_speed)
        if speed == 0.0:
            raise SceneError("`initial_speed` of a torque drive must be non-zero, got 0.0")
        set_field(self, "initial_speed", speed)

    def max_speed(self) -> float:
        """The initial speed's magnitude [rad/s] (the speed engines size their steps for)."""
        return abs(self.initial_speed)

    def time_allowed(self, angle: float) -> float:
        """Time [s] every engine allows to turn ``angle`` [rad]: four times the time at the initial speed
        (the joint may decelerate).
        """
        return 4.0 * angle / abs(self.initial_speed)


Drive = Union[SpeedDrive, AngleDrive, TorqueDrive]  # noqa: UP007 (runtime alias, py3.10)
DRIVES = {"speed": SpeedDrive, "angle": AngleDrive, "torque": TorqueDrive}
