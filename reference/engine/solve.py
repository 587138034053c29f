"""The reference engine: any scene in, the shared result schema out, without time-stepping error.
Prescribed motions are inverse dynamics sample by sample, a torque drive's is integrated; the
works come from quadrature, the time-averaged efficiency from the table, as in every engine.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from reference.engine.motion import input_motion
from reference.engine.options import ReferenceOptions
from reference.engine.table import EXTRA_COLUMNS, table_columns, table_times, table_verdict
from reference.engine.work import work_quadrature
from reference.physics.bands import sign_bands
from reference.physics.loop_closure import LoopClosureError
from reference.results.result import Result, result_table
from reference.results.summary import OptionsError, Status, Summary
from reference.scene.histories import run_clock
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import check_steps, require_scene

ENGINE_NAME = "reference"
ENGINE_VERSION = "reference-0.2"

__all__ = ["ENGINE_NAME", "ENGINE_VERSION", "means_from_works", "run"]


def run(scene: Scene, options: ReferenceOptions | None = None) -> Result:
    """:class:`Result` of ``scene`` by the reference engine, ``options`` (None: defaults) its resolution.

    For scripts ``cardan_exudyn.run(scene, engine="reference")`` is the same for every engine. The
    table: the schema's columns plus :data:`EXTRA_COLUMNS`, every ``record.every``-th row (None without
    ``record.timeseries``). Status ``self_locking`` (with the first angle), ``unphysical`` or
    ``loop_does_not_close`` (no table) where they apply.
    """
    require_scene(scene)
    if options is not None and not isinstance(options, ReferenceOptions):
        raise OptionsError(f"`options` must be ReferenceOptions or None, got {type(options).__name__}")
    options = options or ReferenceOptions()
    start = time.perf_counter()
    summary = Summary(Status.OK, engine=ENGINE_NAME, engine_version=ENGINE_VERSION,
                      scene=scene_to_dict(scene),
                      options={k: getattr(options, k) for k in options.__dataclass_fields__})
    try:
        clock, origin = run_clock(scene)  # histories from t = 0: the same answer at any start time
        table = _run(clock, options, summary, origin)
    except LoopClosureError as exc:  # mounting errors the loop cannot be assembled with
        summary.fail(Status.LOOP_DOES_NOT_CLOSE, str(exc))
        table = None
    summary.wall_time_s = time.perf_counter() - start
    return Result(table, summary)


def _run(scene: Scene, options: ReferenceOptions, summary: Summary, origin: float = 0.0) -> Any:
    """Fill ``summary``; return the time table (or None), its times ``origin`` [s] later than the
    scene's.
    """
    if scene.drive.kind == "torque":  # the ODE's cost grows with the revolutions: refuse first
        spr = options.samples_per_revolution or 360
        check_steps(scene.revolutions * spr,
                    f"{scene.revolutions:g} revolutions at {spr} samples per revolution")
    if scene.has_friction:
        summary.extras["sign_bands_m_s"] = {p: list(b) for p, b in sign_bands(scene).items()}
    motion = input_motion(scene, options)
    summary.status = Status(motion.status)
    summary.reason = motion.reason
    if scene.drive.kind == "torque":
        summary.ode_evaluations = motion.ode_evaluations
    if not motion.tabulated:
        return None
    t = table_times(scene, motion, options)
    columns = table_columns(scene, motion, t)
    table_verdict(t, columns, summary, origin)
    if summary.success:  # the means over whole revolutions, from the works
        means_from_works(scene, work_quadrature(scene, motion, columns, options), columns, options, summary)
    columns["t"] = t + origin
    return result_table(columns, scene.record.every, EXTRA_COLUMNS) if scene.record.timeseries else None


def means_from_works(scene: Scene, works: dict, columns: dict[str, np.ndarray],
                     options: ReferenceOptions, summary: Summary) -> None:
    """The means over whole revolutions from the quadrature's ``works`` (consumed) and the table's
    ``columns`` into ``summary`` (failed ``self_locking`` when friction locks at a node); ``options``'
    ``rtol`` enters a torque drive's error estimate.
    """
    if works.pop("self_locking_nodes", False):
        # as when it locks at a sample: no means (they would be NaN or meaningless)
        summary.fail(Status.SELF_LOCKING,
                     "friction self-locks between the table's samples (at quadrature nodes)")
        return
    diagnostics = {k: works.pop(k) for k in ("quadrature", "energy_balance_residual") if k in works}
    means = summary.whole_revolution_means(columns, scene.record.skip_revolutions, works)
    if means is not None:
        summary.set_means({**means, **diagnostics})
        _efficiency_error(scene, summary, options)


def _efficiency_error(scene: Scene, summary: Summary, options: ReferenceOptions) -> None:
    """The mean efficiency's error estimate into ``summary`` (first-order propagation of the works'
    estimates, plus the ODE's ``rtol`` for a torque drive) and whether it meets ``numerics.accuracy``.
    """
    q = summary.extras.get("quadrature")
    w_in = summary.input_work
    w_loss = summary.loss_work
    if not q or not w_in or w_loss is None or summary.mean_efficiency is None:
        return
    repeats = summary.revolutions / q["revolutions_integrated"] if q.get("revolutions_integrated") else 1
    e_in = repeats * float(q["input_work_error_estimate"])
    e_loss = repeats * float(q["loss_work_error_estimate"])
    estimate = e_loss / abs(w_in) + abs(w_loss) * e_in / w_in ** 2
    if scene.drive.kind == "torque":
        estimate += options.ode_rtol * abs(summary.mean_efficiency)
    summary.efficiency_error_estimate = estimate
    summary.accuracy_met = bool(estimate <= scene.numerics.accuracy)
