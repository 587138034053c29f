"""Richardson extrapolation of two Exudyn runs at ``h`` and ``h / 2`` (``Numerics.richardson``,
frictionless scenes only: with friction the mean efficiency is first order where sign ramps are
unresolved). Generalized-alpha gives ``x_h = x + c h^2 + O(h^3)``, so on the coarse rows

    x ~ (4 x_{h/2} - x_h) / 3

for the velocity-level histories (:data:`EXTRAPOLATED`); positions come from the fine run (index 3
keeps them at the Newton tolerance, not ``c h^2``). Force-level histories carry an alternating
start-up oscillation and are smoothed first by ``(x[i-1] + 2 x[i] + x[i+1]) / 4`` on each grid.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping

import numpy as np

from cardan_exudyn.model.build import ExudynModel
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.solve import result_of, reusable, run_model
from reference.results.columns import instantaneous_efficiency
from reference.results.result import Result
from reference.results.summary import Summary
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

__all__ = ["EXTRAPOLATED", "FROM_FINE", "FILTERED", "smooth", "extrapolate", "combine", "refusal",
           "run_pair", "run_combined"]

_PAIR_SUFFIXES = ("fx", "fy", "fz", "mx", "my", "mz", "omega_rel", "slide_rel")
EXTRAPOLATED = ("omega_in", "omega_out", "torque_in", "energy_kinetic",
                *(f"{p}_{s}" for p in PAIR_NAMES for s in _PAIR_SUFFIXES))
"""Columns combined as ``(4 x_fine - x_coarse) / 3`` (``power_in``, ``power_out`` and
``efficiency`` are recomputed from them)."""
FROM_FINE = ("t", "theta_in", "theta_out", "torque_out", "energy_potential", "power_loss",
             *(f"power_loss_{p}" for p in PAIR_NAMES),
             *(f"{p}_{s}" for p in PAIR_NAMES for s in ("friction_torque", "friction_force")))
"""Columns taken from the fine run's rows at the coarse run's times."""
FILTERED = ("torque_in", *(f"{p}_{s}" for p in PAIR_NAMES for s in ("fx", "fy", "fz", "mx", "my", "mz")))
"""Extrapolated columns smoothed first by :func:`smooth` on each run's grid (force level)."""


def smooth(x: np.ndarray) -> np.ndarray:
    """``(x[i-1] + 2 x[i] + x[i+1]) / 4`` on the inner rows (ends kept): removes a row-to-row alternating
    component, adds ``h^2 x'' / 4 + O(h^4)`` to a smooth history."""
    x = np.asarray(x, float)
    out = x.copy()
    if len(x) > 2:
        out[1:-1] = 0.25 * (x[:-2] + 2.0 * x[1:-1] + x[2:])
    return out


def extrapolate(fine: np.ndarray, coarse: np.ndarray, ratio: float = 2.0, order: int = 2) -> np.ndarray:
    """``x_fine + (x_fine - x_coarse) / (ratio^order - 1)`` on the same rows, ``ratio`` the step ratio
    coarse / fine: exact for an error ``c h^order``."""
    factor = 1.0 / (ratio ** order - 1.0)
    fine = np.asarray(fine, float)
    coarse = np.asarray(coarse, float)
    return fine + factor * (fine - coarse)


def combine(coarse: Mapping[str, np.ndarray], fine: Mapping[str, np.ndarray],
            rtol: float = 1e-9) -> dict[str, np.ndarray]:
    """Every column of ``coarse`` (``N + 1`` rows at ``h``) combined with ``fine`` (``2 N + 1`` at
    ``h / 2``): :data:`EXTRAPOLATED` extrapolated (:data:`FILTERED` smoothed first), powers and
    efficiency recomputed, the rest from the fine run's even rows. ``ValueError`` when the grids
    differ by more than ``rtol`` of the coarse step."""
    t_c = np.asarray(coarse["t"], float)
    t_f = np.asarray(fine["t"], float)
    n = len(t_c)
    step = (t_c[-1] - t_c[0]) / max(n - 1, 1)
    if len(t_f) != 2 * n - 1 or np.max(np.abs(t_f[::2] - t_c)) > rtol * step + 1e-15:
        raise ValueError(f"the fine run's rows ({len(t_f)}) are not the coarse run's ({n}) "
                         f"halved: Richardson needs the steps h and h/2 over the same span")
    out: dict[str, np.ndarray] = {}
    for key, values in coarse.items():
        if key in FILTERED:
            out[key] = extrapolate(smooth(fine[key])[::2], smooth(values))
        elif key in EXTRAPOLATED:
            out[key] = extrapolate(np.asarray(fine[key])[::2], values)
        else:
            out[key] = np.array(fine[key][::2], dtype=np.asarray(fine[key]).dtype)
    if "torque_in" in out and "omega_in" in out:
        out["power_in"] = out["torque_in"] * out["omega_in"]
    if "torque_out" in out and "omega_out" in out:
        out["power_out"] = out["torque_out"] * out["omega_out"]
    if "power_in" in out and "power_loss" in out:
        out["efficiency"] = instantaneous_efficiency(out["power_in"], out["power_loss"])
    return out


