"""The a-priori error model of an Exudyn run and the time step it asks for.

With ``h = omega dt`` [rad] per step, ``beta`` the shaft angle and ``1 - eta`` the loss fraction:

- speed ratio (relative): ``K h^2``, ``K = c + f * ERROR_CONSTANT tan(beta)^2 / cos(beta)^2``,
  ``(c, f)`` of :data:`NODE_ERROR`;
- mean efficiency (absolute): ``(C2 + K) h^2 (1 - eta)``, plus ``C1 h (1 - eta)`` with the
  ``lagged`` coupling (first order).

The constants bound the measurements from above: docs/accuracy.md#step-model-constants.
"""

from __future__ import annotations

import math

from reference.scene.drives import AngleDrive, SpeedDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene
from reference.scene.validation import MAX_STEPS_PER_REVOLUTION, refuse_steps_per_revolution

__all__ = ["ERROR_CONSTANT", "MIN_STEPS_PER_REVOLUTION", "MAX_STEPS_PER_REVOLUTION", "NODE_ERROR",
           "EFFICIENCY_FIRST_ORDER", "EFFICIENCY_FIRST_ORDER_ERRORS", "EFFICIENCY_SECOND_ORDER",
           "SECONDS_PER_STEP", "SECONDS_PER_FRICTIONLESS_STEP", "MIN_COMPANION_STEPS", "error_coefficient",
           "steps_per_revolution", "choose_step", "revolution_period", "reversing_parts", "has_errors",
           "convergence_order", "efficiency_error", "efficiency_steps", "refuse", "plan_steps",
           "kinematic_steps", "richardson", "predicted_errors"]

ERROR_CONSTANT = 0.19
"""``K(beta) / (tan(beta)^2 / cos(beta)^2)`` of the speed-ratio error with Rxyz nodes [-]."""
MIN_STEPS_PER_REVOLUTION = 100
"""Fewest steps per input revolution of an automatic step."""
NODE_ERROR = {"Rxyz": (0.0, 1.0), "RotVecLG": (0.0, 2.0), "EP": (0.045, 2.2)}
"""``(c, f)`` per node type of spider and output: ``K = c + f * ERROR_CONSTANT tan^2 / cos^2``
(the quadratic Euler parameters carry an error even at zero shaft angle)."""


def error_coefficient(shaft_angle: float, node_type: str = "Rxyz") -> float:
    """``K`` [1/rad^2] of the speed-ratio error ``K h^2`` at ``shaft_angle`` [rad] for ``node_type``."""
    constant, factor = NODE_ERROR[node_type]
    t = math.tan(shaft_angle)
    return constant + factor * ERROR_CONSTANT * t * t / math.cos(shaft_angle) ** 2


def steps_per_revolution(shaft_angle: float, accuracy: float, node_type: str = "Rxyz") -> int:
    """Steps per input revolution meeting ``accuracy`` [-] on the speed ratio at ``shaft_angle`` [rad],
    at least :data:`MIN_STEPS_PER_REVOLUTION`; not capped (a capped step would miss the accuracy)."""
    return int(max(kinematic_steps(shaft_angle, accuracy, node_type), MIN_STEPS_PER_REVOLUTION))


def choose_step(scene: Scene, node_type: str = "Rxyz") -> tuple[float, str]:
    """``(dt [s], why)`` of a single run: the given ``numerics.dt``, else the speed ratio's step at the
    drive's top speed (dividing a revolution exactly); ``SceneError`` beyond the step limit."""
    if scene.numerics.dt is not None:
        return scene.numerics.dt, "given"
    beta = scene.joint.geometry.shaft_angle
    n = steps_per_revolution(beta, scene.numerics.accuracy, node_type)
    refuse(scene, n, f"a speed-ratio error of {scene.numerics.accuracy:g} at {math.degrees(beta):g} deg",
           SECONDS_PER_STEP if scene.has_friction else SECONDS_PER_FRICTIONLESS_STEP)
    period = 2.0 * math.pi / scene.drive.max_speed()
    why = (f"auto: {n} steps per input revolution for speed-ratio error "
           f"<= {scene.numerics.accuracy:g} at {math.degrees(beta):g} deg"
           + (f" with {node_type} nodes" if node_type != "Rxyz" else ""))
    if not isinstance(scene.drive, SpeedDrive):
        why += " (at the highest input speed of the drive)"
    return period / n, why


