"""The MuJoCo engine's time step: the a-priori speed-ratio error model (recommended settings: RK4,
``solref`` from ``timeconst_steps``) and the step it chooses::

    err = C_H (tan(b) / cos(b))^2 h^1.5 + C_G |g| tc / omega,   h = omega dt,   tc = timeconst_steps dt

``b`` the shaft angle [rad], ``omega`` the drive's top speed [rad/s]: integration error at speed,
and gravity's drift within one constraint time constant.
Measured: docs/mujoco.md#error-model-and-the-automatic-step.
"""

from __future__ import annotations

import math

import numpy as np

from cardan_exudyn.mujoco.options import MujocoOptions
from reference.results.summary import OptionsError
from reference.scene.scene import Scene
from reference.scene.validation import refuse_steps_per_revolution

__all__ = ["ERROR_CONSTANT_SPEED", "ERROR_CONSTANT_GRAVITY", "MIN_STEPS_PER_REVOLUTION", "SECONDS_PER_STEP",
           "speed_ratio_error_model", "choose_timestep"]

ERROR_CONSTANT_SPEED = 1.5e-4
"""``C_H`` of :func:`speed_ratio_error_model` [-].
Measured: docs/mujoco.md#error-model-and-the-automatic-step."""
ERROR_CONSTANT_GRAVITY = 1e-4
"""``C_G`` of :func:`speed_ratio_error_model` [1/m].
Measured: docs/mujoco.md#error-model-and-the-automatic-step."""
MIN_STEPS_PER_REVOLUTION = 100
"""Fewest steps per input revolution the automatic step takes."""
SECONDS_PER_STEP = 1e-4
"""One RK4 step on one core [s], for a refused step count's run time. Measured: docs/mujoco.md#cost."""


def speed_ratio_error_model(scene: Scene, options: MujocoOptions, steps: int) -> float:
    """Predicted largest error of ``omega_out / omega_in`` [-] at ``steps`` per input revolution (the
    module's model; recommended settings only).

    Parameters
    ----------
    scene : Scene
        Shaft angle, the drive's top speed and gravity are read.
    options : MujocoOptions
        ``timeconst_steps`` is read.
    steps : int
        Steps per input revolution.
    """
    beta = scene.joint.geometry.shaft_angle
    omega = scene.drive.max_speed()
    h = 2.0 * math.pi / steps
    timeconst = options.timeconst_steps * h / omega
    gravity = float(np.linalg.norm(scene.gravity))
    return (ERROR_CONSTANT_SPEED * (math.tan(beta) / math.cos(beta)) ** 2 * h**1.5
            + ERROR_CONSTANT_GRAVITY * gravity * timeconst / omega)


def choose_timestep(scene: Scene, options: MujocoOptions) -> tuple[float, str]:
    """``(dt [s], why)``: the options' ``timestep``, else ``numerics.dt``, else the fewest steps per
    revolution (at least :data:`MIN_STEPS_PER_REVOLUTION`) whose model meets ``numerics.accuracy``.

    Raises
    ------
    OptionsError
        No step given and settings other than those the model was measured with.
    SceneError
        The accuracy needs more steps than allowed.
    """
    if options.timestep is not None:
        return options.timestep, "given (engine settings)"
    if scene.numerics.dt is not None:
        return scene.numerics.dt, "given (scene)"
    if options.integrator != "RK4" or options.solref is not None:
        raise OptionsError("the automatic time step is measured for RK4 with `solref` from "
                           f"`timeconst_steps` only; give `timestep` for integrator "
                           f"{options.integrator!r} and solref {options.solref!r}")
    accuracy = scene.numerics.accuracy
    n = _fewest_steps(scene, options, accuracy)
    target = f"a speed-ratio error of {accuracy:g} at {math.degrees(scene.joint.geometry.shaft_angle):g} deg"
    # a torque drive may take four times the span at its initial speed (drive_plan)
    refuse_steps_per_revolution(n, scene.revolutions * (4.0 if scene.drive.kind == "torque" else 1.0),
                                SECONDS_PER_STEP, target)
    why = f"auto: {n} steps per input revolution for {target} at most (error model of docs/mujoco.md)"
    return 2.0 * math.pi / scene.drive.max_speed() / n, why


def _fewest_steps(scene: Scene, options: MujocoOptions, accuracy: float) -> int:
    """The fewest steps per revolution (at least :data:`MIN_STEPS_PER_REVOLUTION`) whose predicted
    error is at most ``accuracy``: doubling, then bisection."""
    low = MIN_STEPS_PER_REVOLUTION
    high = MIN_STEPS_PER_REVOLUTION
    while speed_ratio_error_model(scene, options, high) > accuracy and high < 2**60:  # falls with h
        low = high
        high = 2 * high
    while high - low > 1:  # the smallest count in (low, high] that meets the accuracy
        middle = (low + high) // 2
        if speed_ratio_error_model(scene, options, middle) <= accuracy:
            high = middle
        else:
            low = middle
    return high
