"""``cardan bench``."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "audit": "cardan_exudyn.studies.bench.audit",
    "batch": "cardan_exudyn.studies.bench.batch",
    "command": "cardan_exudyn.studies.bench.command",
    "configs": "cardan_exudyn.studies.bench.configs",
    "ladders": "cardan_exudyn.studies.bench.ladders",
    "report": "cardan_exudyn.studies.bench.report",
    "result": "cardan_exudyn.studies.bench.result",
    "startup": "cardan_exudyn.studies.bench.startup",
    "targets": "cardan_exudyn.studies.bench.targets",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
