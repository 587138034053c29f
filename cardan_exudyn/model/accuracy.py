"""The Exudyn runs a scene takes to meet ``numerics.accuracy``, and their mean-efficiency error
estimate (``docs/accuracy.md``). With friction a companion at H = 2..3 times the main step h gives

    err = |eta_h - eta_H| / ((H / h)^p - 1),

never below a share of the a-priori model where the error is irregular in the step. An automatic
step is planned by a pilot run and refined once if the estimate misses the target.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from dataclasses import replace as replace_fields
from typing import NamedTuple

from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.richardson import run_combined
from cardan_exudyn.model.solve import run_once, torque_step_hint
from cardan_exudyn.model.stepsize import (
    MAX_STEPS_PER_REVOLUTION,
    MIN_COMPANION_STEPS,
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
from reference.results.accuracy import CompanionRun, PilotRun, RunAccuracy
from reference.results.result import Result
from reference.results.summary import Status
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene

__all__ = ["EXTRAPOLATION_GAIN_CAP", "MAX_COMPANION_RATIO", "MODEL_FLOOR", "run", "PilotPlan",
           "Verdict", "pilot_plan", "pilot_gain", "assess", "publish", "failed", "loss_fraction"]

EXTRAPOLATION_GAIN_CAP = 0.95
"""The loop gain at which the extrapolated coupling escalates to the converged one: a plan without an
estimate takes its error amplification as at most ``1 / (1 - 0.95)``."""
MAX_COMPANION_RATIO = 3.0
"""The pilot is the companion when the main step is at most this many times finer; else a
companion at exactly twice the main step runs. Measured: docs/accuracy.md#accuracy-constants."""
MODEL_FLOOR = 1.0 / 3.0
"""Share of the a-priori model the estimate never falls below at first order and wherever
friction reverses: there the error is irregular in the step and two runs can agree by chance.
Measured: docs/accuracy.md#accuracy-constants."""


def run(scene: Scene, options: ExudynOptions | None = None) -> Result:
    """Simulate ``scene`` with Exudyn, with the estimated error of its mean efficiency.

    A given ``numerics.dt`` runs with a companion at twice the step; an automatic step is planned by
    a pilot. ``numerics.richardson`` (frictionless only): the Richardson combination of the step and
    its half.

    Parameters
    ----------
    scene : Scene
    options : ExudynOptions, optional
        ``error_estimate=False``: no companion and no estimate.

    Returns
    -------
    Result
        The main run: ``summary.efficiency_error_estimate``, ``accuracy_met`` (None without an
        estimate), ``accuracy``; ``wall_time_s`` of every run it took.

    Raises
    ------
    SceneError
        ``numerics.accuracy`` needs more steps than allowed; ``numerics.richardson`` with friction.
    """
    options = options or ExudynOptions()
    wall_start = time.perf_counter()
    if scene.numerics.richardson or not scene.has_friction:
        result = run_combined(scene, options) if scene.numerics.richardson else run_once(scene, options)
        if not failed(result):
            _speed_ratio_warning(result, scene, options)
            publish(result, RunAccuracy(target=scene.numerics.accuracy,
                                        method="no friction: nothing is lost, the efficiency is 1"), 0.0)
        return result
    if scene.numerics.dt is not None:
        if not options.error_estimate:
            return run_once(scene, options)
        main = _given_step_runs(scene, options)
    else:
        main = _automatic_runs(scene, options) if options.error_estimate else _planned_run(scene, options)
        if main.summary.status == Status.INTEGRATION_FAILURE:
            main.summary.reason += torque_step_hint(scene)
    main.summary.wall_time_s = time.perf_counter() - wall_start  # the pilot and companions too
    return main


def _given_step_runs(scene: Scene, options: ExudynOptions) -> Result:
    """A given step: the companion at twice the step, then the main run with its estimate."""
    coarse = run_once(_companion(scene, 2.0 * scene.numerics.dt), options)
    main = run_once(scene, options)
    verdict = assess(main, coarse, scene, options)
    if verdict is not None:
        _speed_ratio_warning(main, scene, options)
        publish(main, *verdict)
    return main


def _speed_ratio_warning(main: Result, scene: Scene, options: ExudynOptions) -> None:
    """Warn in ``main``'s summary when the speed-ratio model predicts more than the target at a given
    step (the estimate covers the mean efficiency only)."""
    predicted = None if scene.numerics.richardson else predicted_errors(scene, options.node_type)
    target = scene.numerics.accuracy
    if predicted is not None and predicted["speed-ratio"] > target:
        main.summary.warn(f"speed ratio: its error model predicts up to {predicted['speed-ratio']:.2g} at "
                          f"the given dt, over the target {target:g} (the accuracy estimate covers the "
                          f"mean efficiency only)")


@dataclass(frozen=True)
class PilotPlan:
    """The pilot run (no table) of an automatic step, its ``pilot_steps`` and the main run's ``steps``
    per revolution (even, at least twice the pilot's), and ``why`` for ``summary.dt_choice``."""

    pilot: Result
    pilot_steps: int
    steps: int
    why: str