EFFICIENCY_FIRST_ORDER = 0.6
"""``C1`` [1/rad] of the first-order term ``C1 h (1 - eta)`` (``lagged`` coupling);
``python tests/benchmarks accuracy --fit`` refits it."""
EFFICIENCY_FIRST_ORDER_ERRORS = 3.5
"""``C1`` with mounting errors (their sliding reverses too, and sign changes cost more than the loss)."""
EFFICIENCY_SECOND_ORDER = 3.0
"""``C2`` [1/rad^2] of the smooth part, ``(C2 + K) (1 - eta) h^2``."""
SECONDS_PER_STEP = 3e-3
"""Wall time of one Exudyn step with friction [s] on one core, for a refusal's predicted run time."""
SECONDS_PER_FRICTIONLESS_STEP = 1e-4
"""Wall time of one frictionless Exudyn step [s] on one core, for a refusal's predicted run time."""
MIN_COMPANION_STEPS = 50
"""Fewest steps per revolution of a pilot or companion run; below it the estimate is at least the model."""


def revolution_period(scene: Scene) -> float:
    """Time of one input revolution at the drive's highest speed [s]."""
    return 2.0 * math.pi / scene.drive.max_speed()


def reversing_parts(scene: Scene) -> list[tuple[str, str]]:
    """The ``(pair, "rotation" | "sliding")`` motions with friction that may reverse (spider rotation
    at a shaft angle or with mounting errors, all sliding with mounting errors, frame rotation under
    a drive that may turn back): the error is first order there until the ramps are resolved."""
    pairs = dict(scene.joint.pairs.items())
    errors = has_errors(scene)
    drive = scene.drive
    turns_back = drive.kind == "torque" or (
        isinstance(drive, AngleDrive) and not _monotonic(drive.angle))
    parts = []
    for p in PAIR_NAMES:
        if pairs[p].friction_coefficient <= 0.0:
            continue
        spider = p in ("input_spider", "spider_output")
        if (spider and (scene.joint.geometry.shaft_angle > 0.0 or errors)) or (not spider and turns_back):
            parts.append((p, "rotation"))
        if errors:
            parts.append((p, "sliding"))
    return parts


def has_errors(scene: Scene) -> bool:
    """Whether the joint has mounting errors."""
    return any(getattr(scene.joint.errors, name) != 0.0 for name in scene.joint.errors.__dataclass_fields__)


def _monotonic(values: tuple) -> bool:
    steps = [b - a for a, b in zip(values[:-1], values[1:], strict=True)]
    return all(d > 0 for d in steps) or all(d < 0 for d in steps)


def convergence_order(scene: Scene) -> int:
    """Order of the mean efficiency's error in the step: 1 with the ``lagged`` coupling, else 2
    (friction's sign jumps are integrated across each side on its own)."""
    return 1 if scene.has_friction and scene.friction.coupling == "lagged" else 2


def efficiency_error(scene: Scene, steps: float, loss_fraction: float, node_type: str = "Rxyz") -> float:
    """A-priori mean-efficiency error [-] at ``steps`` per revolution and ``loss_fraction`` [-]
    (module formula); 0 without friction."""
    if not scene.has_friction:
        return 0.0
    h = 2.0 * math.pi / steps
    beta = scene.joint.geometry.shaft_angle
    smooth = EFFICIENCY_SECOND_ORDER + error_coefficient(beta, node_type)
    first = 0.0
    if scene.friction.coupling == "lagged":
        c1 = EFFICIENCY_FIRST_ORDER_ERRORS if has_errors(scene) else EFFICIENCY_FIRST_ORDER
        first = c1 * h * abs(loss_fraction)
    return first + smooth * h * h * abs(loss_fraction)


