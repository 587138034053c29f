"""The scene: what to simulate (joint, drive, load, numerics, records), validated plain data."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.scene.validation": ('SceneError', 'DEG', 'RPM'),
    "reference.scene.joint": ('PAIR_NAMES', 'Body', 'Geometry', 'Pair', 'Pairs', 'MountingErrors', 'Joint'),
    "reference.scene.drives": ("SpeedDrive", "AngleDrive", "TorqueDrive"),
    "reference.scene.load": ("Load",),
    "reference.scene.settings": ("Numerics", "FrictionSettings", "Record", "COUPLINGS", "FRICTION_LAWS"),
    "reference.scene.scene": ("Scene",),
    "reference.scene.mapping": ("replace", "scene_to_dict", "scene_from_dict"),
    "reference.scene.files": ('load_scene', 'scene_from_mapping'),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
