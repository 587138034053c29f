"""One Exudyn solve of a scene: the model built, the solver set up (step, settings, friction coupling,
stop function) and run, and its columns and summary."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import exudyn as exu
import numpy as np

from cardan_exudyn.interrupts import watch_signals
from cardan_exudyn.model.build import ExudynModel, build_model
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.postprocess import constraint_violation, first_non_finite, postprocess
from cardan_exudyn.model.stepsize import choose_step
from reference.physics.loop_closure import LoopClosureError
from reference.results.columns import REACTION_SUFFIXES
from reference.results.result import Result, result_table
from reference.results.summary import Status, Summary
from reference.scene.drives import AngleDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import check_steps

__all__ = ["ENGINE_NAME", "engine_version", "end_time", "steps_for_span", "simulation_settings",
           "Solved", "solve", "torque_step_hint", "reusable", "run_once", "run_columns", "run_model",
           "result_of"]

ENGINE_NAME = "exudyn"


def engine_version() -> str:
    """The installed Exudyn's version string."""
    return exu.config.Version() if hasattr(exu, "config") else exu.GetVersionString()


def end_time(scene: Scene, start: float) -> float:
    """Time [s] at which the input has turned ``scene.revolutions`` (model clock) from ``start`` [s]; a
    torque drive: the time it is allowed."""
    drive = scene.drive
    target = 2.0 * math.pi * scene.revolutions
    if drive.kind == "speed":
        return start + target / abs(drive.speed)
    if isinstance(drive, AngleDrive):
        return drive.time_to_turn(target)
    return start + drive.time_allowed(target)


def steps_for_span(span: float, dt: float) -> int:
    """Fewest whole steps of at most ``dt`` [s] covering ``span`` [s], at least 1 (the nearest count could
    stop half a step short, averaging less than the revolutions asked for)."""
    return max(1, math.ceil(span / dt - 1e-9))


def simulation_settings(dt: float, t_start: float, t_end: float,
                        options: ExudynOptions) -> Any:
    """Exudyn's simulation settings of one run at step ``dt`` [s] over ``t_start``..``t_end`` [s] (whole
    steps, :func:`steps_for_span`): fixed step, no solution file, sensors stored every step."""
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
    """A finished (or failed) Exudyn solve: ``model`` (sensors holding every step), ``solver``
    (counters ``solver.it``), ``status``, ``reason`` (empty when ok), step ``dt`` [s] and its
    ``dt_reason``, ``wall_time_s``."""

    model: ExudynModel
    solver: Any
    status: Status
    reason: str
    dt: float
    dt_reason: str
    wall_time_s: float


def solve(scene: Scene, options: ExudynOptions, reactions: bool,
          tweak: Callable[[ExudynModel, Any], None] | None = None,
          model: ExudynModel | None = None) -> Solved:
    """Build the model of ``scene`` and integrate it: the step, solver settings, friction set-up and
    stop function of every Exudyn run.

    Parameters
    ----------
    scene : Scene
    options : ExudynOptions
    reactions : bool
        Record the pair reactions (sensors) for the table.
    tweak : callable, optional
        ``tweak(model, settings)``, called before the solver starts (the benchmark's skip audit).
    model : ExudynModel, optional
        A :func:`reusable` model of the same scene up to ``numerics.dt``, integrated again instead of
        a new build; bit for bit the fresh build's run (``tests/test_fixed_costs.py``).

    Raises
    ------
    LoopClosureError
        The mounting errors cannot be assembled.
    """
    wall_start = time.perf_counter()
    dt, dt_reason = choose_step(scene, options.node_type)
    model = _model(scene, options, reactions, model)
    t_end = end_time(model.scene, model.start_time)  # on the model's clock (build.run_clock)
    span = t_end - model.start_time
    check_steps(span / dt, f"{scene.revolutions:g} revolutions at dt = {dt:.3g} s")
    dt = span / steps_for_span(span, dt)  # whole steps end exactly at the span's end
    settings = simulation_settings(dt, model.start_time, t_end, options)
    if model.friction is not None:
        model.friction.configure(settings)
    _set_pre_step(model, 2.0 * math.pi * scene.revolutions if scene.drive.kind == "torque" else None)
    if tweak is not None:
        tweak(model, settings)
    solver = exu.MainSolverImplicitSecondOrder()
    status, reason = _integrate(model, solver, settings)
    if status == Status.INTEGRATION_FAILURE and scene.numerics.dt is None:
        reason += torque_step_hint(scene)
    return Solved(model, solver, status, reason, dt, dt_reason, time.perf_counter() - wall_start)


def _model(scene: Scene, options: ExudynOptions, reactions: bool,
           model: ExudynModel | None) -> ExudynModel:
    """A new model of ``scene``, or ``model`` made ready to be solved again (:func:`solve`)."""
    if model is None:
        return build_model(scene, reactions=reactions, node_type=options.node_type)
    if not reusable(model, reactions):
        raise ValueError("`model` cannot be solved again: it has friction or lacks the "
                         "reaction sensors asked for")
    model.input_turns.reset()
    return model


