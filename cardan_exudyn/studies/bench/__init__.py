"""``cardan bench``: the command (:mod:`.command`), the default scenes and the engine
configurations (:mod:`.configs`), the runs (:mod:`.ladders`), the whole bench and its reading
(:mod:`.result`) and the results folder (:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.bench.command",
    "configs": "cardan_exudyn.studies.bench.configs",
    "ladders": "cardan_exudyn.studies.bench.ladders",
    "report": "cardan_exudyn.studies.bench.report",
    "result": "cardan_exudyn.studies.bench.result",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
