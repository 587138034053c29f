"""Conditioning: from a raw record to conditioned signals on whole input revolutions (:func:`condition`).

The choices and their defaults: ``docs/rigdata.md``.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "rigdata.conditioning.options": ("DERIVATIVES", "Conditioning"),
    "rigdata.conditioning.pipeline": ("Conditioned", "condition"),
    "rigdata.conditioning.angles": ("pulse_edges", "angle_on_grid"),
    "rigdata.conditioning.filters": ("lowpass", "lowpass_adjoint", "angular_speed"),
    "rigdata.conditioning.window": ("revolution_window", "window_weights"),
    "rigdata.conditioning.phase": ("estimate_phase",),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
