"""Choosing the time step from the scene.

For a second-order integrator the error of the output/input speed ratio of a Cardan joint
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

from reference.scene import Scene, SpeedDrive

ERROR_CONSTANT = 0.19
MIN_STEPS_PER_REVOLUTION = 100
MAX_STEPS_PER_REVOLUTION = 2_000_000


NODE_ERROR = {"Rxyz": (0.0, 1.0), "RotVecLG": (0.0, 2.0), "EP": (0.045, 2.2)}


def error_coefficient(shaft_angle: float, node_type: str = "Rxyz") -> float:
    """``K`` of the error model ``K h^2`` [-] for the node type of spider and output."""
    constant, factor = NODE_ERROR[node_type]
    t = math.tan(shaft_angle)
    return constant + factor * ERROR_CONSTANT * t * t / math.cos(shaft_angle) ** 2


def steps_per_revolution(shaft_angle: float, accuracy: float, node_type: str = "Rxyz") -> int:
    """Steps per input revolution that meet ``accuracy`` on the speed ratio."""
    k = error_coefficient(shaft_angle, node_type)
    if k == 0.0:
        return MIN_STEPS_PER_REVOLUTION
    n = math.ceil(2.0 * math.pi / math.sqrt(accuracy / k))
    return int(min(max(n, MIN_STEPS_PER_REVOLUTION), MAX_STEPS_PER_REVOLUTION))


def choose_step(scene: Scene, node_type: str = "Rxyz") -> tuple[float, str]:
    """Time step [s] for the scene and a sentence saying how it was chosen.

    With a constant-speed drive the step divides one revolution exactly, so that averages over
    whole revolutions need no interpolation at the window ends.
    """
    if scene.numerics.dt is not None:
        return scene.numerics.dt, "given"
    beta = scene.joint.geometry.shaft_angle
    n = steps_per_revolution(beta, scene.numerics.accuracy, node_type)
    period = 2.0 * math.pi / scene.drive.max_speed()
    why = (f"auto: {n} steps per input revolution for speed-ratio error "
           f"<= {scene.numerics.accuracy:g} at {math.degrees(beta):g} deg"
           + (f" with {node_type} nodes" if node_type != "Rxyz" else ""))
    if not isinstance(scene.drive, SpeedDrive):
        why += " (at the highest input speed of the drive)"
    return period / n, why
