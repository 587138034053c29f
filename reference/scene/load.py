"""The output load of a scene: a constant resisting torque or its history."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.scene.histories import LinearHistory
from reference.scene.validation import SceneError, check_history, finite, float_array, is_sequence, set_field

__all__ = ["Load"]


@dataclass(frozen=True)
class Load:
    """Resisting torque on the output shaft [N m]; positive opposes positive output rotation.

    Attributes
    ----------
    torque : float or tuple of float
        A constant torque [N m], or with ``time`` one value per sample, linear in between (it never
        overshoots its samples) and held at the end values outside.
    time : tuple of float or None
        Sample times [s] of a history, strictly increasing, at least 2; it shares the scene's clock
        (:func:`reference.scene.histories.time_origin`).
    """

    torque: float | tuple = 0.0
    time: tuple | None = None

    def __post_init__(self) -> None:
        if self.time is None:
            if is_sequence(self.torque):
                raise SceneError("a torque history (`torque` as a list) needs `time`, one per value")
            set_field(self, "torque", finite("torque", self.torque))
            return
        t = float_array("load `time`", self.time)
        v = float_array("load `torque`", self.torque)
        check_history(t, v, self.time, self.torque, "torque", minimum=2, prefix="load ")
        set_field(self, "time", tuple(t.tolist()))
        set_field(self, "torque", tuple(v.tolist()))

    @property
    def constant(self) -> bool:
        """True for a constant torque, False for a history."""
        return self.time is None

    def at(self, t: Any) -> np.ndarray:
        """Load torque [N m] at the instants ``t`` [s] (any shape)."""
        if self.time is None:
            return np.full(np.shape(t), self.torque)
        return self.evaluator().at(t)

    def evaluator(self) -> LinearHistory | None:
        """A history at one instant in plain floats, O(log n) per call
        (:class:`reference.scene.histories.LinearHistory`); None when constant.
        """
        if self.time is None:
            return None
        cached = self.__dict__.get("_history")
        if cached is None:
            cached = LinearHistory(self.time, self.torque)
            object.__setattr__(self, "_history", cached)
        return cached

    def shifted(self, origin: float) -> Load:
        """The same load on a clock that reads ``t - origin`` [s] (a constant: itself)."""
        if self.time is None:
            return self
        return Load(self.torque, tuple((np.asarray(self.time) - origin).tolist()))

    @property
    def knots(self) -> np.ndarray:
        """Instants [s] where a history's slope changes (empty for a constant torque)."""
        return np.zeros(0) if self.time is None else self.evaluator().time

    def mean(self) -> float:
        """The constant torque, or the time average of the history [N m]."""
        if self.time is None:
            return float(self.torque)
        from scipy.integrate import trapezoid  # scipy.integrate takes ~0.5 s to import

        t = np.asarray(self.time)
        return float(trapezoid(np.asarray(self.torque), t) / (t[-1] - t[0]))
