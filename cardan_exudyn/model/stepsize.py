"""Choosing the time step from the scene, and the a-priori error of the mean efficiency.

``numerics.accuracy`` is the target absolute error of the mean efficiency (the headline number)
and of the relative speed-ratio error. The step meets both: the speed-ratio model below
(:func:`steps_per_revolution`) and the mean-efficiency model (:func:`efficiency_error`), which
needs the run's loss fraction ``1 - eta`` (the engine takes it from a companion run at a coarser
step, :func:`cardan_exudyn.model.solve.run`). ``docs/accuracy.md`` has the measurements.

Speed ratio. For a second-order integrator the error of the output/input speed ratio of a Cardan joint
grows as ``K(beta) * h**2`` with ``h = omega * dt`` the input angle step. Measured with this
model (generalized-alpha, spectral radius 0.6, Rxyz nodes; the ``exudyn default`` ladders of
``cardan bench`` re-measure it: 5.8e-6 at 10 deg and 200 steps per revolution, 8.8e-6 at 35 deg
and 800, against 6.0e-6 and 8.6e-6 predicted), ``K(beta) = 0.19 tan(beta)^2 / cos(beta)^2``
holds within 10 % for beta up to 50 deg and over-estimates the error above (so the step is
conservative there): the speed ratio peaks at ``1/cos(beta)`` with a width proportional to
``cos(beta)``, and the step must resolve it.

The other node types of the spider and output (``ExudynOptions.node_type``) integrate other
rotation coordinates and carry more error at the same step (measured by ``cardan stress``'s map and
at 400 steps per revolution, 0 to 80 deg): Lie-group rotation vectors up to 1.9 ``K(beta)``,
Euler parameters ``0.045 + 2.2 K(beta)`` (the constant: the quadratic Euler parameters are not
integrated exactly even at zero shaft angle, where ``K = 0``). ``NODE_ERROR`` holds
``(constant, factor)`` per node type; both bound the measurements from above up to 80 deg.
"""

from __future__ import annotations

import math

from reference.scene.drives import AngleDrive, SpeedDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene
from reference.scene.validation import MAX_STEPS_PER_REVOLUTION, refuse_steps_per_revolution

__all__ = ["ERROR_CONSTANT", "MIN_STEPS_PER_REVOLUTION", "MAX_STEPS_PER_REVOLUTION", "NODE_ERROR",
           "EFFICIENCY_FIRST_ORDER", "EFFICIENCY_FIRST_ORDER_ERRORS", "EFFICIENCY_SECOND_ORDER",
           "SECONDS_PER_STEP", "SECONDS_PER_FRICTIONLESS_STEP",
           "MIN_COMPANION_STEPS", "error_coefficient", "steps_per_revolution", "choose_step",
           "reversing_parts", "has_errors", "convergence_order",
           "efficiency_error",
           "efficiency_steps",
           "plan_steps", "richardson", "revolution_period", "refuse", "kinematic_steps",
           "predicted_errors"]

ERROR_CONSTANT = 0.19
MIN_STEPS_PER_REVOLUTION = 100


NODE_ERROR = {"Rxyz": (0.0, 1.0), "RotVecLG": (0.0, 2.0), "EP": (0.045, 2.2)}


def error_coefficient(shaft_angle: float, node_type: str = "Rxyz") -> float:
    """``K`` of the error model ``K h^2`` [-] for the node type of spider and output."""
    constant, factor = NODE_ERROR[node_type]
    t = math.tan(shaft_angle)
    return constant + factor * ERROR_CONSTANT * t * t / math.cos(shaft_angle) ** 2


def steps_per_revolution(shaft_angle: float, accuracy: float, node_type: str = "Rxyz") -> int:
    """Steps per input revolution that meet ``accuracy`` on the speed ratio, at least
    :data:`MIN_STEPS_PER_REVOLUTION`; not capped (the caller refuses beyond
    :data:`MAX_STEPS_PER_REVOLUTION`, :func:`refuse`): a capped step would miss the accuracy."""
    return int(max(kinematic_steps(shaft_angle, accuracy, node_type), MIN_STEPS_PER_REVOLUTION))


