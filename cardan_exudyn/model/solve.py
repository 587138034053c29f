"""Run a scene with Exudyn: the one solve sequence (step choice, solver settings, friction set-up,
stop function) and the run that turns it into the common result (:class:`reference.results.result.Result`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import exudyn as exu
import numpy as np

from cardan_exudyn.interrupts import watch_signals
from cardan_exudyn.model import richardson as two_step
from cardan_exudyn.model.build import ExudynModel, build_model
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.postprocess import constraint_violation, first_non_finite, postprocess
from cardan_exudyn.model.stepsize import (
    MAX_STEPS_PER_REVOLUTION,
    MIN_COMPANION_STEPS,
    choose_step,
    convergence_order,
    efficiency_error,
    kinematic_steps,
    plan_steps,
    predicted_errors,
    refuse,
    reversing_parts,
    revolution_period,
    richardson,
)
from reference.physics.loop_closure import LoopClosureError
from reference.results.columns import REACTION_SUFFIXES
from reference.results.result import Result, result_table
from reference.results.summary import Status, Summary
from reference.scene.drives import AngleDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError, check_steps

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
          tweak: Callable[[ExudynModel, Any], None] | None = None,
          model: ExudynModel | None = None) -> Solved:
    """Build the model of ``scene`` and integrate it: the step choice, solver settings, friction
    set-up and stop function of every Exudyn run (:func:`run`, the long runs, the benchmark).

    ``tweak(model, settings)``, when given, is called once the model and its simulation settings
    are made and before the solver starts (the benchmark's skip audit adds or removes one thing).

    ``model``: integrate this model again instead of building one (:func:`reusable`): a
    frictionless model built for the same scene up to ``numerics.dt``, whose earlier results have
    been read. Exudyn starts every solve from the model's initial coordinates and clears the
    sensors' stored data, so the run is the one a fresh build gives (bit for bit, measured; pinned
    by ``tests/test_fixed_costs.py``); only the whole revolutions the post-step hook took out of
    the input angle are reset here. Saves the build (a tenth of a short run).

    Raises :class:`LoopClosureError` when the mounting errors cannot be assembled.
    """
    wall_start = time.perf_counter()
    dt, dt_reason = choose_step(scene, options.node_type)
    if model is None:
        model = build_model(scene, reactions=reactions, node_type=options.node_type)
    else:
        if not reusable(model, reactions):
            raise ValueError("`model` cannot be solved again: it has friction or lacks the "
                             "reaction sensors asked for")
        model.input_turns.reset()
    t_end = end_time(model.scene, model.start_time)  # on the model's clock (build.run_clock)
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
    # Ctrl-C / SIGTERM inside the solver comes back as a failed solve or a SystemError: the watch
    # raises the interruption instead, so it is never recorded as an integration failure
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
                status, reason = Status.INTEGRATION_FAILURE, solver.GetErrorString() or "solver failed"
        except (RuntimeError, ValueError) as exc:  # how Exudyn reports a failed solve
            status, reason = Status.INTEGRATION_FAILURE, str(exc).strip().splitlines()[0][:300]
    if friction is not None and friction.error is not None:
        raise friction.error
    if friction is not None and friction.status != Status.OK:
        status, reason = friction.status, friction.reason
    if status == Status.INTEGRATION_FAILURE and scene.numerics.dt is None:
        reason += torque_step_hint(scene)
    return Solved(model, solver, status, reason, dt, dt_reason, time.perf_counter() - wall_start)


def torque_step_hint(scene: Scene) -> str:
    """What to add to an integration failure at an automatic step of a torque drive (the step
    was sized for its initial speed), else ``""``."""
    if scene.drive.kind != "torque":
        return ""
    return (f" (the step was sized for the torque drive's initial speed, "
            f"{abs(scene.drive.initial_speed):.3g} rad/s; a joint that speeds up beyond it "
            f"needs `numerics.dt` for its top speed)")


def reusable(model: ExudynModel, reactions: bool) -> bool:
    """Whether :func:`solve` can integrate ``model`` again: no friction coupling (its state
    belongs to one run) and the reaction sensors when ``reactions`` asks for them."""
    recorded = f"{PAIR_NAMES[0]}_force" in model.sensors
    return model.friction is None and (recorded or not reactions)


def run(scene: Scene, options: ExudynOptions | None = None) -> Result:
    """Simulate ``scene`` with Exudyn and return its time table and summary, with the estimated
    error of its mean efficiency (``docs/accuracy.md``).

    With friction the main run has a companion at 2 to 3 times its step, and the Richardson
    estimate from the two (:func:`_estimate`) is the run's ``summary.efficiency_error_estimate``
    (``accuracy_met``, ``extras["accuracy"]``). A given ``numerics.dt`` has its companion at
    twice the step; an automatic step is chosen by :func:`_automatic_runs`. Without friction the
    mean efficiency is 1 exactly and nothing else runs. With ``numerics.richardson`` (frictionless
    scenes only) the scene runs at its step and at half of it, and the result is the Richardson
    combination of the two (:func:`_richardson_run`).

    Raises
    ------
    SceneError
        ``numerics.accuracy`` needs more steps than allowed (the message gives the predicted
        steps per revolution and run time); ``numerics.richardson`` with friction.
    """
    options = options or ExudynOptions()
    wall_start = time.perf_counter()
    if scene.numerics.richardson and (why := two_step.refusal(scene)) is not None:
        raise SceneError(why)
    if scene.numerics.richardson or not scene.has_friction:
        result = _richardson_run(scene, options) if scene.numerics.richardson else run_once(scene, options)
        _report_accuracy(result, None, scene, options)
        return result
    if scene.numerics.dt is not None:
        if not options.error_estimate:
            return run_once(scene, options)
        coarse = run_once(_companion(scene, 2.0 * scene.numerics.dt), options)
        main = run_once(scene, options)
        _report_accuracy(main, coarse, scene, options)
    else:
        main = _automatic_runs(scene, options) if options.error_estimate else _planned_run(scene, options)
        if main.summary.status == Status.INTEGRATION_FAILURE:
            main.summary.reason += torque_step_hint(scene)
    main.summary.wall_time_s = time.perf_counter() - wall_start  # the pilot and companions too
    return main


def _pilot_plan(scene: Scene, options: ExudynOptions) -> tuple[Result, int, int, str]:
    """The pilot run of an automatic step (half the speed-ratio step, at least
    :data:`MIN_COMPANION_STEPS` per revolution) and the steps per revolution its losses ask for:
    ``(pilot, its steps, planned steps, why)``."""
    period = revolution_period(scene)
    pilot_steps = max(MIN_COMPANION_STEPS, math.ceil(0.5 * _kinematic_steps(scene, options)))
    pilot = run_once(_companion(scene, period / pilot_steps), options)
    cost = pilot.summary.wall_time_s / max(pilot.summary.steps or 1, 1)
    steps, why = plan_steps(scene, loss_fraction(pilot), options.node_type, cost)
    if not pilot.success:
        why += (f" (the pilot at {pilot_steps} steps per revolution ended {pilot.summary.status}: "
                f"its loss fraction taken as 1, the most a joint can lose)")
    return pilot, pilot_steps, max(steps, 2 * pilot_steps), why


def _planned_run(scene: Scene, options: ExudynOptions) -> Result:
    """An automatic step without the error estimate (``ExudynOptions.error_estimate`` off): the
    pilot's losses plan the step for the mean efficiency as well as the speed ratio, as in
    :func:`_automatic_runs`, and the main run is the only other run (no companion, no estimate).
    Choosing the step for the speed ratio alone read the mean efficiency of ``paper-literal-20deg``
    1.9e-3 off under ``numerics.accuracy = 1e-4`` (100 steps per revolution). With the extrapolated
    coupling the planned steps grow by ``sqrt(1 / (1 - g))`` (the pilot's loop gain ``g``): without
    it the paper's 30 and 35 deg scenes read 1.7e-4 and 2.7e-4 off at 1e-4 (``docs/accuracy.md``)."""
    pilot, _, steps, why = _pilot_plan(scene, options)
    if scene.friction.coupling == "extrapolated":
        # no estimate will catch an under-read: the extrapolation's error grows as 1 / (1 - g)
        # with the friction loop gain g (the coupling's module doc), which the model leaves out
        g, said = _pilot_gain(pilot)
        factor = math.sqrt(1.0 / (1.0 - g))
        steps = math.ceil(steps * factor / 2.0) * 2
        why += f"; x{factor:.2f} for the extrapolated coupling at {said}"
        refuse(scene, steps, f"a mean-efficiency error of {scene.numerics.accuracy:g} with the "
                             f"extrapolated coupling")
    main = run_once(replace(scene, **{"numerics.dt": revolution_period(scene) / steps}), options)
    main.summary.scene = scene_to_dict(scene)
    main.summary.dt_choice = why + "; no error estimate (ExudynOptions.error_estimate is off)"
    _record_pilot(main, pilot, is_companion=False)
    return main


def _pilot_gain(pilot: Result) -> tuple[float, str]:
    """The loop gain the planned step allows for (in [0, :data:`EXTRAPOLATION_GAIN_CAP`]) and
    how it was found: the pilot's largest probe; 0 where its probes saw the friction not move
    (no feedback to amplify); the cap where no probe finished or the pilot failed."""
    gain = pilot.summary.max_friction_loop_gain
    if pilot.success and gain is not None and math.isfinite(gain):
        return min(max(gain, 0.0), EXTRAPOLATION_GAIN_CAP), f"loop gain {gain:.2f}"
    probes = (pilot.summary.extras.get("friction") or {}).get("gain_probes") or 0
    if pilot.success and probes > 0:
        return 0.0, f"no loop gain ({probes} probes saw the friction not move)"
    return EXTRAPOLATION_GAIN_CAP, (f"loop gain {EXTRAPOLATION_GAIN_CAP:g}, where the coupling escalates "
                                    f"(the pilot measured none)")


def _automatic_runs(scene: Scene, options: ExudynOptions) -> Result:
    """The runs of an automatic step, the main run returned with its estimate.

    A pilot at half the speed-ratio step (at least :data:`MIN_COMPANION_STEPS` per revolution)
    runs first: its losses set the steps ``n`` that meet ``numerics.accuracy``
    (:func:`cardan_exudyn.model.stepsize.plan_steps`). The pilot is the companion when ``n`` is
    at most :data:`MAX_COMPANION_RATIO` times its steps, else a companion at ``n / 2`` runs. When
    the estimate still exceeds the target, the main run becomes the companion of one more at
    ``2 n`` (the step where the error changes order can make two levels read high)."""
    period = revolution_period(scene)
    pilot, pilot_steps, steps, why = _pilot_plan(scene, options)
    coarse = pilot
    if steps > MAX_COMPANION_RATIO * pilot_steps:  # the pilot is too coarse: a companion at half
        coarse = run_once(_companion(scene, 2.0 * period / steps), options)
    main = run_once(replace(scene, **{"numerics.dt": period / steps}), options)
    _report_accuracy(main, coarse, scene, options)
    # no estimate because the companion failed (not because the main run has no efficiency)
    unverified = main.summary.accuracy_met is None and _failed(coarse) and not _failed(main)
    if (main.summary.accuracy_met is False or unverified) and 2 * steps <= MAX_STEPS_PER_REVOLUTION:
        first = main.summary.efficiency_error_estimate
        coarse, steps = main, 2 * steps
        main = run_once(replace(scene, **{"numerics.dt": period / steps}), options)
        _report_accuracy(main, coarse, scene, options)
        why += (f"; refined to {steps} after an estimated error of {first:.2g} at {steps // 2}"
                if first is not None else
                f"; refined to {steps}: the companion of the run at {steps // 2} failed")
    main.summary.scene, main.summary.dt_choice = scene_to_dict(scene), why
    _record_pilot(main, pilot, is_companion=coarse is pilot)
    return main


def _record_pilot(main: Result, pilot: Result, is_companion: bool) -> None:
    """The pilot run's step, efficiency and cost in ``main``'s ``extras["accuracy"]["pilot"]``."""
    main.summary.extras.setdefault("accuracy", {})["pilot"] = {
        "dt": pilot.summary.dt, "mean_efficiency": pilot.summary.mean_efficiency,
        "wall_time_s": pilot.summary.wall_time_s, "is_companion": is_companion}


def _kinematic_steps(scene: Scene, options: ExudynOptions) -> float:
    """Steps per revolution for the speed ratio; refused (SceneError) beyond the limits."""
    accuracy, beta = scene.numerics.accuracy, scene.joint.geometry.shaft_angle
    steps = kinematic_steps(beta, accuracy, options.node_type)
    refuse(scene, steps, f"a speed-ratio error of {accuracy:g} at {math.degrees(beta):g} deg")
    return steps


def _companion(scene: Scene, dt: float) -> Scene:
    """The companion run's scene: ``scene`` at the step ``dt`` [s], no time table."""
    return replace(scene, **{"numerics.dt": dt, "record.timeseries": False})


def loss_fraction(result: Result) -> float:
    """``1 - mean_efficiency`` of a run [-]; 1 (the most a joint can lose) without one."""
    return 1.0 if _failed(result) else min(abs(1.0 - result.summary.mean_efficiency), 1.0)


EXTRAPOLATION_GAIN_CAP = 0.95
"""The loop gain at which the extrapolated coupling escalates to the converged one
(``coupling.ESCALATE_GAIN``): its error amplification is taken at most ``1 / (1 - 0.95)``."""
MAX_COMPANION_RATIO = 3.0
"""The pilot run is the companion when the main step is at most this many times finer (else a
companion at exactly twice the main step runs): Richardson from far coarser steps is unreliable
(ratios up to 11.6 gave true/estimate 0.03-6)."""
MODEL_FLOOR = 1.0 / 3.0
"""At first order (the lagged coupling), and wherever friction reverses, the estimate is at least
this share of the a-priori model: the error there is irregular in the step (each reversal falls
elsewhere within its step), and the two runs can agree by chance (measured: 20 deg, 1500 rpm,
f = 0.2, angle drive: Richardson 2.0e-5 against a true 6.7e-5)."""


def _report_accuracy(main: Result, coarse: Result | None, scene: Scene, options: ExudynOptions) -> None:
    """The mean-efficiency error estimate of ``main`` into its summary (:func:`_estimate`; 0
    without friction), ``accuracy_met`` and a warning when the estimate exceeds the target; at a
    given step (not combined by Richardson), a warning too when the speed-ratio model predicts
    more than the target: the estimate and ``accuracy_met`` cover the mean efficiency only."""
    s = main.summary
    if _failed(main):
        return
    target = scene.numerics.accuracy
    predicted = None if scene.numerics.richardson else predicted_errors(scene, options.node_type)
    if predicted is not None and predicted["speed-ratio"] > target:
        s.warn(f"speed ratio: its error model predicts up to {predicted['speed-ratio']:.2g} at the given "
               f"dt, over the target {target:g} (the accuracy estimate covers the mean efficiency only)")
    info: dict = {"target": target}
    if coarse is None:
        estimate, info["method"] = 0.0, "no friction: nothing is lost, the efficiency is 1"
    else:
        estimate = _estimate(main, coarse, scene, options, info)
    s.extras["accuracy"] = info
    if estimate is None:  # no claim either way
        s.warn(f"no error estimate: {info['method']}; the accuracy {target:g} is not verified "
               f"(give a smaller --dt, or --accuracy for an automatic step)")
        return
    s.efficiency_error_estimate, s.accuracy_met = estimate, bool(estimate <= target)
    if not s.accuracy_met:
        s.warn(f"accuracy not met: estimated mean-efficiency error {estimate:.2g} > target {target:g} "
               f"(refine --dt or --accuracy)")


def _failed(run: Result) -> bool:
    """Whether a run gave no usable mean efficiency (not ``ok``, or none, or not finite)."""
    eta = run.summary.mean_efficiency
    return not (run.success and eta is not None and math.isfinite(eta))


def _estimate(main: Result, coarse: Result, scene: Scene, options: ExudynOptions,
              info: dict) -> float | None:
    """Richardson from ``coarse`` (at first order at least :data:`MODEL_FLOOR` of the a-priori
    model; at least the model when the companion is too coarse); None when the companion failed.
    How, into ``info``.

    A failed companion gives no estimate, not the model: the run it should check is then close
    to what fails at the coarser step (a friction loop near self-locking, where the model does
    not hold). Falling back to the model called ``paper-literal`` at 40 deg with friction 0.3
    (its companion self-locked) "accuracy met" at an estimated 9.7e-4 with a true error of
    1.4e-2."""
    s = main.summary
    steps, loss = revolution_period(scene) / s.dt, loss_fraction(main)
    order = convergence_order(scene)
    model = efficiency_error(scene, steps, loss, options.node_type)
    info.update(order=order, loss_fraction=loss,
                steps_per_revolution=steps, model=model, companion_dt=coarse.summary.dt,
                companion_status=str(coarse.summary.status),
                companion_mean_efficiency=coarse.summary.mean_efficiency,
                companion_wall_time_s=coarse.summary.wall_time_s)
    if _failed(coarse):
        info["method"] = (f"the companion run at {coarse.summary.dt:.3g} s ended {coarse.summary.status}"
                          if coarse.summary.dt else f"the companion run ended {coarse.summary.status}")
        return None
    ratio = coarse.summary.dt / s.dt
    info["richardson"] = richardson(s.mean_efficiency, coarse.summary.mean_efficiency, ratio, order)
    floored = order == 1 or bool(reversing_parts(scene))
    estimate = max(info["richardson"], MODEL_FLOOR * model if floored else 0.0)
    info["method"] = (f"Richardson, companion at {ratio:.3g} x the step, order {order}"
                      + (f", at least {MODEL_FLOOR:.2g} x the a-priori model" if floored else ""))
    if steps / ratio < MIN_COMPANION_STEPS:  # too coarse for the asymptotic range
        estimate = max(estimate, model)
        info["method"] += (f"; the companion's {steps / ratio:.3g} steps per revolution are "
                           f"too few to trust it: at least the a-priori model")
    return estimate


def run_once(scene: Scene, options: ExudynOptions) -> Result:
    """One Exudyn run of ``scene`` at its own step (given, or :func:`choose_step`'s), without the
    companion run and error estimate of :func:`run`."""
    summary, columns, origin = run_columns(scene, options)
    return _result(scene, summary, columns, origin)


def run_columns(scene: Scene, options: ExudynOptions) -> tuple[Summary, dict[str, np.ndarray] | None, float]:
    """One run as :func:`run_once` does it, before the table: its summary (means included), its
    columns on the model's clock (None when nothing usable was recorded) and the scene's time at
    the model's ``t = 0`` [s]."""
    summary, columns, origin, _ = _run_model(scene, options)
    return summary, columns, origin


def _run_model(scene: Scene, options: ExudynOptions, model: ExudynModel | None = None,
               means: bool = True) -> tuple[Summary, dict[str, np.ndarray] | None, float,
                                            ExudynModel | None]:
    """:func:`run_columns` and the model it solved (None when the loop did not close); ``model``
    solved again instead of a new build (:func:`solve`); ``means=False`` leaves the summary's
    means out (a caller that takes them from other columns)."""
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
        return summary, None, model.time_origin, model
    _check_columns(scene, model, columns, summary, options, means)
    return summary, columns, model.time_origin, model


def _result(scene: Scene, summary: Summary, columns: dict[str, np.ndarray] | None,
            origin: float) -> Result:
    """The result of a run's columns: the scene's own time (the means were taken before) and the
    table when the scene records one."""
    if columns is None:
        return Result(None, summary)
    columns["t"] = columns["t"] + origin
    table = result_table(columns, scene.record.every) if scene.record.timeseries else None
    return Result(table, summary)


def _richardson_run(scene: Scene, options: ExudynOptions) -> Result:
    """``scene`` at its step and at half of it, combined (:mod:`cardan_exudyn.model.richardson`):
    the fine run's summary with the combined table's means, the coarse run's step and grid, both
    runs' counters and wall time; ``extras["richardson"]`` says what was combined."""
    wall_start = time.perf_counter()
    origin = [0.0]
    built: list[ExudynModel | None] = [None]  # the coarse run's model, solved again at h/2

    def one(s: Scene) -> tuple[Summary, dict[str, np.ndarray] | None]:
        # both runs' means are replaced by the combined table's: not taken per run
        summary_, columns_, origin[0], model = _run_model(s, options, built[0], means=False)
        keep = model is not None and reusable(model, options.records_reactions(s))
        built[0] = model if keep else None
        return summary_, columns_

    coarse, fine, columns = two_step.run_pair(scene, one)
    summary = coarse if fine is None or not coarse.success else fine
    if summary is fine:
        summary.extras["richardson"] = {
            "coarse_dt": coarse.dt, "fine_dt": fine.dt, "coarse_wall_time_s": coarse.wall_time_s,
            "fine_wall_time_s": fine.wall_time_s, "extrapolated": list(two_step.EXTRAPOLATED),
            "from_fine": list(two_step.FROM_FINE), "recomputed": ["power_in", "power_out", "efficiency"]}
        summary.dt, summary.dt_choice = coarse.dt, f"{coarse.dt_choice}; Richardson with a run at dt/2"
        for key in ("steps", "newton_iterations", "jacobian_evaluations"):
            setattr(summary, key, (getattr(coarse, key) or 0) + (getattr(fine, key) or 0))
        if columns is not None and summary.success:
            summary.clear_means()
            means = summary.whole_revolution_means(columns, scene.record.skip_revolutions)
            if means is not None:
                summary.set_means(means)
    summary.scene = scene_to_dict(scene)
    summary.wall_time_s = time.perf_counter() - wall_start
    return _result(scene, summary, columns if summary is fine else None, origin[0])


def _check_columns(scene: Scene, model: ExudynModel, columns: dict[str, np.ndarray],
                   summary: Summary, options: ExudynOptions, means: bool = True) -> None:
    """Constraint violations, finiteness, the torque drive's turn, and the means into ``summary``
    (unless ``means`` is False)."""
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
        angle = (mbs_.GetNodeOutput(node, exu.OutputVariableType.Coordinates)[3]
                 + 2.0 * math.pi * model.input_turns.count)  # the continuous angle
        start.setdefault("angle", angle)
        return abs(angle - start["angle"]) < target - 1e-12

    model.user_functions.append(pre_step)
    model.mbs.SetPreStepUserFunction(pre_step)


