"""``cardan reproduce``: the command (:mod:`.command`), the runs (:mod:`.compute`) and the report
(:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.reproduce.command",
    "compute": "cardan_exudyn.studies.reproduce.compute",
    "report": "cardan_exudyn.studies.reproduce.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