def choose_step(scene: Scene, node_type: str = "Rxyz") -> tuple[float, str]:
    """Time step [s] for the scene and a sentence saying how it was chosen.

    With a constant-speed drive the step divides one revolution exactly, so that averages over
    whole revolutions need no interpolation at the window ends.

    Raises :class:`SceneError` (:func:`refuse`, before anything runs) when no step is given and
    ``numerics.accuracy`` on the speed ratio needs more than :data:`MAX_STEPS_PER_REVOLUTION`.
    """
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
"""``C1`` [1/rad] of the mean-efficiency model's first-order term, ``C1 h r`` with ``h`` the input
angle per step [rad] and ``r`` the loss fraction; only the ``lagged`` coupling has it now
(:func:`convergence_order`). It was fitted while every coupling's reversals were first order
(the trapezoid across friction's sign jumps), which bounds the lagged coupling's too.
Envelope of the measured ``error / (r h)`` without mounting errors:
``paper-10deg`` 0.54 and 0.46 at 50 and 100 steps per revolution, the accuracy grid's cells at
most 0.24 (``cardan accuracy --fit`` refits it)."""
EFFICIENCY_FIRST_ORDER_ERRORS = 3.5
"""``C1`` with mounting errors: their sliding reverses too, and its sign changes cost far more
than its small loss (measured ``error / (r h)`` = 2.8-3.2 at 15 deg, 2000 rpm, f = 0.05, 100-800 steps per
revolution)."""
EFFICIENCY_SECOND_ORDER = 3.0
"""``C2`` [1/rad^2]: the smooth part, error <= ``(C2 + K) (1 - eta) h^2`` (measured at 35 deg,
``paper-35deg``: -7.5e-3, -3.1e-3 at 100, 150 steps per revolution, ``error / ((1 - eta) h^2)``
= 2.5, 2.4 with ``K`` = 0.14 included; the grid's second-order cells at 0 deg: at most 0.04)."""
SECONDS_PER_STEP = 3e-3
"""Wall time of one Exudyn step with friction [s] on one core (measured 2.3 ms at 10 deg), for the
predicted run time of a refused request before anything ran."""
SECONDS_PER_FRICTIONLESS_STEP = 1e-4
"""Wall time of one Exudyn step without friction [s] on one core (measured 61-110 us at 10 deg,
2000-100000 steps per revolution), for the predicted run time of a refused request."""
MIN_COMPANION_STEPS = 50
"""Fewest steps per revolution of the companion run (half :data:`MIN_STEPS_PER_REVOLUTION`)."""


def revolution_period(scene: Scene) -> float:
    """Time of one input revolution at the drive's highest speed [s]: steps per revolution are
    counted against it."""
    return 2.0 * math.pi / scene.drive.max_speed()


def reversing_parts(scene: Scene) -> list[tuple[str, str]]:
    """The ``(pair, "rotation" | "sliding")`` motions with friction that may reverse: the spider
    pairs' rotation at a shaft angle or with mounting errors, every pair's sliding with mounting
    errors, the frame pairs' rotation under a drive that may turn back (an angle history that is
    not monotonic; a torque drive, conservatively). Their friction changes sign inside steps: the
    error is first order until the ramps are resolved."""
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
    """Order of convergence of the mean efficiency in the step: 1 with the ``lagged`` coupling
    (friction one step late), else 2.

    Friction's sign jumps at reversals used to make it 1 until the steps resolved the sign ramps:
    the table's trapezoid put each jump in the middle of its step. The window integral now
    integrates each side of a jump on its own (:mod:`reference.results.quadrature`): on the reference
    engine's own rows of ``paper-literal-10deg`` the error fell from 1.1e-3, 5.3e-4, 2.5e-4 to
    1.1e-4, 3.7e-5, 1.9e-6 at 200, 400, 800 steps per revolution, and Exudyn's (converged
    coupling) from 1.0e-3, 5.2e-4, 2.5e-4 to 2.1e-5, 2.0e-5, -1.9e-6."""
    return 1 if scene.has_friction and scene.friction.coupling == "lagged" else 2


