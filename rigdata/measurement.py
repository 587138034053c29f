"""Measured efficiency of one rig record or file (``cardan rig measure``)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from rigdata.conditioning import Conditioned, Conditioning, condition
from rigdata.efficiency import Measured, measured_efficiency
from rigdata.montecarlo import check_draws
from rigdata.readers import read
from rigdata.record import RigRecord
from rigdata.transducer import Transducer

__all__ = ["Source", "as_record", "Measurement", "measure"]

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
    """

    record: RigRecord
    conditioned: Conditioned
    measured: Measured

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
        return {"file": str(self.record.file), **self.measured.as_dict(),
                "phase_deg": math.degrees(self.conditioned.phase),
                "synthetic": bool(self.record.provenance.get("synthetic"))}


def measure(source: Source, shaft_angle_deg: float = 15.0, *, conditioning: Conditioning | None = None,
            transducers: Transducer | tuple[Transducer, Transducer] | None = None,
            monte_carlo: int = 2000, seed: int = 0, **read_options: Any) -> Measurement:
    """Measured efficiency over whole input revolutions, with its uncertainty.

    Parameters
    ----------
    source : RigRecord, str or path-like
        A record or a rig file (read with ``read_options``, :func:`rigdata.readers.read`).
    shaft_angle_deg : float
        Shaft angle [deg], for the yoke phase estimate.
    conditioning : Conditioning, optional
    transducers : Transducer or (input, output) pair, optional
        Default: the paper's (assumptions: :data:`rigdata.transducer.PROVENANCE`).
    monte_carlo : int
        Monte Carlo draws (0: GUM only).
    seed : int
        Seed of the draws.

    Raises
    ------
    RigDataError
        A file or record that cannot be measured.
    """
    if isinstance(shaft_angle_deg, bool) or not isinstance(shaft_angle_deg, (int, float, np.number)):
        raise TypeError(f"`shaft_angle_deg` must be a number [deg], got {shaft_angle_deg!r:.80}")
    if not (math.isfinite(shaft_angle_deg) and 0.0 <= shaft_angle_deg < 90.0):
        raise ValueError(f"`shaft_angle_deg` must be in [0, 90) deg, got {shaft_angle_deg!r}")
    check_draws(monte_carlo, seed)
    record = as_record(source, **read_options)
    cond = condition(record, math.radians(shaft_angle_deg), conditioning)
    measured = measured_efficiency(cond, transducers, monte_carlo=monte_carlo, seed=seed)
    return Measurement(record, cond, measured)
