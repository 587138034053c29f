"""A torque drive's integration needs besides the dynamics: its speed tolerance and an evaluation
budget, so a drive that cannot turn its joint ends as an incomplete run with a reason.
"""

from __future__ import annotations

import bisect
import math

from reference.scene.scene import Scene

__all__ = ["ODE_EVALUATIONS_PER_REVOLUTION", "ODE_EVALUATIONS_PER_KNOT", "EvaluationBudget", "Stalled",
           "speed_tolerance"]

ODE_EVALUATIONS_PER_REVOLUTION = 20_000
"""Right-hand-side evaluations a torque drive's integration may spend per requested revolution
(at least one revolution's worth), plus :data:`ODE_EVALUATIONS_PER_KNOT`. Why: a drive that
cannot overcome its load and friction from (near) rest creeps inside the friction's sign ramps
or rocks about an equilibrium for the whole time allowed; a run that turns stays far below.
Measured: docs/engines.md#constants-of-the-reference-engine."""
ODE_EVALUATIONS_PER_KNOT = 1_000
"""More evaluations per load-history sample the integration has passed (each is a kink of the
acceleration). Measured: docs/engines.md#constants-of-the-reference-engine."""


def speed_tolerance(atol: float, initial_speed: float, initial_acceleration: float,
                    angle: float) -> float:
    """Absolute tolerance [rad/s] on a torque drive's speed: ``atol`` relative to ``initial_speed``
    [rad/s], but at least the speed error that moves the angle by ``atol`` [rad] in the time
    ``sqrt(2 angle / |initial_acceleration|)`` [s]. Why: a drive starting at rest reaches speeds set by
    its acceleration. Measured: docs/engines.md#constants-of-the-reference-engine.
    """
    return max(atol * abs(initial_speed), atol * math.sqrt(abs(initial_acceleration) / (2.0 * angle)))


class Stalled(Exception):
    """A torque drive's integration spent its evaluation budget (raised inside the integrator) at time
    ``t`` [s], angle ``theta`` [rad], speed ``theta_t`` [rad/s] after ``evaluations``; ``reason`` says
    how far ``scene``'s drive got and what to change.
    """

    def __init__(self, scene: Scene, t: float, theta: float, theta_t: float, evaluations: int) -> None:
        super().__init__(t, theta, theta_t)
        self.t = t
        self.theta = theta
        self.theta_t = theta_t
        drive = scene.drive
        self.reason = (
            f"torque drive turned {abs(theta) / (2 * math.pi):.3g} of {scene.revolutions:g} "
            f"revolutions in {t:.3g} s (speed then {theta_t:.3g} rad/s) and was stopped after "
            f"{evaluations} right-hand-side evaluations, its budget: a drive torque "
            f"({drive.torque:g} N m) that does not overcome the load and friction leaves the joint "
            f"creeping near rest or rocking about an equilibrium; raise the drive torque or the "
            f"initial speed ({drive.initial_speed:.3g} rad/s)")


class EvaluationBudget:
    """Counts (``count``) a torque drive's right-hand-side evaluations and stops past
    :data:`ODE_EVALUATIONS_PER_REVOLUTION` per revolution plus :data:`ODE_EVALUATIONS_PER_KNOT` per
    load-history sample passed.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.count = 0
        self._base = ODE_EVALUATIONS_PER_REVOLUTION * max(1.0, scene.revolutions)
        self._knots = scene.load.knots.tolist()

    def spend(self, t: float, theta: float, theta_t: float) -> None:
        """Count one evaluation at ``t`` [s], ``theta`` [rad], ``theta_t`` [rad/s]; :class:`Stalled` (not
        counted) when the budget is spent.
        """
        if self.count >= self._base and (
                self.count >= self._base + ODE_EVALUATIONS_PER_KNOT * bisect.bisect_right(self._knots, t)):
            raise Stalled(self.scene, t, theta, theta_t, self.count)
        self.count += 1