def efficiency_error(scene: Scene, steps: float, loss_fraction: float, node_type: str = "Rxyz") -> float:
    """A-priori error [-] of the mean efficiency at ``steps`` per revolution, for a run losing
    ``loss_fraction`` (``1 - eta``) of its input work: ``(C2 + K) h^2 (1 - eta)``, plus
    ``C1 h r`` with the ``lagged`` coupling (friction one step late: first order), ``r`` the
    loss fraction, ``C1`` larger with mounting errors; ``K`` the speed-ratio coefficient
    (:func:`error_coefficient`). The other couplings have no first-order term: friction's sign
    jumps are integrated across (:func:`convergence_order`)."""
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
    """Fewest steps per revolution whose :func:`efficiency_error` meets ``accuracy`` (may exceed
    :data:`MAX_STEPS_PER_REVOLUTION`: the caller refuses)."""

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
    """Raise :class:`SceneError` when ``steps`` per revolution exceed the limits: the predicted
    steps and run time (at ``seconds_per_step`` [s]), in one line
    (:func:`reference.scene.validation.refuse_steps_per_revolution`; a torque drive counted as 4 times
    its revolutions, the time it is allowed)."""
    revolutions = scene.revolutions * (4.0 if scene.drive.kind == "torque" else 1.0)
    refuse_steps_per_revolution(steps, revolutions, seconds_per_step, why)


def plan_steps(scene: Scene, loss_fraction: float, node_type: str = "Rxyz",
               seconds_per_step: float = SECONDS_PER_STEP) -> tuple[int, str]:
    """Steps per revolution meeting ``numerics.accuracy`` on the speed ratio and, for a run
    losing ``loss_fraction`` of its input work (:func:`efficiency_error`), on the mean
    efficiency; and why.

    Raises :class:`SceneError` (:func:`refuse`) beyond :data:`MAX_STEPS_PER_REVOLUTION`."""
    accuracy, beta = scene.numerics.accuracy, scene.joint.geometry.shaft_angle
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
    """Steps per revolution for a speed-ratio error ``accuracy``, not capped (may be huge)."""
    k = error_coefficient(shaft_angle, node_type)
    if k == 0.0:
        return MIN_STEPS_PER_REVOLUTION
    return math.ceil(2.0 * math.pi / math.sqrt(accuracy / k))


def richardson(fine: float, coarse: float, ratio: float, order: int) -> float:
    """Richardson estimate [-] of the error of ``fine`` from ``coarse`` at ``ratio`` times its
    step: ``|fine - coarse| / (ratio**order - 1)``."""
    return abs(fine - coarse) / (ratio ** order - 1.0)


def predicted_errors(scene: Scene, node_type: str = "Rxyz") -> dict[str, float] | None:
    """A-priori errors [-] of a run at the scene's given ``numerics.dt``, before anything runs:
    ``{"speed-ratio": ..., "mean-efficiency": ...}``, the speed-ratio model and the
    mean-efficiency model at the largest loss fraction (1; 0 without friction, where nothing is
    lost); None without a given step. Named apart because a run's error estimate covers the mean
    efficiency only: a frictionless run is exact there at any step."""
    if scene.numerics.dt is None:
        return None
    steps = revolution_period(scene) / scene.numerics.dt
    h = 2.0 * math.pi / steps
    kinematic = error_coefficient(scene.joint.geometry.shaft_angle, node_type) * h * h
    return {"speed-ratio": kinematic, "mean-efficiency": efficiency_error(scene, steps, 1.0, node_type)}
