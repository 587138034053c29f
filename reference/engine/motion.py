"""The input's motion over a run for each drive kind: constant speed and angle history in closed form,
a torque drive integrated by ``solve_ivp`` (DOP853) with the forward dynamics'
(:mod:`reference.engine.forward`) acceleration.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference.engine.options import ReferenceOptions
from reference.engine.torque_ode import EvaluationBudget, Stalled, speed_tolerance
from reference.results.summary import Status
from reference.scene.drives import AngleDrive, SpeedDrive, TorqueDrive
from reference.scene.scene import Scene

__all__ = ["InputMotion", "SelfLocking", "input_motion"]


class SelfLocking(Exception):
    """Friction has no finite consistent value at instant ``t`` [s], input angle ``theta`` [rad] (raised
    inside the integrator).
    """

    def __init__(self, t: float, theta: float) -> None:
        super().__init__(t, theta)
        self.t = t
        self.theta = theta


@dataclass
class InputMotion:
    """The input's motion over the span ``[t0, t_end]`` [s]: ``state(t) -> (theta, theta_t, theta_tt |
    None)`` vectorised (None: the dynamics supply it), ``torque_in`` [N m] of a torque drive,
    ``knots`` [s], ``status``/``reason`` of an early end, ``ode_evaluations``, ``periodic`` (every
    revolution repeats the first) and ``tabulated`` (False: no state to tabulate).
    """

    t0: float
    t_end: float
    state: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray | None]]
    torque_in: float | None = None
    knots: np.ndarray = field(default_factory=lambda: np.zeros(0))
    status: Status = Status.OK
    reason: str = ""
    ode_evaluations: int = 0
    periodic: bool = False
    tabulated: bool = True

    def angle(self, t: float) -> float:
        """Input angle [rad] at one instant."""
        return float(np.asarray(self.state(np.array([t]))[0]).ravel()[0])


def _speed_motion(scene: Scene, drive: SpeedDrive) -> InputMotion:
    w = drive.speed
    t_end = 2.0 * math.pi * scene.revolutions / abs(w)
    return InputMotion(0.0, t_end, lambda t: (w * np.asarray(t, float),
                                             np.full(np.shape(t), w),
                                             np.zeros(np.shape(t))), periodic=scene.load.constant)


def _angle_motion(scene: Scene, drive: AngleDrive) -> InputMotion:
    spline = drive.spline()
    t0 = drive.time[0]
    # a history shorter than the span ends first; the means say how many revolutions it holds
    t_end = drive.time_to_turn(2.0 * math.pi * scene.revolutions)
    return InputMotion(t0, float(t_end), lambda t: (spline(t), spline(t, 1), spline(t, 2)),
                       knots=np.asarray(drive.time))


def _torque_motion(scene: Scene, drive: TorqueDrive, options: ReferenceOptions) -> InputMotion:
    budget = EvaluationBudget(scene)
    rhs = _torque_rhs(scene, drive, budget)
    try:
        sol = _integrate(scene, drive, options, rhs)
    except SelfLocking as exc:
        return _stopped(drive, budget, exc.t, Status.SELF_LOCKING,
                        f"friction self-locks at t = {exc.t:.6g} s, input angle "
                        f"{math.degrees(exc.theta):.6g} deg: no consistent friction")
    except Stalled as exc:
        return _stopped(drive, budget, exc.t, Status.INCOMPLETE, exc.reason)
    return _integrated(scene, drive, sol, budget.count)


def _torque_rhs(scene: Scene, drive: TorqueDrive,
                budget: EvaluationBudget) -> Callable[[float, np.ndarray], np.ndarray]:
    """The ODE ``(t, [theta, theta_t]) -> [theta_t, theta_tt]``, each call counted on ``budget``;
    :class:`SelfLocking` where friction has no consistent value.
    """
    from reference.engine.forward import right_hand_side  # scipy.linalg: imported with scipy.integrate

    acceleration = right_hand_side(scene, drive.torque)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        theta = float(y[0])
        theta_t = float(y[1])
        budget.spend(t, theta, theta_t)
        theta_tt, locked = acceleration(t, theta, theta_t)
        if locked:
            raise SelfLocking(t, theta)
        return np.array([theta_t, theta_tt])

    return rhs


def _integrate(scene: Scene, drive: TorqueDrive, options: ReferenceOptions,
               rhs: Callable[[float, np.ndarray], np.ndarray]) -> Any:
    """``solve_ivp``'s solution from rest at angle 0, stopped once the input has turned the scene's
    revolutions either way or at the time every engine allows.
    """
    from scipy.integrate import solve_ivp  # scipy.integrate takes ~0.5 s to import

    target = 2.0 * math.pi * scene.revolutions
    w0 = drive.initial_speed

    def reached(t: float, y: np.ndarray) -> float:
        return abs(y[0]) - target

    reached.terminal = True
    a0 = float(rhs(0.0, np.array([0.0, w0]))[1])
    return solve_ivp(rhs, (0.0, drive.time_allowed(target)), [0.0, w0], method="DOP853",
                     dense_output=True, events=reached, rtol=options.ode_rtol,
                     atol=[options.ode_atol, speed_tolerance(options.ode_atol, w0, a0, target)])


def _stopped(drive: TorqueDrive, budget: EvaluationBudget, t_end: float, status: Status,
             reason: str) -> InputMotion:
    """A motion stopped inside the integrator at ``t_end`` [s]: nothing to tabulate."""
    return InputMotion(0.0, t_end, lambda t: (np.nan, np.nan, None), drive.torque, status=status,
                       reason=reason, ode_evaluations=budget.count, tabulated=False)


def _integrated(scene: Scene, drive: TorqueDrive, sol: Any, evaluations: int) -> InputMotion:
    """The motion from ``solve_ivp``'s solution ``sol``: its dense output up to the stop."""
    if not sol.success:
        return InputMotion(0.0, float(sol.t[-1]), sol.sol, drive.torque,
                           status=Status.INTEGRATION_FAILURE, reason=sol.message,
                           ode_evaluations=evaluations, tabulated=bool(sol.t[-1] > 0.0))
    t_end = float(sol.t_events[0][0]) if sol.t_events[0].size else float(sol.t[-1])
    dense = sol.sol

    def state(t):
        y = dense(np.asarray(t, float))
        return y[0], y[1], None

    motion = InputMotion(0.0, t_end, state, drive.torque, ode_evaluations=evaluations)
    if not sol.t_events[0].size:
        motion.status = Status.INCOMPLETE
        motion.reason = (f"torque drive turned {abs(sol.y[0, -1]) / (2 * math.pi):.3g} of "
                         f"{scene.revolutions:g} revolutions in the time allowed")
    return motion


def input_motion(scene: Scene, options: ReferenceOptions) -> InputMotion:
    """:class:`InputMotion` for ``scene``'s drive (on the run's clock), a torque drive integrated with
    ``options``' ODE tolerances.
    """
    drive = scene.drive
    if isinstance(drive, SpeedDrive):
        return _speed_motion(scene, drive)
    if isinstance(drive, AngleDrive):
        return _angle_motion(scene, drive)
    if isinstance(drive, TorqueDrive):
        return _torque_motion(scene, drive, options)
    raise NotImplementedError(f"the reference engine has no {drive.kind!r} drive")
