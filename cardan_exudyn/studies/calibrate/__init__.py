"""``cardan calibrate``: the command (:mod:`.command`), the paper's cases under parameter values
(:mod:`.fitting`), the fit (:mod:`.fit`), the envelope (:mod:`.envelope`) and the reports
(:mod:`.report`)."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "command": "cardan_exudyn.studies.calibrate.command",
    "envelope": "cardan_exudyn.studies.calibrate.envelope",
    "fit": "cardan_exudyn.studies.calibrate.fit",
    "fitting": "cardan_exudyn.studies.calibrate.fitting",
    "report": "cardan_exudyn.studies.calibrate.report",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
