"""The independent reference engine: inverse dynamics of speed and angle drives, forward dynamics
of torque drives, work quadrature, and many scenes at once (``batch``)."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.engine.options": ("ReferenceOptions",),
    "reference.engine.motion": ("SelfLocking",),
    "reference.engine.solve": ("run",),
    "reference.engine.batch.solve": ('run_batch',),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
