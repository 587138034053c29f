"""``cardan mujoco_settings``."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "compute": "cardan_exudyn.studies.mujoco_settings.compute",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
