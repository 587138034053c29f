"""Run a scene with Exudyn: the one solve sequence (step choice, solver settings, friction set-up,
stop function) and the run that turns it into the common result (:class:`reference.schema.Result`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import exudyn as exu
import numpy as np

from cardan_exudyn.model.build import ExudynModel, build_model
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.postprocess import constraint_violation, first_non_finite, postprocess
from cardan_exudyn.model.stepsize import choose_step
from reference.joint import PAIR_NAMES
from reference.loop_closure import LoopClosureError
from reference.scene import AngleDrive, Scene, scene_to_dict
from reference.schema import (
    REACTION_SUFFIXES,
    Result,
    Status,
    Summary,
    result_table,
)
from reference.validation import check_steps

ENGINE_NAME = "exudyn"


def engine_version() -> str:
    return exu.config.Version() if hasattr(exu, "config") else exu.GetVersionString()


def end_time(scene: Scene, start: float) -> float:
    """Time at which the input has turned ``scene.revolutions`` revolutions [s]."""
    drive = scene.drive
    target = 2.0 * math.pi * scene.revolutions
    if drive.kind == "speed":
        return start + target / abs(drive.speed)
    if isinstance(drive, AngleDrive):
        return drive.time_to_turn(target)
    return start + drive.time_allowed(target)


def steps_for_span(span: float, dt: float) -> int:
    """Fewest whole steps of at most ``dt`` (to rounding) that cover ``span``.

    Rounding to the nearest count instead would stop short of the span by up to half a step, and
    a span of exactly ``1 + skip`` revolutions would then average less than one revolution.
    """
    return max(1, math.ceil(span / dt - 1e-9))


def simulation_settings(dt: float, t_start: float, t_end: float,
                        options: ExudynOptions) -> Any:
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    n = steps_for_span(t_end - t_start, dt)
    ti.startTime = t_start
    ti.endTime = t_start + n * dt
    ti.numberOfSteps = n
    ti.verboseMode = 0
    ti.adaptiveStep = False
    ti.automaticStepSize = False
    ti.generalizedAlpha.spectralRadius = options.spectral_radius
    ti.newton.useModifiedNewton = options.modified_newton
    ti.newton.modifiedNewtonJacUpdatePerStep = options.jacobian_every_step
    ti.newton.relativeTolerance = options.newton_relative_tolerance
    ti.newton.absoluteTolerance = options.newton_absolute_tolerance
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.5 * dt
    s.show.statistics = False
    s.show.computationTime = False
    return s


@dataclass
class Solved:
    """A finished (or failed) Exudyn solve of a scene: the model with its sensors, the solver's
    counters, the status and reason, the step used and how it was chosen, the solve's wall time."""

    model: ExudynModel
    solver: Any
    status: Status
    reason: str
    dt: float
    dt_reason: str
    wall_time_s: float


def solve(scene: Scene, options: ExudynOptions, reactions: bool,
          tweak: Callable[[ExudynModel, Any], None] | None = None) -> Solved:
    """Build the model of ``scene`` and integrate it: the step choice, solver settings, friction
    set-up and stop function of every Exudyn run (:func:`run`, the long runs, the benchmark).

    ``tweak(model, settings)``, when given, is called once the model and its simulation settings
    are made and before the solver starts (the benchmark's skip audit adds or removes one thing).

    Raises :class:`LoopClosureError` when the mounting errors cannot be assembled.
    """
    wall_start = time.perf_counter()
    dt, dt_reason = choose_step(scene, options.node_type)
    model = build_model(scene, reactions=reactions, node_type=options.node_type)
    t_end = end_time(scene, model.start_time)
    span = t_end - model.start_time
    check_steps(span / dt, f"{scene.revolutions:g} revolutions at dt = {dt:.3g} s")
    dt = span / steps_for_span(span, dt)  # whole steps end exactly at the span's end
    settings = simulation_settings(dt, model.start_time, t_end, options)
    target = 2.0 * math.pi * scene.revolutions
    friction = model.friction
    if friction is not None:
        friction.configure(settings)
    _set_pre_step(model, target if scene.drive.kind == "torque" else None)
    if tweak is not None:
        tweak(model, settings)
    solver = exu.MainSolverImplicitSecondOrder()
    status, reason = Status.OK, ""
    try:
        if friction is None:
            ok = solver.SolveSystem(model.mbs, settings)
        else:
            solver.InitializeSolver(model.mbs, settings)
            friction.initialise(solver, settings)
            ok = friction.status != Status.OK or solver.SolveSteps(model.mbs, settings)
            solver.FinalizeSolver(model.mbs, settings)
        if not ok:
            status, reason = Status.INTEGRATION_FAILURE, solver.GetErrorString() or "solver failed"
    except (RuntimeError, ValueError) as exc:  # how Exudyn reports a failed solve
        status, reason = Status.INTEGRATION_FAILURE, str(exc).strip().splitlines()[0][:300]
    if friction is not None and friction.error is not None:
        raise friction.error
    if friction is not None and friction.status != Status.OK:
        status, reason = friction.status, friction.reason
    return Solved(model, solver, status, reason, dt, dt_reason, time.perf_counter() - wall_start)


