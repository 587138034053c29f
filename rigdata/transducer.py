"""The rig's torque/speed transducers and acquisition: the numbers the uncertainty rests on.

Full scale, sensitivity and pulses per revolution are the paper's (section 4.2); accuracy, drift
and noise are assumptions, each a parameter.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

__all__ = ["FULL_SCALE", "SENSITIVITY", "PULSES_PER_REV", "PROVENANCE", "Transducer"]

FULL_SCALE = 100.0
"""Rated torque of the Magtrol TMB 210 [N m] (paper, section 4.2)."""
SENSITIVITY = 0.1
"""Torque output of the Magtrol TMB 210 [V/(N m)]: 100 mV/(N m) (paper, section 4.2)."""
PULSES_PER_REV = 60
"""Pulses per revolution of the Magtrol TMB 210 speed output (paper, section 4.2)."""

#: Where each default comes from.
PROVENANCE = {
    "full_scale": "paper section 4.2: Magtrol TMB 210, max torque 100.00 N m",
    "sensitivity": "paper section 4.2: torque sensitivity 100 mV/N m",
    "pulses_per_rev": "paper section 4.2: speed sensitivity 60 pulses per rev",
    "accuracy_class": "assumption: accuracy class 0.1 % of full scale (the class of in-line torque "
                      "transducers of this size; with it the class alone is half of a 0.2 N m reading); "
                      "a limit, read as a rectangular distribution",
    "zero_drift": "assumption: zero drift over one record within +-0.01 N m (0.01 % of full scale: "
                  "a temperature change of about 1 K in a run of seconds at 0.1 %/10 K); a limit "
                  "of a linear ramp over the record, rectangular",
    "speed_accuracy": "assumption: a speed channel (rpm or rad/s, an analogue or converted speed output) "
                      "reads within 0.1 % of reading (a gain error), a limit, rectangular; a pulse count's "
                      "gain is its time base's and its error is the count's quantisation instead",
    "adc_range": "assumption: +-10 V input range of the acquisition card",
    "adc_bits": "assumption: 16-bit acquisition card",
}


@dataclass(frozen=True)
class Transducer:
    """One torque/speed transducer with its acquisition channel.

    Attributes
    ----------
    full_scale : float
        Rated torque [N m].
    sensitivity : float
        Torque output [V/(N m)].
    pulses_per_rev : int
        Speed pulses per revolution [-].
    accuracy_class : float
        Limit of the constant torque error as a fraction of full scale [-], independent per transducer.
    zero_drift : float
        Limit of the zero's drift over a record [N m], a linear ramp from zero.
    speed_accuracy : float
        Limit of a speed channel's gain error as a fraction of reading [-] (not of pulse counts).
    adc_range : float
        Acquisition input range +- [V].
    adc_bits : int
        Acquisition resolution [bit].
    """

    full_scale: float = FULL_SCALE
    sensitivity: float = SENSITIVITY
    pulses_per_rev: int = PULSES_PER_REV
    accuracy_class: float = 1e-3
    zero_drift: float = 0.01
    speed_accuracy: float = 1e-3
    adc_range: float = 10.0
    adc_bits: int = 16

    def __post_init__(self) -> None:
        for name in ("full_scale", "sensitivity", "adc_range"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"`{name}` must be a positive number, got {value!r}")
        for name in ("accuracy_class", "zero_drift", "speed_accuracy"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError(f"`{name}` must be a number >= 0, got {value!r}")
        for name, top in (("pulses_per_rev", 1_000_000), ("adc_bits", 32)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= top:
                raise ValueError(f"`{name}` must be an integer in [1, {top}], got {value!r:.40}")
        # an error class above 100 % of full scale, or a drift or full scale beyond any torque
        # transducer, is a typing error (and overflows the uncertainty budget's squares)
        if self.accuracy_class > 1.0:
            raise ValueError(f"`accuracy_class` must be at most 1 (100 % of full scale), "
                             f"got {self.accuracy_class!r}")
        if self.speed_accuracy > 1.0:
            raise ValueError(f"`speed_accuracy` must be at most 1 (100 % of reading), "
                             f"got {self.speed_accuracy!r}")
        for name in ("full_scale", "zero_drift", "adc_range"):
            if getattr(self, name) > 1e8:
                raise ValueError(f"`{name}` must be at most 1e8, got {getattr(self, name)!r}")
        if self.sensitivity < 1e-12:
            raise ValueError(f"`sensitivity` must be at least 1e-12 V/(N m), got {self.sensitivity!r}")

    @property
    def accuracy_limit(self) -> float:
        """Limit of the torque error from the accuracy class [N m]."""
        return self.accuracy_class * self.full_scale

    @property
    def pulse_angle(self) -> float:
        """Angle between two speed pulses [rad]."""
        return 2.0 * math.pi / self.pulses_per_rev

    @property
    def adc_step(self) -> float:
        """One acquisition step in torque [N m]."""
        return 2.0 * self.adc_range / 2 ** self.adc_bits / self.sensitivity

    def as_dict(self) -> dict:
        """The settings as a JSON-ready dict."""
        return asdict(self)