def efficiency_steps(scene: Scene, accuracy: float, loss_fraction: float, node_type: str = "Rxyz") -> int:
    """Fewest steps per revolution whose :func:`efficiency_error` meets ``accuracy`` [-] at
    ``loss_fraction`` [-]; not capped."""

    def meets(n: int) -> bool:
        return efficiency_error(scene, n, loss_fraction, node_type) <= accuracy

    low, high = 1, MIN_STEPS_PER_REVOLUTION
    while not meets(high):
        low, high = high, 2 * high
        if high > 1e15:  # far beyond any limit: the caller refuses
            return high
    while high - low > 1:  # the error falls as the steps grow: bisect
        middle = (low + high) // 2
        low, high = (low, middle) if meets(middle) else (middle, high)
    return high


def refuse(scene: Scene, steps: float, why: str, seconds_per_step: float = SECONDS_PER_STEP) -> None:
    """``SceneError`` when ``steps`` per revolution asked for by ``why`` exceed the limit, with the
    predicted run time at ``seconds_per_step`` [s] (a torque drive counts 4 times its revolutions)."""
    revolutions = scene.revolutions * (4.0 if scene.drive.kind == "torque" else 1.0)
    refuse_steps_per_revolution(steps, revolutions, seconds_per_step, why)


def plan_steps(scene: Scene, loss_fraction: float, node_type: str = "Rxyz",
               seconds_per_step: float = SECONDS_PER_STEP) -> tuple[int, str]:
    """``(steps, why)``: even steps per revolution meeting ``numerics.accuracy`` on the speed ratio and
    on the mean efficiency at ``loss_fraction`` [-]; ``SceneError`` beyond the limit."""
    accuracy = scene.numerics.accuracy
    beta = scene.joint.geometry.shaft_angle
    kinematic = kinematic_steps(beta, accuracy, node_type)
    refuse(scene, kinematic, f"a speed-ratio error of {accuracy:g} at {math.degrees(beta):g} deg",
           seconds_per_step)
    friction = efficiency_steps(scene, accuracy, loss_fraction, node_type) if scene.has_friction else 0
    refuse(scene, friction, f"a mean-efficiency error of {accuracy:g} (loss fraction "
                            f"{loss_fraction:.3g}, order {convergence_order(scene)})",
           seconds_per_step)
    n = max(kinematic, friction, MIN_STEPS_PER_REVOLUTION)
    n += n % 2  # even: the companion at twice the step
    why = (f"auto: {n} steps per input revolution for errors <= {accuracy:g} of the speed ratio "
           f"({kinematic}) and the mean efficiency ({friction} at loss fraction {loss_fraction:.3g})")
    return n, why


def kinematic_steps(shaft_angle: float, accuracy: float, node_type: str = "Rxyz") -> float:
    """Steps per revolution for relative speed-ratio error ``accuracy`` at ``shaft_angle`` [rad], not
    capped; :data:`MIN_STEPS_PER_REVOLUTION` where ``K`` is 0."""
    k = error_coefficient(shaft_angle, node_type)
    if k == 0.0:
        return MIN_STEPS_PER_REVOLUTION
    return math.ceil(2.0 * math.pi / math.sqrt(accuracy / k))


def richardson(fine: float, coarse: float, ratio: float, order: int) -> float:
    """Richardson estimate of ``fine``'s error: ``|fine - coarse| / (ratio**order - 1)``, ``ratio`` the
    coarse / fine step."""
    return abs(fine - coarse) / (ratio ** order - 1.0)


def predicted_errors(scene: Scene, node_type: str = "Rxyz") -> dict[str, float] | None:
    """A-priori ``{"speed-ratio", "mean-efficiency"}`` errors [-] at the given ``numerics.dt`` (the latter
    at loss fraction 1), before anything runs; None without a given step."""
    if scene.numerics.dt is None:
        return None
    steps = revolution_period(scene) / scene.numerics.dt
    h = 2.0 * math.pi / steps
    kinematic = error_coefficient(scene.joint.geometry.shaft_angle, node_type) * h * h
    return {"speed-ratio": kinematic, "mean-efficiency": efficiency_error(scene, steps, 1.0, node_type)}