def run(scene: Scene, options: ExudynOptions | None = None) -> Result:
    """Simulate ``scene`` with Exudyn and return its time table and summary."""
    options = options or ExudynOptions()
    wall_start = time.perf_counter()
    summary = Summary(Status.OK, engine=ENGINE_NAME, engine_version=engine_version(),
                      scene=scene_to_dict(scene),
                      options={**options.to_dict(), "integrator": "generalized-alpha index 3"})
    try:
        solved = solve(scene, options, reactions=options.records_reactions(scene))
    except LoopClosureError as exc:  # mounting errors the loop cannot be assembled with
        summary.fail(Status.LOOP_DOES_NOT_CLOSE, str(exc))
        summary.wall_time_s = time.perf_counter() - wall_start
        return Result(None, summary)
    model, solver = solved.model, solved.solver
    summary.status, summary.reason = Status(solved.status), solved.reason
    summary.dt, summary.dt_choice = solved.dt, solved.dt_reason
    summary.steps = int(solver.it.currentStepIndex)
    summary.newton_iterations = int(solver.it.newtonStepsCount)
    summary.jacobian_evaluations = int(solver.it.newtonJacobiCount)
    summary.wall_time_s = time.perf_counter() - wall_start
    if model.friction is not None:
        friction = model.friction.summary()
        summary.extras["friction"] = friction
        summary.max_friction_loop_gain = friction["loop_gain_estimate_max"]
    try:
        columns = postprocess(model, project=options.velocity_projection)
    except ValueError as exc:  # no data recorded, e.g. a failure in the first step
        if summary.success:
            summary.fail(Status.INTEGRATION_FAILURE, f"no usable output: {exc}")
        return Result(None, summary)
    _check_columns(scene, model, columns, summary, options)
    table = result_table(columns, scene.record.every) if scene.record.timeseries else None
    return Result(table, summary)


def _check_columns(scene: Scene, model: ExudynModel, columns: dict[str, np.ndarray],
                   summary: Summary, options: ExudynOptions) -> None:
    """Constraint violations, finiteness, the torque drive's turn, and the means into ``summary``."""
    violation = constraint_violation(model.pair_kinematics)
    summary.max_constraint_violation_m = violation["max_constraint_violation_m"]
    summary.max_constraint_violation_rad = violation["max_constraint_violation_rad"]
    if options.velocity_projection:
        summary.extras["max_velocity_correction"] = model.velocity_correction
    unrecorded = set() if f"{PAIR_NAMES[0]}_force" in model.sensors else {
        f"{p}_{c}" for p in PAIR_NAMES for c in REACTION_SUFFIXES}
    bad = first_non_finite({k: v for k, v in columns.items() if k not in unrecorded})
    if bad and summary.success:
        summary.fail(Status.DIVERGED, f"non-finite values in `{bad}`")
    target = 2.0 * math.pi * scene.revolutions
    if scene.drive.kind == "torque" and summary.success:
        turned = abs(columns["theta_in"][-1] - columns["theta_in"][0])
        if turned + 1e-6 < target:
            summary.fail(Status.INCOMPLETE, f"torque drive turned {turned / (2 * math.pi):.3g} of "
                                            f"{scene.revolutions:g} revolutions in the time allowed")
    if summary.success:
        means = summary.whole_revolution_means(columns, scene.record.skip_revolutions)
        if means is not None:
            summary.set_means(means)


def _set_pre_step(model: ExudynModel, target: float | None) -> None:
    """Stop the run after ``target`` radians (torque drive) or when friction self-locks."""
    node = model.nodes["input"]
    friction = model.friction
    if target is None and friction is None:
        return
    start = {}

    def pre_step(mbs_, t):
        if friction is not None and friction.status != Status.OK:
            return False
        if target is None:
            return True
        angle = mbs_.GetNodeOutput(node, exu.OutputVariableType.Coordinates)[3]
        start.setdefault("angle", angle)
        return abs(angle - start["angle"]) < target - 1e-12

    model.user_functions.append(pre_step)
    model.mbs.SetPreStepUserFunction(pre_step)


