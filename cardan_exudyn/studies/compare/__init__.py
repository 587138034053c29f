"""``cardan compare``: the command (:mod:`.command`) and its report folder (:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.compare.command",
    "report": "cardan_exudyn.studies.compare.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
