"""``cardan tolerance``: the command (:mod:`.command`), the paper's case (:mod:`.paper_case`),
the Monte Carlo study (:mod:`.montecarlo`) and their report folders (:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.tolerance.command",
    "montecarlo": "cardan_exudyn.studies.tolerance.montecarlo",
    "paper_case": "cardan_exudyn.studies.tolerance.paper_case",
    "report": "cardan_exudyn.studies.tolerance.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
