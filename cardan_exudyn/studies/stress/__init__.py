"""``cardan stress``."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.stress.command",
    "longrun": "cardan_exudyn.studies.stress.longrun",
    "longrun_measures": "cardan_exudyn.studies.stress.longrun_measures",
    "longrun_plan": "cardan_exudyn.studies.stress.longrun_plan",
    "longrun_report": "cardan_exudyn.studies.stress.longrun_report",
    "longrun_summary": "cardan_exudyn.studies.stress.longrun_summary",
    "map": "cardan_exudyn.studies.stress.map",
    "report": "cardan_exudyn.studies.stress.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
