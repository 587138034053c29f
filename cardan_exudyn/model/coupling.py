"""Friction of eqs. (1)-(5) in the Exudyn model, computed from the pairs' reaction outputs.

What is added to the model
--------------------------
For each pair with a non-zero friction coefficient (and only for those): a body-fixed
``LoadTorqueVector`` about the pair axis on each non-ground body of the pair, and for cylindrical
pairs of a joint with mounting errors a body-fixed ``LoadForceVector`` along the axis, applied at
the pair point of each body. The ideal joint's cylindrical pairs cannot slide (their axial friction
is 0, as the reference engine computes it); the solver leaves their slide with noise at the Newton
tolerance (1e-11..1e-10 m/s with a measured angle drive), which the sign ramp would turn into an
axial force that changes with every solve: at 0 deg, where the true friction is only the weights',
the fixed point could not converge below it and the run stopped as self-locking.
Body ``b`` receives the friction (torque ``M_z``, force ``F_z``), body ``a`` the opposite. Both
load vectors are fixed in their body because the pair axis is fixed in both bodies of the pair.

How the friction is updated (``scene.friction.coupling``)
---------------------------------------------------------
One Python post-Newton user function (``mbs.SetPostNewtonUserFunction``) reads, after each
converged Newton solve, the pair reactions (the joints' ``ForceLocal`` / ``TorqueLocal`` outputs;
only their magnitudes normal to the pair axis enter eqs. (3)-(5), and these do not depend on
which of the two pair frames, rotated about the axis, they are expressed in; the raw Lagrange
multipliers are not used: for the joint to ground their force part is in global components)
and the relative speeds (BDF2 derivatives of the pairs' relative coordinates, see
``engine.relative_speeds``), computes the friction and sets the loads with ``SetLoadParameter``.
Before the first step the friction is iterated to consistency with the initial state
(``FrictionCoupling.initialise``), so no scheme starts frictionless.

- ``lagged`` (the paper's scheme): the function returns zero error, so the friction computed at
  the end of step n acts during step n+1. First order in the step size (the friction is one
  step late).
- ``converged``: the function returns the relative change of the friction as the error of
  Exudyn's *discontinuous iteration*; Exudyn repeats the Newton solve of the same step with the
  updated friction until the change is below ``tolerance``. The friction applied in a step is
  then the friction of that step's own reactions (a fixed point per step), and the error of the
  mean efficiency falls at the integrator's order (second). When a step is accepted, the
  friction for the next step is predicted by linear extrapolation of the last two steps, which
  only shortens the iteration (the fixed point does not depend on it).

Self-locking
------------
The fixed-point iteration contracts with the loop gain of the friction feedback (friction ->
reactions -> friction). In the converged scheme the ratio of successive corrections estimates
it (``loop_gain_estimate`` in the summary); a step whose iteration stalls (residual reduced by
less than ``STALL_RATIO`` after ``max_iterations``) has no consistent friction state and stops
the run with status ``self_locking``; a step that still converges but slowly is counted in
``unconverged_steps`` and the run goes on. In the lagged scheme every step is one iteration of the same map,
so a gain >= 1 shows as geometric growth of the friction from step to step: growth by more than
a factor 1e3 over consecutive growing steps stops the run with status ``self_locking``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cardan_exudyn.model.friction_law import PairLaw, bdf2_weights, pair_loads
from reference.bands import sign_bands
from reference.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES
from reference.schema import Status

# geometric growth of the friction (lagged scheme) taken as self-locking
LAGGED_GROWTH_LIMIT = 1e3
# converged scheme: a step whose fixed-point residual shrank less than this after
# max_iterations is taken as self-locking (no consistent friction state)
STALL_RATIO = 0.1
# the loop-gain diagnostic (spectral radius of the secant map) is taken every this many steps
GAIN_EVERY = 4
# the fixed-point tolerance is relative to the largest friction load, but at least to this
# fraction of the largest load the pairs would carry sliding: when every rubbing pair is at rest
# (inside its sign ramp, e.g. the spider pairs at 0 deg) the loads are rounding noise of the
# relative speeds, and a tolerance relative to the noise itself is never met (the step then
# stalled and was reported as self-locking)
REST_FLOOR = 1e-6


# state of the ground in the per-body tuples (rotation, angular velocity, velocity, position)
_GROUND = (np.eye(3), np.zeros(3), np.zeros(3), np.zeros(3))


@dataclass
class _PairData:
    name: str
    kind: str
    law: PairLaw
    joint: int                          # the pair's ObjectJointGeneric
    bodies: tuple[str, str]
    local: tuple[np.ndarray, np.ndarray]  # pair point in each body's node frame
    axis_local: np.ndarray              # pair axis in node frames (same for a and b)
    torque_loads: list = field(default_factory=list)  # (load number, +1 for b / -1 for a)
    force_loads: list = field(default_factory=list)


@dataclass
class FrictionLog:
    """Per accepted step: its time, the friction in effect in its final solve, evaluations."""

    t: list = field(default_factory=list)
    applied: list = field(default_factory=list)   # per pair (M_z, F_z) in effect in the solve
    iterations: list = field(default_factory=list)


class FrictionCoupling:
    """Friction loads of a model and the user functions that update them (see module doc)."""

    def __init__(self, model: Any) -> None:
        scene = model.scene
        self.model = model
        self.mbs = model.mbs
        self.settings = scene.friction
        self.bands = sign_bands(scene)  # per pair (rotation, sliding, resultant) [m/s], as every engine
        self.converged = scene.friction.coupling == "converged"
        self.pairs: list[_PairData] = []
        for name, pair in scene.joint.friction_pairs():
            if pair.friction_coefficient <= 0.0:
                continue
            frame = model.pair_frames[name]
            law = PairLaw.of(PAIR_KIND[name], pair, scene.friction.law)
            p = _PairData(name=name, kind=PAIR_KIND[name], law=law, joint=model.joints[name],
                          bodies=PAIR_BODIES[name], local=model.marker_local[name],
                          axis_local=frame[:, 2].copy())
            for role, body, local in zip((-1, 1), p.bodies, p.local, strict=True):
                if body == "ground":
                    continue
                marker = self.mbs.AddMarker(eii.MarkerBodyRigid(
                    bodyNumber=model.bodies[body], localPosition=list(local)))
                p.torque_loads.append((self.mbs.AddLoad(eii.LoadTorqueVector(
                    markerNumber=marker, loadVector=[0.0, 0.0, 0.0], bodyFixed=True)), role))
                # the ideal joint's cylindrical pairs cannot slide: their axial friction is 0 (as
                # the reference's); the law would turn the solver's noise in the slide into force
                if p.kind == "cylindrical" and scene.joint.errors.any:
                    p.force_loads.append((self.mbs.AddLoad(eii.LoadForceVector(
                        markerNumber=marker, loadVector=[0.0, 0.0, 0.0], bodyFixed=True)), role))
            self.pairs.append(p)
        self.n = len(self.pairs)
        self.applied = np.zeros((self.n, 2))
        self.log = FrictionLog()
        self.initial: np.ndarray | None = None  # friction consistent with the initial state
        self._accepted: list[np.ndarray] = []
        self._step_t = None
        self._step_iter = 0
        self._xs: list[np.ndarray] = []
        self._gs: list[np.ndarray] = []
        self._step_gain = 0.0
        self._gains: list[float] = []
        self._broyden_b = None
        self._load_axes: list | None = None
        self._accepted_steps = 0
        mask = np.zeros((self.n, 2), dtype=bool)
        self._weight = np.ones((self.n, 2))
        for k, p in enumerate(self.pairs):
            mask[k, 0] = True
            mask[k, 1] = bool(p.force_loads)
            self._weight[k, 1] = 0.5 * p.law.d
        self._mask = mask.ravel()
        self.unconverged_steps = 0
        self.status, self.reason = Status.OK, ""
        self.error: Exception | None = None  # raised inside the user function (see post_newton)
        self.scale_floor = 0.0  # set by evaluate (REST_FLOOR)
        self._growth_steps, self._growth_start = 0, 0.0
        self._ode2 = {}

    def prepare(self) -> None:
        """Look up coordinate indices (after ``mbs.Assemble``) and register the user functions."""
        for name, node in self.model.nodes.items():
            start = self.mbs.GetNodeODE2Index(node)
            rot = self.model.rotations[name]
            reference = None if rot.zero_reference else np.asarray(rot.reference)
            # rotation coordinates [start + 3, end), the node type's frame function and reference
            # coordinates (None when zero)
            self._ode2[name] = (start, start + 3 + rot.size, rot.frame_one, reference)
        self._history = [(self.model.start_time, self._pair_coordinates(self._body_states()))]
        self.mbs.SetPostNewtonUserFunction(self.post_newton)
        self.model.user_functions.append(self.post_newton)

    def configure(self, settings: Any) -> None:
        """Discontinuous-iteration settings for the chosen coupling."""
        d = settings.timeIntegration.discontinuous
        d.iterationTolerance = self.settings.tolerance if self.converged else 1.0
        d.maxIterations = self.settings.max_iterations + 1 if self.converged else 1
        d.ignoreMaxIterations = True
        d.useRecommendedStepSize = False

    def _body_states(self) -> dict[str, tuple]:
        sd = self.mbs.systemData
        q = sd.GetODE2Coordinates(exu.ConfigurationType.Current)
        q_t = sd.GetODE2Coordinates_t(exu.ConfigurationType.Current)
        states = {}
        for name, (i, end, frame, reference) in self._ode2.items():
            p = q[i + 3:end]
            a, omega = frame(p if reference is None else p + reference, q_t[i + 3:end])
            states[name] = (a, omega, np.asarray(q_t[i:i + 3]),
                            self.model.com_reference[name] + np.asarray(q[i:i + 3]))
        return states

    def _pair_coordinates(self, states: dict[str, tuple]) -> np.ndarray:
        """Per pair: relative rotation angle of b about the axis, and axial slide of b [m].

        Computed from positions, which index-3 integration keeps on the constraint manifold to
        the Newton tolerance; their time derivatives are the relative speeds used by the law.
        """
        coords = np.zeros((self.n, 2))
        for k, p in enumerate(self.pairs):
            a_a, _, _, r_a = states.get(p.bodies[0], _GROUND)
            a_b, _, _, r_b = states.get(p.bodies[1], _GROUND)
            frame = self.model.pair_frames[p.name]
            # (A_a F)^T (A_b F): only its first column is needed, (x_a . x_b, y_a . x_b)
            x_b = a_b @ frame[:, 0]
            x_a, y_a = a_a @ frame[:, 0], a_a @ frame[:, 1]
            coords[k, 0] = math.atan2(float(y_a @ x_b), float(x_a @ x_b))
            if p.kind == "cylindrical":
                d = (r_b + a_b @ p.local[1]) - (r_a + a_a @ p.local[0])
                coords[k, 1] = float(d @ (a_a @ p.axis_local))
        return coords

    def _speeds(self, coords: np.ndarray, t: float) -> np.ndarray:
        """Relative angular and sliding speeds: BDF2 of the pair coordinates (BDF1 at the start)."""
        hist = self._history
        c1 = hist[-1][1]
        delta = coords - c1
        delta[:, 0] = (delta[:, 0] + math.pi) % (2.0 * math.pi) - math.pi  # unwrap the angle
        h1 = t - hist[-1][0]
        if len(hist) < 2:
            return delta / h1
        c2 = hist[-2][1]
        delta2 = c1 - c2
        delta2[:, 0] = (delta2[:, 0] + math.pi) % (2.0 * math.pi) - math.pi
        w1, w2 = bdf2_weights(h1, hist[-1][0] - hist[-2][0])
        return (w1 * delta - w2 * delta2) / h1

    def _velocity_level_speeds(self, states: dict[str, tuple]) -> np.ndarray:
        """Relative speeds from the body velocities (used at the initial, consistent state)."""
        speeds = np.zeros((self.n, 2))
        for k, p in enumerate(self.pairs):
            a_a, w_a, v_a, _ = states.get(p.bodies[0], _GROUND)
            a_b, w_b, v_b, _ = states.get(p.bodies[1], _GROUND)
            axis = a_a @ p.axis_local
            speeds[k, 0] = float((w_b - w_a) @ axis)
            if p.kind == "cylindrical":
                r_a, r_b = a_a @ p.local[0], a_b @ p.local[1]
                speeds[k, 1] = float((v_b + np.cross(w_b, r_b) - v_a - np.cross(w_a, r_a)) @ axis)
        return speeds

    def initialise(self, solver: Any, settings: Any, max_iterations: int = 60) -> None:
        """Friction consistent with the initial reactions, before the first step.

        Exudyn computes the initial accelerations and reactions from the initial state and the
        loads in place; the friction loads are iterated with them (Broyden) until consistent,
        so that the first recorded row, the first step and, in the lagged scheme, the friction
        of the first step all include friction. Call after ``solver.InitializeSolver``.
        """
        b = None
        x_prev = r_prev = None
        x = np.zeros(int(self._mask.sum()))
        for _ in range(max_iterations):
            friction, _ = self.evaluate(None)
            g = friction.ravel()[self._mask]
            r = g - x
            scale = max(float((np.abs(friction) * self._weight).max()), self.scale_floor)
            weighted = np.abs(r) * self._weight.ravel()[self._mask]
            if scale == 0.0 or weighted.max() <= self.settings.tolerance * scale:
                self.apply(friction)
                solver.InitializeSolverInitialConditions(self.mbs, settings)
                self._accepted = [friction.copy()]
                self.initial = friction.copy()
                return
            if b is None:
                b = -np.eye(x.size)
            elif x_prev is not None:
                dx, dr = x - x_prev, r - r_prev
                if dx @ dx > 0.0:
                    b += np.outer(dr - b @ dx, dx) / (dx @ dx)
            x_prev, r_prev = x, r
            x = x + np.linalg.solve(b, -r)
            full = np.zeros(self._mask.size)
            full[self._mask] = x
            self.apply(full.reshape(self.n, 2))
            solver.InitializeSolverInitialConditions(self.mbs, settings)
        self.status = Status.SELF_LOCKING
        self.reason = (f"no consistent friction state at the start: the fixed-point iteration "
                       f"did not converge in {max_iterations} iterations (loop gain >= 1)")

    def evaluate(self, t: float | None) -> tuple[np.ndarray, np.ndarray]:
        """Friction (M_z, F_z on body b) of each pair, and the pair coordinates, at the current
        state (``t`` None: the initial state, with velocity-level speeds)."""
        get = self.mbs.GetObjectOutput
        force_local, torque_local = exu.OutputVariableType.ForceLocal, exu.OutputVariableType.TorqueLocal
        states = self._body_states()
        coords = self._pair_coordinates(states)
        speeds = self._velocity_level_speeds(states) if t is None else self._speeds(coords, t)
        friction = np.zeros((self.n, 2))
        sliding = 0.0  # largest load a pair would carry sliding (forces weighted by d / 2)
        for k, p in enumerate(self.pairs):
            lx, ly, _ = get(p.joint, force_local)
            tx, ty, _ = get(p.joint, torque_local)
            omega_rel, slide = speeds[k]
            # a pair that cannot slide (no axial load: the ideal joint) has solver noise as its
            # slide; under the resultant law it would enter the slip direction
            slide = float(slide) if p.force_loads else 0.0
            band = self.bands[p.name]
            # TorqueLocal's in-plane components are rotated by 90 deg; only the magnitude enters
            loads = pair_loads(p.law, lx, ly, tx, ty, float(omega_rel), slide, band.rotation,
                               band.sliding, band.resultant)
            friction[k] = loads.torque, (loads.force if p.force_loads else 0.0)
            sliding = max(sliding, loads.sliding_scale)
        self.scale_floor = REST_FLOOR * sliding
        return friction, coords

    def apply(self, friction: np.ndarray) -> None:
        """Set every friction load (called once or more per step: plain floats, no arrays)."""
        if self._load_axes is None:  # (load, column of friction, role times the axis in node axes)
            self._load_axes = [(load, k, j, tuple(float(role * c) for c in p.axis_local))
                               for k, p in enumerate(self.pairs)
                               for j, loads in ((0, p.torque_loads), (1, p.force_loads))
                               for load, role in loads]
        set_load = self.mbs.SetLoadParameter
        values = friction.tolist()
        for load, k, j, (x, y, z) in self._load_axes:
            value = values[k][j]
            set_load(load, "loadVector", [value * x, value * y, value * z])
        self.applied = friction.copy()

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function: update the friction, return the change as the
        discontinuous iteration's error (see the module doc).

        Exudyn reports any Python exception raised here as a solver failure; the exception is
        kept in :attr:`error` instead (the pre-step function then stops the run) so that
        :func:`cardan_exudyn.model.solve.solve` re-raises it: a bug is not a physical outcome.
        """
        try:
            return self._update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            self.error = exc
            self.status, self.reason = Status.INTEGRATION_FAILURE, f"friction update raised {exc!r}"
            return [0.0, -1.0]

    def _update(self, t: float) -> list[float]:
        if t != self._step_t and self._step_t is not None:  # the previous step was accepted
            self._history = [self._history[-1], (self._step_t, self._coords)]
        friction, self._coords = self.evaluate(t)
        # forces enter as the torque they make at the journal radius, so one relative measure
        # covers both kinds of load
        weighted = np.abs(friction) * self._weight
        scale = max(float(weighted.max()), self.scale_floor)
        change = float((np.abs(friction - self.applied) * self._weight).max())
        error = change / scale if scale > 0.0 else 0.0
        if t != self._step_t:  # first evaluation of a new step
            self._step_t, self._step_iter = t, 0
            self.log.t.append(t)
            self.log.applied.append(self.applied.copy())
            self.log.iterations.append(1)
        else:
            self._step_iter += 1
            self.log.applied[-1] = self.applied.copy()
            self.log.iterations[-1] = self._step_iter + 1
        if not self.converged:
            self._watch_growth(friction)
            self.apply(friction)
            return [0.0, -1.0]
        if self._step_iter == 0:
            self._xs, self._gs = [], []
        self._xs.append(self.applied.ravel().copy())
        self._gs.append(friction.ravel().copy())
        residuals = [g - x for x, g in zip(self._xs, self._gs, strict=True)]
        if len(residuals) == 2:  # after one plain update: the contraction of the map
            r0, r1 = np.linalg.norm(residuals[0]), np.linalg.norm(residuals[1])
            if r0 > 1e-7 * max(float(np.abs(friction).max()), 1e-300):
                self._step_gain = r1 / r0
        if error <= self.settings.tolerance:
            self._accept(friction)
            return [0.0, -1.0]
        if len(residuals) >= self.settings.max_iterations:
            self.unconverged_steps += 1
            shrink = np.linalg.norm(residuals[-1]) / max(np.linalg.norm(residuals[0]), 1e-300)
            if shrink >= STALL_RATIO:
                self.status = Status.SELF_LOCKING
                self.reason = (f"no consistent friction state at t = {t:.6g} s: the fixed-point "
                               f"iteration stalled (residual ratio {shrink:.3g} after "
                               f"{len(residuals)} iterations, contraction of the plain map "
                               f"{self._step_gain:.3g}); the loop gain of the friction feedback "
                               "is >= 1" + self._band_hint())
            self._accept(friction)
            return [0.0, -1.0]
        self.apply(self._broyden(residuals).reshape(friction.shape))
        return [error, -1.0]

    def _broyden(self, residuals: list[np.ndarray]) -> np.ndarray:
        """Next friction guess: Broyden's quasi-Newton method on ``r(x) = Phi(x) - x``.

        The map friction -> reactions -> friction is nearly linear within a step (signs fixed)
        and changes slowly from step to step, so the secant approximation ``B`` of ``dr/dx`` is
        kept across steps (it starts as ``-I``, i.e. a plain fixed-point update, and is updated
        with every pair of iterates of the same step). After the first steps an accepted step
        typically needs two or three evaluations where the plain iteration contracts only with
        the loop gain (0.6-0.9 at 10-35 deg).
        """
        mask = self._mask
        x = self._xs[-1][mask]
        r = residuals[-1][mask]
        if self._broyden_b is None:
            self._broyden_b = -np.eye(mask.sum())
        if len(residuals) >= 2:
            dx = x - self._xs[-2][mask]
            dr = r - residuals[-2][mask]
            norm = float(dx @ dx)
            if norm > 0.0:
                self._broyden_b += np.outer(dr - self._broyden_b @ dx, dx) / norm
        try:
            step = np.linalg.solve(self._broyden_b, -r)
        except np.linalg.LinAlgError:
            self._broyden_b = -np.eye(mask.sum())
            step = r
        out = self._gs[-1].copy()
        out[mask] = x + step
        return out

    def _accept(self, friction: np.ndarray) -> None:
        """Step accepted: record the loop gain; predict the next step's friction by extrapolating
        the last three steps.

        Loop gain: the spectral radius of the Broyden approximation of d(friction out)/d(friction
        in), ``B + I``, i.e. the contraction of the plain fixed-point map friction -> reactions ->
        friction at this step (exact for the directions the iterations have explored).

        Quadratic extrapolation on the step grid (error O(h^3)) puts the first evaluation of the
        next step within
        about 1e-4 of its fixed point at the default step sizes, so one Broyden correction
        usually meets the tolerance. It only sets the starting guess.
        """
        self._accepted_steps += 1
        # the eigenvalues cost as much as a friction evaluation: every GAIN_EVERY-th step
        if self._broyden_b is not None and self._accepted_steps % GAIN_EVERY == 1:
            g = self._broyden_b + np.eye(self._broyden_b.shape[0])
            self._gains.append(float(np.max(np.abs(np.linalg.eigvals(g)))))
        hist = self._accepted
        hist.append(friction.copy())
        if len(hist) > 3:
            hist.pop(0)
        if len(hist) == 3:
            prediction = 3.0 * hist[2] - 3.0 * hist[1] + hist[0]
        elif len(hist) == 2:
            prediction = 2.0 * hist[1] - hist[0]
        else:
            prediction = friction
        self.apply(prediction)

    def _band_hint(self) -> str:
        if all(min(self.bands[p.name]) > 0.0 for p in self.pairs):
            return ""
        return (" (with a sign band of 0 the exact sign of rounding-level relative speeds decides "
                "the direction of friction in pairs that do not move; use a positive band)")

    def _watch_growth(self, friction: np.ndarray) -> None:
        size = float(np.max(np.abs(friction)))
        before = float(np.max(np.abs(self.applied)))
        if before > 0.0 and size > before:
            if self._growth_steps == 0:  # growth out of rounding noise (pairs at rest) is no locking
                self._growth_start = max(before, self.scale_floor)
            self._growth_steps += 1
            if size > LAGGED_GROWTH_LIMIT * self._growth_start:
                self.status = Status.SELF_LOCKING
                self.reason = (f"lagged friction grew geometrically by more than "
                               f"{LAGGED_GROWTH_LIMIT:g}x over {self._growth_steps} steps up to "
                               f"t = {self._step_t:.6g} s: the friction feedback loop gain is >= 1"
                               + self._band_hint())
        else:
            self._growth_steps = 0

    def summary(self) -> dict[str, Any]:
        iterations = np.asarray(self.log.iterations, dtype=float)
        return {
            "coupling": self.settings.coupling,
            "sign_bands_m_s": {p.name: list(self.bands[p.name]) for p in self.pairs},
            "pairs_with_friction": [p.name for p in self.pairs],
            "tolerance": self.settings.tolerance if self.converged else None,
            "mean_iterations_per_step": float(iterations.mean()) if iterations.size else 0.0,
            "max_iterations_in_a_step": int(iterations.max()) if iterations.size else 0,
            "unconverged_steps": self.unconverged_steps,
            # spectral radius of the secant estimate of the friction feedback map, every
            # GAIN_EVERY-th accepted
            # step (see _accept); the median is robust to the start-up steps
            "loop_gain_estimate": float(np.median(self._gains)) if self._gains else None,
            "loop_gain_estimate_max": float(np.max(self._gains)) if self._gains else None,
        }

    def columns(self, times: np.ndarray) -> dict[str, np.ndarray]:
        """Friction applied in the step ending at each recorded time, per pair (zeros elsewhere)."""
        n = len(times)
        out = {f"{name}_{kind}": np.zeros(n) for name in PAIR_NAMES
               for kind in ("friction_torque", "friction_force")}
        if not self.log.t:
            return out
        # the initial row (no step yet): the initial friction, else that of the first step
        t_log = np.asarray(self.log.t)
        applied = np.asarray(self.log.applied)
        index = np.searchsorted(t_log, times - 1e-12 * max(1.0, abs(times[-1])))
        index[0] = 0 if times[0] < t_log[0] else index[0]
        valid = (index < len(t_log))
        valid[valid] &= np.isclose(t_log[index[valid]], times[valid], rtol=0, atol=1e-9)
        valid[0] = True
        for k, p in enumerate(self.pairs):
            for j, kind in enumerate(("friction_torque", "friction_force")):
                col = np.zeros(n)
                col[valid] = applied[index[valid], k, j]
                if self.initial is not None and times[0] < t_log[0]:
                    col[0] = self.initial[k, j]
                out[f"{p.name}_{kind}"] = col
        return out
