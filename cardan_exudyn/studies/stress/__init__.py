"""``cardan stress``: the command (:mod:`.command`), the map's panels (:mod:`.panels`), one cell
measured (:mod:`.cell`) and classified (:mod:`.classify`), the map (:mod:`.map`) and the report
folder (:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "cell": "cardan_exudyn.studies.stress.cell",
    "classify": "cardan_exudyn.studies.stress.classify",
    "command": "cardan_exudyn.studies.stress.command",
    "map": "cardan_exudyn.studies.stress.map",
    "panels": "cardan_exudyn.studies.stress.panels",
    "report": "cardan_exudyn.studies.stress.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
