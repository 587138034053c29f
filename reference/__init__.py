"""reference: the paper's data, the scene format, the result schema and an independent engine.

numpy/scipy only (never exudyn, cardan_exudyn or rigdata), so it works without Exudyn::

    import reference

    scene = reference.named_scene("paper-10deg")          # or reference.load_scene("my.toml")
    scene = reference.replace(scene, **{"load.torque": 1.0})
    result = reference.run(scene)                          # the reference engine
    if result.success:
        print(result.summary.mean_efficiency)

Other engines: ``cardan_exudyn.run(scene, engine=...)``. Names are imported on first use (PEP 562).
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.scene.validation": ("SceneError", "DEG", "RPM"),
    "reference.scene.joint": ("PAIR_NAMES", "Body", "Geometry", "Pair", "Pairs", "MountingErrors", "Joint"),
    "reference.scene.drives": ("SpeedDrive", "AngleDrive", "TorqueDrive"),
    "reference.scene.load": ("Load",),
    "reference.scene.settings": ("Numerics", "FrictionSettings", "Record"),
    "reference.scene.scene": ("Scene",),
    "reference.scene.mapping": ("replace", "scene_to_dict", "scene_from_dict"),
    "reference.scene.files": ("load_scene", "scene_from_mapping"),
    "reference.paper.scenes": ("named_scene", "paper_scene", "rig_scene"),
    "reference.results.summary": ("Status", "Summary", "OptionsError"),
    "reference.results.result": ("Result",),
    "reference.results.accuracy": ("RunAccuracy",),
    "reference.results.friction_diagnostics": ("FrictionDiagnostics",),
    "reference.engine.options": ("ReferenceOptions",),
    "reference.engine.solve": ("run",),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