def _integrate(model: ExudynModel, solver: Any, settings: Any) -> tuple[Status, str]:
    """``(status, reason)`` of running the solver over ``settings``' span; with friction the coupling is
    initialised first and its status wins. An interruption inside the solver is raised as itself
    (:func:`~cardan_exudyn.interrupts.watch_signals`), never recorded as an integration failure."""
    friction = model.friction
    status = Status.OK
    reason = ""
    with watch_signals():
        try:
            if friction is None:
                ok = solver.SolveSystem(model.mbs, settings)
            else:
                solver.InitializeSolver(model.mbs, settings)
                friction.initialise(solver, settings)
                ok = friction.status != Status.OK or solver.SolveSteps(model.mbs, settings)
                solver.FinalizeSolver(model.mbs, settings)
            if not ok:
                status = Status.INTEGRATION_FAILURE
                reason = solver.GetErrorString() or "solver failed"
        except (RuntimeError, ValueError) as exc:  # how Exudyn reports a failed solve
            status = Status.INTEGRATION_FAILURE
            reason = str(exc).strip().splitlines()[0][:300]
    if friction is not None and friction.error is not None:
        raise friction.error
    if friction is not None and friction.status != Status.OK:
        return friction.status, friction.reason
    return status, reason


def torque_step_hint(scene: Scene) -> str:
    """The note for an integration failure at a torque drive's automatic step (sized for its initial
    speed), else ``""``."""
    if scene.drive.kind != "torque":
        return ""
    return (f" (the step was sized for the torque drive's initial speed, "
            f"{abs(scene.drive.initial_speed):.3g} rad/s; a joint that speeds up beyond it "
            f"needs `numerics.dt` for its top speed)")


def reusable(model: ExudynModel, reactions: bool) -> bool:
    """Whether :func:`solve` can integrate ``model`` again: no friction coupling (its state is one run's)
    and reaction sensors when ``reactions`` asks for them."""
    recorded = f"{PAIR_NAMES[0]}_force" in model.sensors
    return model.friction is None and (recorded or not reactions)


def run_once(scene: Scene, options: ExudynOptions) -> Result:
    """One Exudyn run of ``scene`` at its own step: the table (when recorded) and summary with means."""
    summary, columns, origin = run_columns(scene, options)
    return result_of(scene, summary, columns, origin)


def run_columns(scene: Scene, options: ExudynOptions) -> tuple[Summary, dict[str, np.ndarray] | None, float]:
    """:func:`run_once` before the table: ``(summary, columns on the model's clock or None, origin [s])``."""
    summary, columns, origin, _ = run_model(scene, options)
    return summary, columns, origin


def run_model(scene: Scene, options: ExudynOptions, model: ExudynModel | None = None,
              means: bool = True) -> tuple[Summary, dict[str, np.ndarray] | None, float,
                                           ExudynModel | None]:
    """:func:`run_columns` and the model it solved (None when the loop did not close); ``model``: solve
    it again (:func:`solve`); ``means`` False leaves the summary's means out."""
    wall_start = time.perf_counter()
    summary = Summary(Status.OK, engine=ENGINE_NAME, engine_version=engine_version(),
                      scene=scene_to_dict(scene),
                      options={**options.to_dict(), "integrator": "generalized-alpha index 3"})
    try:
        solved = solve(scene, options, reactions=options.records_reactions(scene), model=model)
    except LoopClosureError as exc:  # mounting errors the loop cannot be assembled with
        summary.fail(Status.LOOP_DOES_NOT_CLOSE, str(exc))
        summary.wall_time_s = time.perf_counter() - wall_start
        return summary, None, 0.0, None
    model = solved.model
    _record_solve(summary, solved)
    summary.wall_time_s = time.perf_counter() - wall_start
    if model.friction is not None:
        summary.friction = model.friction.diagnostics()
        summary.max_friction_loop_gain = summary.friction.loop_gain_estimate_max
    try:
        columns = postprocess(model, project=options.velocity_projection)
    except ValueError as exc:  # no data recorded, e.g. a failure in the first step
        if summary.success:
            summary.fail(Status.INTEGRATION_FAILURE, f"no usable output: {exc}")
        return summary, None, model.time_origin, model
    _check_columns(scene, model, columns, summary, options, means)
    return summary, columns, model.time_origin, model


def _record_solve(summary: Summary, solved: Solved) -> None:
    """The solve's status, step and cost counters into ``summary``."""
    solver = solved.solver
    summary.status = Status(solved.status)
    summary.reason = solved.reason
    summary.dt = solved.dt
    summary.dt_choice = solved.dt_reason
    summary.steps = int(solver.it.currentStepIndex)
    summary.newton_iterations = int(solver.it.newtonStepsCount)
    summary.jacobian_evaluations = int(solver.it.newtonJacobiCount)


def result_of(scene: Scene, summary: Summary, columns: dict[str, np.ndarray] | None,
              origin: float) -> Result:
    """The result of a run's ``columns`` (time shifted in place by ``origin`` [s] to the scene's clock),
    the table recorded as ``scene.record`` says."""
    if columns is None:
        return Result(None, summary)
    columns["t"] = columns["t"] + origin
    table = result_table(columns, scene.record.every) if scene.record.timeseries else None
    return Result(table, summary)


def _check_columns(scene: Scene, model: ExudynModel, columns: dict[str, np.ndarray],
                   summary: Summary, options: ExudynOptions, means: bool = True) -> None:
    """Constraint violations, finiteness, the torque drive's turn and (``means``) the means into
    ``summary``."""
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
    if summary.success and means:
        values = summary.whole_revolution_means(columns, scene.record.skip_revolutions)
        if values is not None:
            summary.set_means(values)


def _set_pre_step(model: ExudynModel, target: float | None) -> None:
    """Stop the run after ``target`` [rad] of input (torque drive) or when the friction coupling fails."""
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
        angle = (mbs_.GetNodeOutput(node, exu.OutputVariableType.Coordinates)[3]
                 + 2.0 * math.pi * model.input_turns.count)  # the continuous angle
        start.setdefault("angle", angle)
        return abs(angle - start["angle"]) < target - 1e-12

    model.user_functions.append(pre_step)
    model.mbs.SetPreStepUserFunction(pre_step)


