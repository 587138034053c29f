"""Synthetic rig files, labelled as such: the reference engine's joint measured by a model of the
rig's transducers (:mod:`rigdata.synthetic.rig`), and validation campaigns of them
(:mod:`rigdata.synthetic.campaign`).
"""

from __future__ import annotations

from rigdata.synthetic.campaign import CAMPAIGN_TRANSDUCER, DEFAULT_POINTS, write_campaign
from rigdata.synthetic.rig import (
    EXTENSIONS,
    FORMATS,
    GENERATOR,
    MAX_SAMPLES,
    RigSettings,
    Truth,
    joint_scene,
    measure,
    metadata,
    motor_angle,
    record,
    true_signals,
    write,
)

__all__ = ["GENERATOR", "FORMATS", "EXTENSIONS", "MAX_SAMPLES", "RigSettings", "Truth", "motor_angle",
           "true_signals", "measure", "joint_scene", "metadata", "record", "write", "write_campaign",
           "CAMPAIGN_TRANSDUCER", "DEFAULT_POINTS"]
