"""MuJoCo, an optional engine for frictionless scenes: run it through :func:`cardan_exudyn.run` with
engine ``"mujoco"``."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "cardan_exudyn.mujoco.options": ("MujocoOptions", "INTEGRATORS", "MUJOCO_DEFAULT_SOLREF",
                                     "MUJOCO_DEFAULT_SOLIMP", "STIFF_SOLIMP"),
    "cardan_exudyn.mujoco.timestep": ("speed_ratio_error_model", "choose_timestep"),
    "cardan_exudyn.mujoco.engine": ("run",),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