class Verdict(NamedTuple):
    """A main run's estimate and how it was made (:func:`assess`)."""

    record: RunAccuracy
    estimate: float | None
    """Estimated absolute error of the mean efficiency [-]; None without one."""


def pilot_plan(scene: Scene, options: ExudynOptions) -> PilotPlan:
    """Run the pilot of an automatic step (half the speed-ratio step, at least ``MIN_COMPANION_STEPS``
    per revolution; a failed pilot loses everything) and plan the main run's steps from its losses."""
    period = revolution_period(scene)
    pilot_steps = max(MIN_COMPANION_STEPS, math.ceil(0.5 * _kinematic_steps(scene, options)))
    pilot = run_once(_companion(scene, period / pilot_steps), options)
    cost = pilot.summary.wall_time_s / max(pilot.summary.steps or 1, 1)
    steps, why = plan_steps(scene, loss_fraction(pilot), options.node_type, cost)
    if not pilot.success:
        why += (f" (the pilot at {pilot_steps} steps per revolution ended {pilot.summary.status}: "
                f"its loss fraction taken as 1, the most a joint can lose)")
    return PilotPlan(pilot, pilot_steps, max(steps, 2 * pilot_steps), why)


def _planned_run(scene: Scene, options: ExudynOptions) -> Result:
    """An automatic step without the estimate: pilot and main run; with the extrapolated coupling the
    steps grow by ``sqrt(1 / (1 - g))`` (pilot loop gain ``g``), as its error ``~ 1 / (1 - g)`` is
    left out of the model."""
    plan = pilot_plan(scene, options)
    steps = plan.steps
    why = plan.why
    if scene.friction.coupling == "extrapolated":
        gain, said = pilot_gain(plan.pilot)
        factor = math.sqrt(1.0 / (1.0 - gain))
        steps = math.ceil(steps * factor / 2.0) * 2
        why += f"; x{factor:.2f} for the extrapolated coupling at {said}"
        refuse(scene, steps, f"a mean-efficiency error of {scene.numerics.accuracy:g} with the "
                             f"extrapolated coupling")
    main = run_once(replace(scene, **{"numerics.dt": revolution_period(scene) / steps}), options)
    main.summary.scene = scene_to_dict(scene)
    main.summary.dt_choice = why + "; no error estimate (ExudynOptions.error_estimate is off)"
    publish(main, RunAccuracy(pilot=_pilot_record(plan.pilot, is_companion=False)), None)
    return main


def pilot_gain(pilot: Result) -> tuple[float, str]:
    """The loop gain a plan without an estimate allows for, in [0, :data:`EXTRAPOLATION_GAIN_CAP`], and
    its text: the pilot's largest probe; 0 when probes saw the friction not move; else the cap."""
    gain = pilot.summary.max_friction_loop_gain
    if pilot.success and gain is not None and math.isfinite(gain):
        return min(max(gain, 0.0), EXTRAPOLATION_GAIN_CAP), f"loop gain {gain:.2f}"
    friction = pilot.summary.friction
    probes = (friction.gain_probes if friction is not None else None) or 0
    if pilot.success and probes > 0:
        return 0.0, f"no loop gain ({probes} probes saw the friction not move)"
    return EXTRAPOLATION_GAIN_CAP, (f"loop gain {EXTRAPOLATION_GAIN_CAP:g}, where the coupling escalates "
                                    f"(the pilot measured none)")


def _automatic_runs(scene: Scene, options: ExudynOptions) -> Result:
    """The runs of an automatic step: pilot plans ``n`` steps (the pilot is the companion when ``n`` is at
    most :data:`MAX_COMPANION_RATIO` times its steps, else one at ``n / 2`` runs); refined once to
    ``2 n`` when the estimate misses the target or the companion alone failed."""
    period = revolution_period(scene)
    plan = pilot_plan(scene, options)
    steps = plan.steps
    why = plan.why
    coarse = plan.pilot
    if steps > MAX_COMPANION_RATIO * plan.pilot_steps:
        coarse = run_once(_companion(scene, 2.0 * period / steps), options)
    main = run_once(replace(scene, **{"numerics.dt": period / steps}), options)
    verdict = assess(main, coarse, scene, options)
    if _refine(verdict, main, coarse, scene) and 2 * steps <= MAX_STEPS_PER_REVOLUTION:
        first = verdict.estimate
        coarse = main
        steps = 2 * steps
        main = run_once(replace(scene, **{"numerics.dt": period / steps}), options)
        verdict = assess(main, coarse, scene, options)
        why += (f"; refined to {steps} after an estimated error of {first:.2g} at {steps // 2}"
                if first is not None else
                f"; refined to {steps}: the companion of the run at {steps // 2} failed")
    main.summary.scene = scene_to_dict(scene)
    main.summary.dt_choice = why
    verdict = verdict or Verdict(RunAccuracy(), None)
    pilot = _pilot_record(plan.pilot, is_companion=coarse is plan.pilot)
    publish(main, replace_fields(verdict.record, pilot=pilot), verdict.estimate)
    return main


