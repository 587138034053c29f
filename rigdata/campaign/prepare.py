"""Each recording read, conditioned and measured once per campaign (:func:`prepare`); every model run
of the campaign reuses what it returns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.scene.mapping import replace
from reference.scene.scene import Scene
from rigdata.campaign.spec import CampaignSpec, RecordingSpec
from rigdata.checks import Finding, shaft_angle_agrees
from rigdata.conditioning import Conditioned, condition
from rigdata.efficiency import Measured, measured_efficiency
from rigdata.measurement import measurement_findings
from rigdata.readers import read
from rigdata.record import RigDataError, with_signs

__all__ = ["Prepared", "prepare", "operating_point"]


@dataclass(frozen=True)
class Prepared:
    """One recording, measured: what every model run of it starts from.

    Attributes
    ----------
    spec : RecordingSpec
    sha256 : str
        Of the file, so a changed file is never taken for the one measured before.
    conditioned : Conditioned
    measured : Measured
    findings : tuple of Finding
        The measurement's checks and the shaft angle's.
    scene : Scene
        The campaign's joint at this recording's shaft angle (drive and load not yet replaced).
    provenance : dict
        The reader's provenance (format, reader, synthetic label) without the raw header.
    """

    spec: RecordingSpec
    sha256: str
    conditioned: Conditioned
    measured: Measured
    findings: tuple[Finding, ...]
    scene: Scene
    provenance: dict[str, Any]

    @property
    def usable(self) -> bool:
        """False when the measurement is ``unphysical`` or ``inconsistent`` (an error in the data)."""
        return not any(f.status in ("unphysical", "inconsistent") for f in self.findings)


def operating_point(c: Conditioned) -> dict[str, float]:
    """Mean input speed [rad/s] and [rpm], mean input and output torque [N m] over the window."""
    inside = (c.t >= c.window[0]) & (c.t <= c.window[1])
    speed = float(np.mean(c.speed_in[inside]))
    return {"speed_in": speed, "speed_in_rpm": speed * 30.0 / math.pi,
            "torque_in": float(np.mean(c.torque_in[inside])),
            "torque_out": float(np.mean(c.torque_out[inside])), "revolutions": int(c.revolutions)}


def prepare(rec: RecordingSpec, campaign: CampaignSpec) -> Prepared:
    """Read, condition and measure recording ``rec``; RigDataError naming the campaign file and the
    recording if it cannot be.
    """
    where = f"{campaign.path}: {rec.where}" if campaign.path is not None else rec.where
    try:
        record = with_signs(read(rec.file, **rec.read), rec.signs)
    except ValueError as exc:  # RigDataError, or read() refusing a channel of `map`
        raise RigDataError(f"{where}: {exc}") from None
    beta = math.radians(rec.shaft_angle_deg)
    try:
        cond = condition(record, beta, campaign.conditioning)
        measured = measured_efficiency(cond, rec.transducers, monte_carlo=campaign.monte_carlo,
                                       seed=campaign.seed)
        findings = (*measurement_findings(cond, measured, rec.transducers, rec.file),
                    shaft_angle_agrees(cond, beta))
    except ValueError as exc:
        raise RigDataError(f"{where}: {exc}") from None
    scene = replace(campaign.scene, **{"joint.geometry.shaft_angle": beta})
    provenance = {k: v for k, v in record.provenance.items() if k not in ("header",)}
    return Prepared(rec, str(record.provenance.get("sha256", "")), cond, measured, findings, scene,
                    provenance)
