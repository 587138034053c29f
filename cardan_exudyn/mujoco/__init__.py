"""MuJoCo, an optional engine for frictionless scenes: run it through
:func:`cardan_exudyn.engines.run` with engine ``"mujoco"``.

Inside: :mod:`~cardan_exudyn.mujoco.options` (settings, no MuJoCo import),
:mod:`~cardan_exudyn.mujoco.timestep` (error model, automatic step), :mod:`~cardan_exudyn.mujoco.mjcf`
(the model), :mod:`~cardan_exudyn.mujoco.drive` (drive plan, initial state),
:mod:`~cardan_exudyn.mujoco.simulate` (the time loop), :mod:`~cardan_exudyn.mujoco.table` (result
columns), :mod:`~cardan_exudyn.mujoco.engine` (``run``).
"""

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