def _refine(verdict: Verdict | None, main: Result, coarse: Result, scene: Scene) -> bool:
    """Whether an automatic step is refined: the estimate exceeds the target, or the companion failed."""
    if verdict is None:
        return False
    estimate = verdict.estimate
    if estimate is None:
        return failed(coarse) and not failed(main)
    return not estimate <= scene.numerics.accuracy


def _pilot_record(pilot: Result, is_companion: bool) -> PilotRun:
    """The pilot's step [s], mean efficiency [-], wall time [s] and role."""
    s = pilot.summary
    return PilotRun(dt=s.dt, mean_efficiency=s.mean_efficiency, wall_time_s=s.wall_time_s,
                    is_companion=is_companion)


def _kinematic_steps(scene: Scene, options: ExudynOptions) -> float:
    """Steps per revolution for the speed ratio; refused (SceneError) beyond the limits."""
    accuracy = scene.numerics.accuracy
    beta = scene.joint.geometry.shaft_angle
    steps = kinematic_steps(beta, accuracy, options.node_type)
    refuse(scene, steps, f"a speed-ratio error of {accuracy:g} at {math.degrees(beta):g} deg")
    return steps


def _companion(scene: Scene, dt: float) -> Scene:
    """The scene of a companion or pilot run: ``scene`` at the step ``dt`` [s], no time table."""
    return replace(scene, **{"numerics.dt": dt, "record.timeseries": False})


def failed(result: Result) -> bool:
    """Whether a run gave no usable mean efficiency (not ``ok``, or none, or not finite)."""
    eta = result.summary.mean_efficiency
    return not (result.success and eta is not None and math.isfinite(eta))


def loss_fraction(result: Result) -> float:
    """``1 - mean_efficiency`` of a run [-]; 1 (the most a joint can lose) without one."""
    return 1.0 if failed(result) else min(abs(1.0 - result.summary.mean_efficiency), 1.0)


def publish(main: Result, record: RunAccuracy, estimate: float | None) -> None:
    """Write ``record`` as ``main``'s ``summary.accuracy`` and, against its target, ``estimate`` [-] as
    ``efficiency_error_estimate`` and ``accuracy_met`` (a warning when over or missing)."""
    s = main.summary
    s.accuracy = record
    target = record.target
    if target is None:
        return
    if estimate is None:  # no claim either way
        s.warn(f"no error estimate: {record.method}; the accuracy {target:g} is not verified "
               f"(give a smaller --dt, or --accuracy for an automatic step)")
        return
    s.efficiency_error_estimate = estimate
    s.accuracy_met = bool(estimate <= target)
    if not s.accuracy_met:
        s.warn(f"accuracy not met: estimated mean-efficiency error {estimate:.2g} > target {target:g} "
               f"(refine --dt or --accuracy)")


def assess(main: Result, coarse: Result, scene: Scene,
           options: ExudynOptions) -> Verdict | None:
    """``main``'s mean-efficiency error estimate against companion ``coarse``: Richardson at
    ``convergence_order``, at least :data:`MODEL_FLOOR` x the a-priori model at first order or
    where friction reverses, at least the model when the companion is under ``MIN_COMPANION_STEPS``.
    Estimate None when the companion failed (near self-locking the model does not hold); None
    without a usable ``main``."""
    if failed(main):
        return None
    s = main.summary
    c = coarse.summary
    steps = revolution_period(scene) / s.dt
    loss = loss_fraction(main)
    order = convergence_order(scene)
    model = efficiency_error(scene, steps, loss, options.node_type)
    known = RunAccuracy(target=scene.numerics.accuracy, order=order, loss_fraction=loss,
                        steps_per_revolution=steps, model=model,
                        companion=CompanionRun(dt=c.dt, status=str(c.status),
                                               mean_efficiency=c.mean_efficiency,
                                               wall_time_s=c.wall_time_s))
    if failed(coarse):
        method = (f"the companion run at {c.dt:.3g} s ended {c.status}" if c.dt else
                  f"the companion run ended {c.status}")
        return Verdict(replace_fields(known, method=method), None)
    ratio = c.dt / s.dt
    extrapolated = richardson(s.mean_efficiency, c.mean_efficiency, ratio, order)
    floored = order == 1 or bool(reversing_parts(scene))
    estimate = max(extrapolated, MODEL_FLOOR * model if floored else 0.0)
    method = (f"Richardson, companion at {ratio:.3g} x the step, order {order}"
              + (f", at least {MODEL_FLOOR:.2g} x the a-priori model" if floored else ""))
    if steps / ratio < MIN_COMPANION_STEPS:
        estimate = max(estimate, model)
        method += (f"; the companion's {steps / ratio:.3g} steps per revolution are "
                   f"too few to trust it: at least the a-priori model")
    return Verdict(replace_fields(known, richardson=extrapolated, method=method), estimate)
