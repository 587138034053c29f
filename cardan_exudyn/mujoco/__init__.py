"""MuJoCo, an optional engine for frictionless scenes."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "cardan_exudyn.mujoco.engine": ('MujocoOptions', 'run'),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
