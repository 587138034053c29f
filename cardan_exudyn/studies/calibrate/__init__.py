"""``cardan calibrate``."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "compute": "cardan_exudyn.studies.calibrate.compute",
    "envelope": "cardan_exudyn.studies.calibrate.envelope",
    "fitting": "cardan_exudyn.studies.calibrate.fitting",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