def refusal(scene: Scene) -> str | None:
    """Why ``scene`` cannot be extrapolated (one line), or None when it can."""
    if scene.has_friction:
        return ("`numerics.richardson` applies to frictionless scenes only: with friction the "
                "mean efficiency is first order where the sign ramps are unresolved, and "
                "extrapolating it at order 2 can make it worse")
    return None


Columns = dict[str, np.ndarray]


def run_pair(scene: Scene, run: Callable[[Scene], tuple[Summary, Columns | None]]
             ) -> tuple[Summary, Summary | None, Columns | None]:
    """``(coarse summary, fine summary, combined columns)`` of ``run(scene) -> (summary, columns)`` at
    the scene's step ``h`` and at ``h / 2``; the fine summary or columns None when a run has none."""
    coarse_summary, coarse = run(scene)
    if coarse is None or not coarse_summary.dt:
        return coarse_summary, None, None
    fine_summary, fine = run(replace(scene, **{"numerics.dt": 0.5 * coarse_summary.dt}))
    if fine is None:
        return coarse_summary, fine_summary, None
    return coarse_summary, fine_summary, combine(coarse, fine)


def run_combined(scene: Scene, options: ExudynOptions) -> Result:
    """Frictionless ``scene`` at its step and at half of it, combined: the fine run's summary with the
    combined table's means, the coarse step and grid, both runs' counters
    (``extras["richardson"]``); ``SceneError`` with friction."""
    why = refusal(scene)
    if why is not None:
        raise SceneError(why)
    wall_start = time.perf_counter()
    origin = [0.0]
    built: list[ExudynModel | None] = [None]

    def one(s: Scene) -> tuple[Summary, Columns | None]:
        # both runs' means are replaced by the combined table's: not taken per run
        summary_, columns_, origin[0], model = run_model(s, options, built[0], means=False)
        keep = model is not None and reusable(model, options.records_reactions(s))
        built[0] = model if keep else None
        return summary_, columns_

    coarse, fine, columns = run_pair(scene, one)
    summary = coarse if fine is None or not coarse.success else fine
    if summary is fine:
        _combined_summary(coarse, fine, columns, scene)
    summary.scene = scene_to_dict(scene)
    summary.wall_time_s = time.perf_counter() - wall_start
    return result_of(scene, summary, columns if summary is fine else None, origin[0])


def _combined_summary(coarse: Summary, fine: Summary, columns: Columns | None, scene: Scene) -> None:
    """Turn the fine run's summary into the combination's: what was combined, the coarse step, both
    runs' counters, and the means of the combined ``columns``."""
    fine.extras["richardson"] = {
        "coarse_dt": coarse.dt, "fine_dt": fine.dt, "coarse_wall_time_s": coarse.wall_time_s,
        "fine_wall_time_s": fine.wall_time_s, "extrapolated": list(EXTRAPOLATED),
        "from_fine": list(FROM_FINE), "recomputed": ["power_in", "power_out", "efficiency"]}
    fine.dt = coarse.dt
    fine.dt_choice = f"{coarse.dt_choice}; Richardson with a run at dt/2"
    for key in ("steps", "newton_iterations", "jacobian_evaluations"):
        setattr(fine, key, (getattr(coarse, key) or 0) + (getattr(fine, key) or 0))
    if columns is not None and fine.success:
        fine.clear_means()
        means = fine.whole_revolution_means(columns, scene.record.skip_revolutions)
        if means is not None:
            fine.set_means(means)
