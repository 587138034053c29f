"""Validation campaigns: calibrate the unknown parameters on some recordings, validate on the others,
and state each model error with its whole uncertainty budget (ASME V&V 20). ``docs/rigdata.md``.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "rigdata.campaign.spec": ("CampaignError", "CampaignSpec", "Parameter", "InputUncertainty",
                              "RecordingSpec", "load_campaign", "campaign_from_mapping"),
    "rigdata.campaign.run": ("campaign", "coverage_factor"),
    "rigdata.campaign.result": ("CampaignResult", "RecordingResult", "EngineComparison"),
    "rigdata.campaign.calibration": ("Calibration", "Estimate", "CalibrationFailed"),
    "rigdata.campaign.budget": ("Budget",),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
