"""Measured efficiency of one rig record or file (``cardan rig measure``)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from rigdata.checks import (
    Finding,
    check_output_sign,
    efficiency_in_range,
    recorded_shaft_angle,
    revolutions_agree,
)
from rigdata.conditioning import Conditioned, Conditioning, condition
from rigdata.efficiency import Measured, measured_efficiency, transducer_pair
from rigdata.montecarlo import check_draws
from rigdata.readers import read
from rigdata.record import RigRecord, with_signs
from rigdata.transducer import Transducer

__all__ = ["Source", "as_record", "Measurement", "measure", "checked_angle_deg", "measurement_findings"]

Source = RigRecord | str | os.PathLike
"""A record, or a rig file to read."""


def as_record(source: Source, **read_options: Any) -> RigRecord:
    """``source`` if a record, else :func:`rigdata.readers.read` of it with ``read_options``."""
    if isinstance(source, RigRecord):
        if read_options:
            raise ValueError(f"read options {sorted(read_options)} apply to a file, not to a RigRecord")
        return source
    return read(source, **read_options)

@dataclass(frozen=True)
class Measurement:
    """The measured efficiency of one record (what ``cardan rig measure`` prints).

    Attributes
    ----------
    record : RigRecord
    conditioned : Conditioned
        Signals over the whole-revolution window and the input yoke phase.
    measured : Measured
    findings : tuple of Finding
        The plausibility checks (:mod:`rigdata.checks`); the measurement is a result only if all are ok.
    """

    record: RigRecord
    conditioned: Conditioned
    measured: Measured
    findings: tuple[Finding, ...] = ()

    @property
    def status(self) -> str:
        """``ok``, else the status of the first check that failed."""
        return next((f.status for f in self.findings if not f.ok), "ok")

    @property
    def reason(self) -> str | None:
        """The message of the first check that failed, None when ``ok``."""
        return next((f.message for f in self.findings if not f.ok), None)

    @property
    def efficiency(self) -> float:
        """Measured ``W_out / W_in`` over the window [-]."""
        return self.measured.efficiency

    @property
    def u(self) -> float:
        """Its combined standard uncertainty [-]."""
        return self.measured.u

    def as_dict(self) -> dict[str, Any]:
        """``cardan rig measure --json``: file, efficiency and uncertainty, input yoke phase [deg], synthetic
        flag.
        """
        return {"file": str(self.record.file), "status": self.status, "reason": self.reason,
                "checks": [f.as_dict() for f in self.findings], **self.measured.as_dict(),
                "phase_deg": math.degrees(self.conditioned.phase),
                "synthetic": bool(self.record.provenance.get("synthetic"))}


def checked_angle_deg(shaft_angle_deg: object) -> float | str:
    """``shaft_angle_deg`` in [0, 90) deg or ``"auto"``; TypeError/ValueError otherwise."""
    if shaft_angle_deg == "auto":
        return "auto"
    if isinstance(shaft_angle_deg, bool) or not isinstance(shaft_angle_deg, (int, float, np.number)):
        raise TypeError(f"`shaft_angle_deg` must be a number [deg] or 'auto', got {shaft_angle_deg!r:.80}")
    if not (math.isfinite(shaft_angle_deg) and 0.0 <= shaft_angle_deg < 90.0):
        raise ValueError(f"`shaft_angle_deg` must be in [0, 90) deg, got {shaft_angle_deg!r}")
    return float(shaft_angle_deg)


def measurement_findings(cond: Conditioned, measured: Measured, transducers: Any,
                         file: object = None) -> tuple[Finding, ...]:
    """The checks of a measured efficiency: RigDataError for a reversed output sign, else the findings on
    revolutions and range.
    """
    check_output_sign(measured, file)
    return (revolutions_agree(cond, transducer_pair(transducers)), efficiency_in_range(measured))


def measure(source: Source, shaft_angle_deg: float | str = 15.0, *, conditioning: Conditioning | None = None,
            transducers: Transducer | tuple[Transducer, Transducer] | None = None,
            monte_carlo: int = 2000, seed: int = 0, signs: dict[str, int] | None = None,
            **read_options: Any) -> Measurement:
    """Measured efficiency over whole input revolutions, with its uncertainty.

    Parameters
    ----------
    source : RigRecord, str or path-like
        A record or a rig file (read with ``read_options``, :func:`rigdata.readers.read`).
    shaft_angle_deg : float or "auto"
        Shaft angle [deg], for the yoke phase estimate; ``"auto"``: the recording's own.
    conditioning : Conditioning, optional
    transducers : Transducer or (input, output) pair, optional
        Default: the paper's (assumptions: :data:`rigdata.transducer.PROVENANCE`).
    monte_carlo : int
        Monte Carlo draws (0: GUM only).
    seed : int
        Seed of the draws.
    signs : dict of str to int, optional
        Sign convention: channel -> -1 to flip it (``{"torque_out": -1}``), :func:`rigdata.record.with_signs`.

    Returns
    -------
    Measurement
        With :attr:`Measurement.status` not ``ok`` when the revolutions or the range check fails.

    Raises
    ------
    RigDataError
        A file or record that cannot be measured, or whose output power is negative (sign convention).
    """
    angle = checked_angle_deg(shaft_angle_deg)
    check_draws(monte_carlo, seed)
    record = with_signs(as_record(source, **read_options), signs)
    beta = recorded_shaft_angle(record, conditioning) if angle == "auto" else math.radians(angle)
    cond = condition(record, beta, conditioning)
    measured = measured_efficiency(cond, transducers, monte_carlo=monte_carlo, seed=seed)
    return Measurement(record, cond, measured, measurement_findings(cond, measured, transducers, record.file))
