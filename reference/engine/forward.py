"""Forward dynamics of a torque-driven scene at one state, from precomputed Fourier series.

With one degree of freedom the Newton-Euler system is

    K(theta) x = R0(theta) + theta_t^2 R2(theta) + T_load U(theta) - T_in e - W(theta) phi,

``K`` and ``W`` depending on the input angle only, the slot speeds ``theta_t`` times functions of
it. So ``K^-1 R0``, ``K^-1 R2``, ``K^-1 U``, ``K^-1 e``, ``K^-1 W`` and the unit slot speeds are
held as Fourier series of one revolution (:mod:`reference.engine.series`), and a call solves
``phi = G(x0 - S phi)`` (eqs. (3), (5)) by Newton's method, warm-started from the previous call.
Measured: docs/engines.md#constants-of-the-reference-engine.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reference.engine.dynamics import solve_dynamics
from reference.engine.friction_newton import WARM_START_GAIN, friction_newton
from reference.engine.newton_euler import DRIVE_ROW, reaction_system
from reference.engine.series import TAU, TrigSeries, fit_periodic
from reference.engine.slots import (
    FrictionLaw,
    friction_matrix,
    friction_slots,
    slot_bands,
    slot_signs,
    slot_speeds,
)
from reference.physics.joint_motion import joint_motion
from reference.physics.loop_closure import LoopClosureError
from reference.scene.scene import Scene

__all__ = ["GRID_SIZES", "METHODS", "PART_SCALE", "ForwardDynamics", "ForwardState", "angle_functions",
           "direct_acceleration", "right_hand_side"]

GRID_SIZES = (64, 128, 256, 512, 1024, 2048)
"""Grid points per revolution tried in turn until the series is resolved."""
PART_SCALE = 1024.0
"""Speed [rad/s], acceleration [rad/s^2] and load [N m] at which the system's parts are taken:
large, so that their differences from the state at rest keep all digits (gravity and the
centrifugal terms would cost the direct solve's difference of accelerations 0 and 1 about three),
and a power of two, so that the divisions are exact."""

Acceleration = Callable[[float, float, float], tuple[float, bool]]
"""``(t [s], theta [rad], theta_t [rad/s]) -> (theta_tt [rad/s^2], self_locking)``."""


def angle_functions(scene: Scene, slots: list[tuple[str, str]], n: int) -> dict[str, np.ndarray]:
    """The angle-only parts of the system on ``n`` angles ``2 pi j / n`` for ``scene``'s ``slots`` (K):
    ``x0``, ``x2``, ``xu``, ``xd`` (n, 18), ``K^-1`` times the right-hand side at rest, per
    ``theta_t^2`` [1/s^2], per unit load and per unit drive torque; ``s`` (n, 18, K), ``K^-1 W``; ``v``
    (n, K), slot speeds per unit input speed [m/rad]. LoopClosureError where the loop does not close.
    """
    theta = TAU * np.arange(n) / n
    # four blocks: at rest, then a speed, an acceleration and a load so large that their parts
    # dominate the rest's (gravity) and survive the difference to rounding
    big = np.array([PART_SCALE ** 2, PART_SCALE, PART_SCALE])
    speed = np.repeat([0.0, PART_SCALE, 0.0, 0.0], n)
    accel = np.repeat([0.0, 0.0, PART_SCALE, 0.0], n)
    load = np.repeat([0.0, 0.0, 0.0, PART_SCALE], n)
    motion = joint_motion(scene.joint, np.tile(theta, 4), speed, accel)
    matrix, rhs = reaction_system(scene, motion, load)
    rest = rhs[:n]
    parts = (rhs.reshape(4, n, 18)[1:] - rhs[:n]) / big[:, None, None]
    matrix = matrix[:n].copy()
    matrix[:, :, -1] = -parts[1]  # the acceleration's share moves to the left, as in solve_dynamics
    drive = np.zeros((n, 18))
    drive[:, DRIVE_ROW] = 1.0
    wrenches = friction_matrix(motion, slots)[:n]
    columns = np.concatenate([np.stack([rest, parts[0], parts[2], drive], -1), wrenches], -1)
    solved = np.linalg.solve(matrix, columns)
    unit = slice(n, 2 * n)
    v = (slot_speeds(scene, slots, {p: w[unit] for p, w in motion.omega_rel.items()},
                     {p: w[unit] for p, w in motion.slide_rel.items()}) / PART_SCALE
         if slots else np.zeros((n, 0)))
    return {"x0": solved[..., 0], "x2": solved[..., 1], "xu": solved[..., 2], "xd": solved[..., 3],
            "s": solved[..., 4:], "v": v}


@dataclass(frozen=True)
class ForwardState:
    """The forward dynamics at one state: input ``acceleration`` [rad/s^2], ``friction`` (K,) [N m or N],
    ``converged``, Newton's ``iterations``, and ``loop_gain``: the friction loop Jacobian's spectral
    radius, or an upper bound where that is below :data:`WARM_START_GAIN` (infinite when not
    converged).
    """

    acceleration: float
    friction: np.ndarray
    converged: bool
    loop_gain: float
    iterations: int

    @property
    def self_locking(self) -> bool:
        """No converged fixed point, or a loop gain of 1 or more."""
        return not (self.converged and self.loop_gain < 1.0)


class ForwardDynamics:
    """The input acceleration of a torque-driven ``scene`` at one state, from the precomputed
    ``series`` (:func:`_layout`'s ``parts``, 2 or 3 with a load history, side by side) of the ``active``
    slots (those that can rub).

    Build with :meth:`of_scene`; call as the integrator's ``(t, theta, theta_t) -> (theta_tt,
    self_locking)`` or :meth:`solve`. Not thread-safe (the last call's friction starts the next).
    """

    def __init__(self, scene: Scene, series: TrigSeries, active: np.ndarray, parts: int) -> None:
        slots = friction_slots(scene)
        law = FrictionLaw(scene, slots)
        k = active.size
        self.scene = scene
        self.slots = slots
        self.active = active
        self.series = series
        self._frequencies = series.frequencies
        self._phases = series.phases
        # the series of the parts per unit theta_t^2 (and load) stacked under the base's
        self._table = np.concatenate(np.split(series.table, parts, 1))
        self._cut = (4 * k * (k + 1), 4 * k * (k + 1) + k + 1)
        self._factors = -np.stack([law.k_force, law.k_moment], -1)[active].ravel()
        self._bands = slot_bands(scene, slots)
        self._coupled = scene.friction.coupling != "uncoupled"
        self._history = scene.load.evaluator()
        self._start: np.ndarray | None = None  # the last call's friction: Newton's warm start
        bands = self._bands[active]
        pair = [slots[j][0] for j in active]
        # the signs on the active slots without the general code's checks (all bands > 0)
        self._inverse_band = 1.0 / bands if np.all(bands > 0.0) else None
        self._same_pair = np.array([[p == q for q in pair] for p in pair], dtype=float)
        self._resultant = scene.friction.law == "resultant"
        # the paper's law with ramps: each friction value's factor is clip(theta_t v / band), so
        # the series gives v / band, once per norm the value multiplies
        self._ramps = not self._resultant and self._inverse_band is not None
        if self._ramps:
            speed = self._table[:, self._cut[1]:] * self._inverse_band
            self._table = np.concatenate([self._table[:, :self._cut[1]], np.repeat(speed, 2, 1)], 1)
        self._basis = np.empty(self._table.shape[0])

    @classmethod
    def of_scene(cls, scene: Scene, torque_in: float) -> ForwardDynamics | None:
        """Fit the series for ``scene`` at drive torque ``torque_in`` [N m]; None where the loop does not
        close at some angle or no grid of :data:`GRID_SIZES` resolves the series.
        """
        slots = friction_slots(scene)
        index = FrictionLaw(scene, slots).index
        for n in GRID_SIZES:
            try:
                f = angle_functions(scene, slots, n)
            except LoopClosureError:
                return None
            # a slot whose speed is zero at every angle (no sliding in the ideal joint) never rubs
            active = np.nonzero(np.any(f["v"] != 0.0, 0))[0]
            parts = _layout(scene, torque_in, f, index[active], active)
            series = fit_periodic(np.concatenate(parts, 1), np.concatenate(
                [np.full(p.shape[1], np.max(np.abs(p), initial=0.0)) for p in parts]))
            if series is not None:
                return cls(scene, series, active, len(parts))
        return None

    def _friction(self, theta: float, theta_t: float, load: float | None) -> tuple:
        """``(theta_tt, phi, converged, loop_gain, iterations)`` on the active slots."""
        u = self._basis
        m = self._frequencies.size
        np.cos(self._frequencies * (theta % TAU) - self._phases, out=u[:m])
        np.multiply(u[:m], theta_t * theta_t, out=u[m:2 * m])
        if self._history is not None:
            np.multiply(u[:m], load, out=u[2 * m:])
        f = u @ self._table
        k = self.active.size
        last = f[self._cut[0]:self._cut[1]]
        if k == 0:
            return float(last[0]), np.zeros(0), True, 0.0, 0
        if self._ramps:
            ks = np.clip(theta_t * f[self._cut[1]:], -1.0, 1.0) * self._factors
        else:
            ks = np.repeat(self._signs(theta_t * f[self._cut[1]:]), 2) * self._factors
        sxa = f[:self._cut[0]].reshape(4 * k, k + 1)
        phi, converged, gain, iterations = friction_newton(sxa, ks, self._coupled, self._start)
        if self._start is not None and not gain < WARM_START_GAIN:  # near locking: as solve_friction
            phi, converged, gain, iterations = friction_newton(sxa, ks, self._coupled)
        if not self._coupled:  # as solve_dynamics: the frictionless solution, friction beside it
            return float(last[k]), phi, converged, gain, iterations
        self._start = phi if converged else None
        return float(last[k] - last[:k] @ phi), phi, converged, gain, iterations

    def solve(self, theta: float, theta_t: float, load: float | None = None) -> ForwardState:
        """:class:`ForwardState` at input angle ``theta`` [rad], speed ``theta_t`` [rad/s] and output
        ``load`` [N m] (None: the scene's constant load).
        """
        if self._history is not None and load is None:
            raise ValueError("the scene's load is a torque history: pass `load` [N m]")
        accel, phi, converged, gain, iterations = self._friction(theta, theta_t, load)
        friction = np.zeros(len(self.slots))
        friction[self.active] = phi
        return ForwardState(accel, friction, converged, gain, iterations)

    def _signs(self, speed: np.ndarray) -> np.ndarray:
        """:func:`reference.engine.slots.slot_signs` on the active slots (speeds [m/s], shape (K,))."""
        if self._inverse_band is None:
            speeds = np.zeros(len(self.slots))
            speeds[self.active] = speed
            return slot_signs(self.scene, self.slots, speeds, self._bands)[self.active]
        if self._resultant:  # the slot's component of its pair's regularised unit slip vector
            return speed / np.maximum(np.sqrt((speed * speed) @ self._same_pair), 1.0 / self._inverse_band)
        return np.clip(speed * self._inverse_band, -1.0, 1.0)

    def __call__(self, t: float, theta: float, theta_t: float) -> tuple[float, bool]:
        """``(theta_tt [rad/s^2], self_locking)`` at time ``t`` [s] (the load history's time)."""
        accel, _, converged, gain, _ = self._friction(
            theta, theta_t, None if self._history is None else self._history(t))
        return accel, not (converged and gain < 1.0)


def _layout(scene: Scene, torque_in: float, f: dict[str, np.ndarray], rows: np.ndarray,
            active: np.ndarray) -> list[np.ndarray]:
    """The grid functions in :class:`ForwardDynamics`' column order, one array (n, M) per part:
    the base (drive torque and a constant load folded in), per ``theta_t^2``, per load torque (a
    history only). Columns: per active slot and pair component ``[S row, x]`` (K, 4, K + 1), the
    acceleration's ``[S row, x]`` (K + 1), the unit slot speeds (K)."""
    n = f["x0"].shape[0]
    k = active.size
    last = f["x0"].shape[1] - 1
    constant = scene.load.constant
    base = f["x0"] - torque_in * f["xd"] + (float(scene.load.torque) * f["xu"] if constant else 0.0)
    s = f["s"][..., active]

    def columns(x: np.ndarray, response: np.ndarray, speeds: np.ndarray) -> np.ndarray:
        slot_part = np.concatenate([response[:, rows], x[:, rows, None]], -1).reshape(n, -1)
        return np.concatenate([slot_part, response[:, last], x[:, last, None], speeds], 1)

    zero = np.zeros_like(s)
    out = [columns(base, s, f["v"][:, active]), columns(f["x2"], zero, np.zeros((n, k)))]
    if not constant:
        out.append(columns(f["xu"], zero, np.zeros((n, k))))
    return out


def direct_acceleration(scene: Scene, torque_in: float, t: float, theta: float, theta_t: float,
                        bands: np.ndarray | None = None) -> tuple[float, bool]:
    """``(theta_tt [rad/s^2], self_locking)`` at time ``t`` [s], ``theta`` [rad], ``theta_t`` [rad/s]
    by :func:`reference.engine.dynamics.solve_dynamics`; ``bands`` (K,) [m/s] the slots' ramp widths
    (None: looked up).
    """
    _, fixed = solve_dynamics(scene, np.array([theta]), np.array([theta_t]), torque_in=torque_in,
                              load_torque=scene.load.at(np.array([t])), bands=bands)
    return float(fixed.x[0, -1]), bool(fixed.self_locking[0])


METHODS = ("auto", "series", "direct")


def right_hand_side(scene: Scene, torque_in: float, method: str = "auto") -> Acceleration:
    """``(t, theta, theta_t) -> (theta_tt, self_locking)`` for ``scene`` at drive torque ``torque_in``
    [N m]; ``method`` ``"series"`` (:class:`ForwardDynamics`, ValueError where it cannot be built),
    ``"direct"`` (:func:`direct_acceleration`) or ``"auto"`` (the series, else direct).
    """
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    if method != "direct":
        fast = ForwardDynamics.of_scene(scene, torque_in)
        if fast is not None:
            return fast
        if method == "series":
            raise ValueError("the forward dynamics' series cannot be built for this scene (the loop "
                             "does not close at some angle, or the grid does not resolve it)")
    bands = slot_bands(scene, friction_slots(scene))  # once: one sample per call
    return lambda t, theta, theta_t: direct_acceleration(scene, torque_in, t, theta, theta_t, bands)
