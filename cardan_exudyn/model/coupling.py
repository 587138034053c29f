"""Friction of eqs. (1)-(5) in the Exudyn model, computed from the pairs' reaction outputs.

What is added to the model
--------------------------
For each pair with a non-zero friction coefficient (and only for those) a friction torque about
the pair axis, and for cylindrical pairs of a joint with mounting errors an axial force, on each
moving body of the pair: merged per body into one body-fixed torque vector, and a force vector
only where a pair slides (:class:`cardan_exudyn.model.friction_io.BodyLoads`). The ideal joint's
cylindrical pairs cannot slide (their axial friction is 0, as the reference engine computes it);
the solver leaves their slide with noise at the Newton tolerance (1e-11..1e-10 m/s with a
measured angle drive), which the sign ramp would turn into an axial force that changes with every
solve: at 0 deg, where the true friction is only the weights', the fixed point could not converge
below it and the run stopped as self-locking. Body ``b`` receives the friction (torque ``M_z``,
force ``F_z``), body ``a`` the opposite.

How the friction is updated (``scene.friction.coupling``)
---------------------------------------------------------
One Python post-Newton user function (``mbs.SetPostNewtonUserFunction``) reads, after each Newton
solve, the law's inputs -- per pair the magnitudes of the reaction force normal to the axis and of
the bending moment (from the Lagrange multipliers, read once), and the relative angular and
sliding speeds (BDF2 of the joint's own angle and slide outputs) -- computes the friction and sets
the loads (:mod:`cardan_exudyn.model.friction_io`: plain floats, no small arrays). On the one-solve
path each evaluation is one pass over the pairs to read (:class:`~cardan_exudyn.model.friction_io.PairReader`,
which also gives the sides of the sign ramps) and one to extrapolate and evaluate the law
(:class:`~cardan_exudyn.model.friction_law.LawTable`); the friction is carried as one flat tuple
``(M_z, F_z)`` per pair, which the log keeps without copying. Before the first
step the friction is iterated to consistency with the initial state (``FrictionCoupling.initialise``),
so no scheme starts frictionless.

- ``extrapolated`` (the default): one Newton solve per step. At the end of step ``n`` the law's
  inputs ``x`` are extrapolated to the end of step ``n + 1`` as ``1.5 x_n - 0.5 x_{n-2}`` (linear
  through steps ``n - 2`` and ``n``) and the law, sign ramps included, is evaluated on them: the
  friction acting in step ``n + 1`` is that of its own (predicted) state, so the mean efficiency
  converges at the integrator's order (second) where friction is smooth. The linear map of the
  friction feedback (loop gain ``g``: reactions -> friction -> reactions) then iterates as
  ``z^3 = g (1.5 z^2 - 0.5)``, whose roots lie inside the unit circle for every real ``g`` in
  (-1, 1) (``tests/test_coupling_lean.py`` checks the roots and runs at gains near -1 and +1).
  Extrapolating the friction itself instead of the inputs stays first order (a sign ramp crossed
  in a step is not predicted), and ``2 x_n - x_{n-1}`` is unstable for ``g < -1/3``. The first
  two steps extrapolate with what exists (constant, then linear through two steps). Every
  :data:`PROBE_EVERY`-th step (more often at coarse steps) that is not a reversal step is solved
  twice, the second time with the friction of the first solve's state: the ratio of the two
  friction changes estimates the loop gain
  (``loop_gain_estimate``). A probe above :data:`ESCALATE_GAIN` switches the run to the converged
  scheme (near self-locking the extrapolation amplifies its error by ``1 / (1 - g)``, and only the
  fixed-point iteration tells a joint that locks).
- ``converged``: the function returns the relative change of the friction as the error of
  Exudyn's *discontinuous iteration*; Exudyn repeats the Newton solve of the same step with the
  updated friction until the change is below ``tolerance``. The friction applied in a step is
  then the friction of that step's own reactions (a fixed point per step). Costs 5-8 Newton
  solves per step where the extrapolated scheme needs one.
- ``lagged`` (the paper's scheme): the function returns zero error, so the friction computed at
  the end of step n acts during step n+1. First order in the step size (the friction is one
  step late).

Self-locking
------------
The fixed-point iteration contracts with the loop gain of the friction feedback (friction ->
reactions -> friction). In the converged scheme the ratio of successive corrections estimates
it (``loop_gain_estimate`` in the summary); a step whose iteration stalls (residual reduced by
less than ``STALL_RATIO`` after ``max_iterations``) has no consistent friction state and stops
the run with status ``self_locking``; a step that still converges but slowly is counted in
``unconverged_steps`` and the run goes on. In the lagged and extrapolated schemes every step is
one iteration of the same map, so a gain >= 1 shows as growth of the friction from step to step:
growth by more than a factor 1e3 over consecutive growing steps stops the run with status
``self_locking`` (the extrapolated scheme escalates to the converged one before that, at its
first probe above :data:`ESCALATE_GAIN`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cardan_exudyn.model import friction_io as io
from cardan_exudyn.model.friction_law import LawTable, PairLaw
from reference.physics.bands import sign_bands
from reference.results.friction_diagnostics import FrictionDiagnostics
from reference.results.summary import Status
from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES

# geometric growth of the friction (lagged and extrapolated schemes) taken as self-locking
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
PROBE_EVERY = 25
"""Extrapolated scheme: every this many steps one step is solved twice to estimate the loop gain
(a reversal step is solved to its fixed point instead). At coarse steps more often, at least
:data:`PROBES_PER_REVOLUTION` times a revolution: a pilot at 50 steps per revolution and 10 deg
probing every 25th step fell on a spider pair's reversal every time and measured no gain at all.
Probes deferred past reversals instead landed just after them, read the transition rather than
the loop (1.2 with sliding pairs whose gain is below 0.6) and escalated those runs."""
PROBES_PER_REVOLUTION = 8
"""Extrapolated scheme: probes per input revolution at least (the gain varies over a revolution:
a pilot at 50 steps per revolution probing twice a revolution read 0.02 where the run reached
1.0; its planned step then read the mean efficiency 1.5e-4 off at accuracy 1e-4)."""
ESCALATE_GAIN = 0.95
"""Extrapolated scheme: a probed loop gain above this switches the run to the converged scheme."""
RAMP_STEPS = 4
"""Extrapolated scheme: a sign ramp crossed in fewer steps than this counts as a jump."""
PROBE_NOISE = 1e-9
"""A probe whose first friction change is below this share of the largest friction load is
rounding noise and estimates nothing."""


@dataclass
class _PairData:
    name: str
    law: PairLaw
    joint: int                          # the pair's ObjectJointGeneric
    bands: tuple[float, float, float]   # sign ramps: rotation, sliding, resultant [m/s]
    slides: bool                        # carries an axial force (cylindrical, mounting errors)
    weight: float                       # a force counts as the torque it makes: d / 2 [m]


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
        self.mode = scene.friction.coupling
        self.pairs: list[_PairData] = []
        contributions, axes = [], []
        for name, pair in scene.joint.friction_pairs():
            if pair.friction_coefficient <= 0.0:
                continue
            # the ideal joint's cylindrical pairs cannot slide: their axial friction is 0 (as
            # the reference's); the law would turn the solver's noise in the slide into force
            slides = PAIR_KIND[name] == "cylindrical" and scene.joint.errors.any
            law = PairLaw.of(PAIR_KIND[name], pair, scene.friction.law)
            self.pairs.append(_PairData(name, law, model.joints[name],
                                        tuple(self.bands[name]), slides, 0.5 * law.d))
            contributions.append([(model.bodies[body], local, role) for role, body, local in
                                  zip((-1, 1), PAIR_BODIES[name], model.marker_local[name], strict=True)
                                  if body != "ground"])
            axes.append(model.pair_frames[name][:, 2].copy())
        self.loads = io.BodyLoads(self.mbs, contributions, axes, [p.slides for p in self.pairs])
        self.n = len(self.pairs)
        self.table = LawTable([p.law for p in self.pairs], [p.bands for p in self.pairs],
                              [p.slides for p in self.pairs])
        self._flat_weight = tuple(w for p in self.pairs for w in (1.0, p.weight))
        self.channels: list[io.PairChannel] = []
        self.reader: io.PairReader | None = None
        self.applied: tuple = (0.0,) * (2 * self.n)  # flat (M_z, F_z) per pair, in effect
        self._applied_size = 0.0                     # the largest of its magnitudes
        self.log = FrictionLog()
        self.initial: np.ndarray | None = None  # friction consistent with the initial state
        self._accepted: list[np.ndarray] = []
        self._step_t = None
        self._step_iter = 0
        self._xs: list[np.ndarray] = []    # converged iteration of a step: friction in (masked)
        self._gs: list[tuple] = []         # friction out (flat)
        self._rs: list[np.ndarray] = []    # residual out - in (masked)
        self._step_gain = 0.0
        self._gains: list[float] = []
        self._broyden_b = None
        self._accepted_steps = 0
        # extrapolated scheme: probes done, steps between probes (initialise sets it for the step)
        self.probes, self._probe_every = 0, PROBE_EVERY
        self._inputs: list[list] = []      # extrapolated scheme: law inputs of the last 3 steps
        self._probe: tuple | None = None   # (friction of the first solve, its change) in a probe
        self.escalated_at: float | None = None
        self._iterating = False            # extrapolated scheme: this step is iterated (reversal)
        self.iterated_steps = 0
        self._regimes: list = []           # the regimes of self._inputs (PairReader.regime)
        self._predicted_regime: tuple = ()
        self._last_inputs: list = []
        self._weight = np.array(self._flat_weight).reshape(self.n, 2)
        self._mask = np.array([m for p in self.pairs for m in (True, p.slides)])  # loads that can act
        self._mask_index = tuple(int(i) for i in np.flatnonzero(self._mask))
        self.unconverged_steps = 0
        self.status, self.reason = Status.OK, ""
        self.error: Exception | None = None  # raised inside the user function (see post_newton)
        self.scale_floor = 0.0  # set by evaluate (REST_FLOOR)
        self._growth_steps, self._growth_start = 0, 0.0

    def prepare(self) -> None:
        """Look up the multipliers (after ``mbs.Assemble``) and register the user function."""
        self.channels = [io.pair_channel(self.mbs, p.joint, PAIR_BODIES[p.name][0] == "ground",
                                         self.model.pair_frames[p.name], p.slides) for p in self.pairs]
        self.reader = io.PairReader(self.mbs, self.channels, self.model.start_time,
                                    [(p.weight, *p.bands[:2]) for p in self.pairs])
        self.mbs.SetPostNewtonUserFunction(self.post_newton)
        self.model.user_functions.append(self.post_newton)

    def configure(self, settings: Any) -> None:
        """Discontinuous-iteration settings for the chosen coupling (the extrapolated scheme
        repeats a solve only to probe or after escalating to the converged scheme)."""
        d = settings.timeIntegration.discontinuous
        iterating = self.mode != "lagged"
        d.iterationTolerance = self.settings.tolerance if iterating else 1.0
        d.maxIterations = self.settings.max_iterations + 1 if iterating else 1
        d.ignoreMaxIterations = True
        d.useRecommendedStepSize = False

    def _read_inputs(self, t: float | None) -> list[tuple[float, float, float, float]]:
        """Per pair the law's inputs ``(|F|, |M|, omega_rel, slide_rel)`` at the current state
        (``t`` None: the initial state, with velocity-level speeds)."""
        self._last_inputs = self.reader.read(t)
        return self._last_inputs

    def _law(self, inputs: list) -> tuple[float, ...]:
        """Friction, flat ``(M_z, F_z)`` per pair, for the law's ``inputs``; sets :attr:`scale_floor`."""
        friction, _, sliding, _ = self.table.loads(inputs)
        self.scale_floor = REST_FLOOR * sliding
        return friction

    def evaluate(self, t: float | None) -> tuple[float, ...]:
        """Friction at the current state, flat ``(M_z, F_z)`` on body b of each pair [N m, N]
        (``t`` None: the initial state, with velocity-level speeds)."""
        return self._law(self._read_inputs(t))

    def initialise(self, solver: Any, settings: Any, max_iterations: int = 60) -> None:
        """Friction consistent with the initial reactions, before the first step.

        Exudyn computes the initial accelerations and reactions from the initial state and the
        loads in place; the friction loads are iterated with them (Broyden) until consistent,
        so that the first recorded row, the first step and, in the lagged scheme, the friction
        of the first step all include friction. Call after ``solver.InitializeSolver``.
        """
        ti = settings.timeIntegration
        speed, duration = self.model.scene.drive.max_speed(), ti.endTime - ti.startTime
        if speed > 0.0 and duration > 0.0:  # steps per input revolution at the drive's top speed
            steps = 2.0 * math.pi / speed * ti.numberOfSteps / duration
            self._probe_every = int(min(PROBE_EVERY, max(2, steps // PROBES_PER_REVOLUTION)))
        b = None
        x_prev = r_prev = None
        x = np.zeros(int(self._mask.sum()))
        for _ in range(max_iterations):
            inputs = self._read_inputs(None)
            friction = np.array(self._law(inputs)).reshape(self.n, 2)
            g = friction.ravel()[self._mask]
            r = g - x
            scale = max(float((np.abs(friction) * self._weight).max()), self.scale_floor)
            weighted = np.abs(r) * self._weight.ravel()[self._mask]
            if scale == 0.0 or weighted.max() <= self.settings.tolerance * scale:
                self.apply(friction)
                solver.InitializeSolverInitialConditions(self.mbs, settings)
                self._accepted = [tuple(friction.ravel().tolist())]
                self._inputs = [inputs]
                self._predicted_regime = self.reader.regime
                self._regimes = [self._predicted_regime]
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

    def apply(self, friction: Any, size: float | None = None) -> None:
        """Set every friction load from ``friction``: flat ``(M_z, F_z)`` per pair, or an array
        of shape (n, 2); ``size``: its largest magnitude, when known."""
        values = tuple(friction.ravel().tolist()) if isinstance(friction, np.ndarray) else friction
        self.loads.apply(values)
        self.applied = values
        self._applied_size = max(map(abs, values)) if size is None else size

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function: update the friction, return the change as the
        discontinuous iteration's error (see the module doc).

        Exudyn reports any Python exception raised here as a solver failure; the exception is
        kept in :attr:`error` instead (the pre-step function then stops the run) so that
        :func:`cardan_exudyn.model.solve.solve` re-raises it: a bug is not a physical outcome.
        """
        try:
            if self.mode == "extrapolated" and self.escalated_at is None:
                return self._extrapolated(t)
            return self._update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            self.error = exc
            self.status, self.reason = Status.INTEGRATION_FAILURE, f"friction update raised {exc!r}"
            return [0.0, -1.0]

    def _new_step(self, t: float) -> bool:
        """Bookkeeping at each evaluation; True at the first evaluation of a step (the one before
        was then accepted: its coordinates join the BDF2 history)."""
        log = self.log
        if t == self._step_t:
            self._step_iter += 1
            log.applied[-1] = self.applied
            log.iterations[-1] = self._step_iter + 1
            return False
        if self._step_t is not None:
            self.reader.accept(self._step_t)
        self._step_t, self._step_iter = t, 0
        log.t.append(t)
        log.applied.append(self.applied)
        log.iterations.append(1)
        return True

    def _extrapolated(self, t: float) -> list[float]:
        """One step of the extrapolated scheme (module doc): the friction for the next step from
        the law on extrapolated inputs; a probe step is solved twice, a step next to a reversal
        is solved to its fixed point."""
        first = self._new_step(t)
        if self._iterating:
            return self._update(t, counted=True)
        inputs = self._last_inputs = self.reader.read(t)
        regime = self.reader.regime
        if first:
            self._accepted_steps += 1
            if self._reversed(inputs, regime):
                self._iterating = True
                self.iterated_steps += 1
                return self._update(t, counted=True)
            if self._accepted_steps % self._probe_every == 0:
                friction = self._law(inputs)
                self._probe = (friction, self._change(friction, self.applied))
                self.apply(friction)
                return [1.0, -1.0]  # above any tolerance: Exudyn solves the step again
        elif self._probe is not None:
            self._finish_probe(t, self._law(inputs))
            if self.escalated_at is not None:
                return self._update(t, counted=True)
        self._predict(inputs, regime)
        return [0.0, -1.0]

    def _reversed(self, inputs: list, regime: tuple) -> bool:
        """Whether a pair's motion crossed its sign ramp in fewer than :data:`RAMP_STEPS` steps
        (from one side to the other or into it) between ``inputs`` (of ``regime``) and the steps
        the extrapolation through them would use, or against the prediction this step was solved
        with: its friction then jumps, and so do the reactions (the friction feeds back), which a
        line through the jump would carry into the next steps as an error of order one. The step
        is then solved to its fixed point (about three steps per reversal). A ramp resolved by the
        step is crossed smoothly and needs nothing (iterating there mixes fixed-point and
        extrapolated states in the stencil, which measured worse)."""
        others = (self._predicted_regime, *self._regimes)
        for other in others:
            if other != regime:
                break
        else:
            return False
        last = self._inputs[-1] if self._inputs else inputs
        for k, p in enumerate(self.pairs):
            for j, scale in ((0, p.weight), (1, 1.0)):
                if all(other[2 * k + j] == regime[2 * k + j] for other in others):
                    continue
                if abs(inputs[k][2 + j] - last[k][2 + j]) * scale * RAMP_STEPS > p.bands[j]:
                    return True
        return False

    def _predict(self, inputs: list, regime: tuple) -> None:
        """Accept the step's ``inputs`` (of ``regime``) and apply the friction of the law on the
        inputs extrapolated to the end of the next step (``1.5 x_n - 0.5 x_{n-2}``, module doc)."""
        hist, regimes = self._inputs, self._regimes
        hist.append(inputs)
        regimes.append(regime)
        if len(hist) > 3:
            del hist[0], regimes[0]
        if len(hist) == 3:
            friction, self._predicted_regime, sliding, size = self.table.loads(inputs, hist[0], 1.5, 0.5)
        elif len(hist) == 2:
            friction, self._predicted_regime, sliding, size = self.table.loads(inputs, hist[0], 2.0, 1.0)
        else:
            friction, self._predicted_regime, sliding, size = self.table.loads(inputs)
        self.scale_floor = REST_FLOOR * sliding
        self._watch_growth(size)
        self.apply(friction, size)

    def _change(self, friction: tuple, before: tuple) -> float:
        """Largest change between two flat friction states, forces weighted by ``d / 2`` [N m]."""
        return max((w * abs(a - b) for w, a, b in zip(self._flat_weight, friction, before, strict=True)),
                   default=0.0)

    def _finish_probe(self, t: float, friction: list) -> None:
        """Second solve of a probe step: the loop gain from the two changes; escalation."""
        first, change0 = self._probe
        self._probe = None
        self.probes += 1
        size = self._change(friction, (0.0,) * (2 * self.n))
        if change0 <= PROBE_NOISE * max(size, self.scale_floor):
            return
        gain = self._change(friction, first) / change0
        self._gains.append(gain)
        if gain > ESCALATE_GAIN:
            self.escalated_at = t
            self._xs, self._gs, self._rs = [], [], []  # the converged iteration takes over

    def _update(self, t: float, counted: bool = False) -> list[float]:
        """One evaluation of the converged or lagged scheme (``counted``: :meth:`_new_step` was
        already called for it)."""
        if not counted:
            self._new_step(t)
        friction, applied = self.evaluate(t), self.applied
        # forces enter as the torque they make at the journal radius, so one relative measure
        # covers both kinds of load
        weights = self._flat_weight
        scale = max(max([w * abs(f) for w, f in zip(weights, friction, strict=True)]), self.scale_floor)
        change = max([w * abs(f - a) for w, f, a in zip(weights, friction, applied, strict=True)])
        error = change / scale if scale > 0.0 else 0.0
        if self.mode == "lagged":
            size = max(map(abs, friction))
            self._watch_growth(size)
            self.apply(friction, size)
            return [0.0, -1.0]
        if self._step_iter == 0:
            self._xs, self._gs, self._rs = [], [], []
        xs, rs = self._xs, self._rs
        index = self._mask_index
        x = np.array([applied[i] for i in index])
        xs.append(x)
        self._gs.append(friction)
        rs.append(np.array([friction[i] for i in index]) - x)
        if len(rs) == 2:  # after one plain update: the contraction of the map
            r0, r1 = math.sqrt(rs[0] @ rs[0]), math.sqrt(rs[1] @ rs[1])
            if r0 > 1e-7 * max(max(map(abs, friction)), 1e-300):
                self._step_gain = r1 / r0
        if error <= self.settings.tolerance:
            self._accept(friction)
            return [0.0, -1.0]
        if len(rs) >= self.settings.max_iterations:
            self.unconverged_steps += 1
            shrink = math.sqrt(rs[-1] @ rs[-1]) / max(math.sqrt(rs[0] @ rs[0]), 1e-300)
            if shrink >= STALL_RATIO:
                self.status = Status.SELF_LOCKING
                self.reason = (f"no consistent friction state at t = {t:.6g} s: the fixed-point "
                               f"iteration stalled (residual ratio {shrink:.3g} after "
                               f"{len(rs)} iterations, contraction of the plain map "
                               f"{self._step_gain:.3g}); the loop gain of the friction feedback "
                               "is >= 1" + self._band_hint())
            self._accept(friction)
            return [0.0, -1.0]
        self.apply(self._broyden())
        return [error, -1.0]

    def _broyden(self) -> tuple[float, ...]:
        """Next friction guess (flat): Broyden's quasi-Newton method on ``r(x) = Phi(x) - x``.

        The map friction -> reactions -> friction is nearly linear within a step (signs fixed)
        and changes slowly from step to step, so the secant approximation ``B`` of ``dr/dx`` is
        kept across steps (it starts as ``-I``, i.e. a plain fixed-point update, and is updated
        with every pair of iterates of the same step). After the first steps an accepted step
        typically needs two or three evaluations where the plain iteration contracts only with
        the loop gain (0.6-0.9 at 10-35 deg). Works on the loads that can be non-zero
        (:attr:`_mask_index`); the others stay 0.
        """
        xs, rs = self._xs, self._rs
        x, r = xs[-1], rs[-1]
        if self._broyden_b is None:
            self._broyden_b = -np.eye(x.size)
        if len(rs) >= 2:
            dx = x - xs[-2]
            dr = r - rs[-2]
            norm = float(dx @ dx)
            if norm > 0.0:
                self._broyden_b += (dr - self._broyden_b @ dx)[:, None] * dx / norm  # outer product
        try:
            step = np.linalg.solve(self._broyden_b, -r)
        except np.linalg.LinAlgError:
            self._broyden_b = -np.eye(x.size)
            step = r
        out = list(self._gs[-1])
        for i, value in zip(self._mask_index, (x + step).tolist(), strict=True):
            out[i] = value
        return tuple(out)

    def _accept(self, friction: tuple) -> None:
        """Step accepted (``friction``: flat): record the loop gain; predict the next step's
        friction by extrapolating the last three steps.

        Loop gain: the spectral radius of the Broyden approximation of d(friction out)/d(friction
        in), ``B + I``, i.e. the contraction of the plain fixed-point map friction -> reactions ->
        friction at this step (exact for the directions the iterations have explored).

        Quadratic extrapolation on the step grid (error O(h^3)) puts the first evaluation of the
        next step within about 1e-4 of its fixed point at the default step sizes, so one Broyden
        correction usually meets the tolerance. It only sets the starting guess.
        """
        if self.mode == "extrapolated" and self.escalated_at is None:  # back to one solve per step
            self._iterating = False
            self._predict(self._last_inputs, self.reader.regime)
            return
        self._accepted_steps += 1
        # the eigenvalues cost as much as a friction evaluation: every GAIN_EVERY-th step
        if self._broyden_b is not None and self._accepted_steps % GAIN_EVERY == 1:
            g = self._broyden_b + np.eye(self._broyden_b.shape[0])
            self._gains.append(float(np.max(np.abs(np.linalg.eigvals(g)))))
        hist = self._accepted
        hist.append(friction)
        if len(hist) > 3:
            del hist[0]
        if len(hist) == 3:
            prediction = tuple(3.0 * c - 3.0 * b + a for a, b, c in zip(*hist, strict=True))
        elif len(hist) == 2:
            prediction = tuple(2.0 * b - a for a, b in zip(*hist, strict=True))
        else:
            prediction = friction
        self.apply(prediction)

    def _band_hint(self) -> str:
        if all(min(self.bands[p.name]) > 0.0 for p in self.pairs):
            return ""
        return (" (with a sign band of 0 the exact sign of rounding-level relative speeds decides "
                "the direction of friction in pairs that do not move; use a positive band)")

    def _watch_growth(self, size: float) -> None:
        """Self-locking watch of the one-solve schemes; ``size``: the largest magnitude of the
        friction about to be applied."""
        before = self._applied_size
        if before > 0.0 and size > before:
            if self._growth_steps == 0:  # growth out of rounding noise (pairs at rest) is no locking
                self._growth_start = max(before, self.scale_floor)
            self._growth_steps += 1
            if size > LAGGED_GROWTH_LIMIT * self._growth_start and self.mode == "extrapolated":
                # growth of the extrapolated scheme is a gain >= 1 or an unstable step: only the
                # fixed-point iteration can tell, from the next step on
                self.escalated_at, self._growth_steps = self._step_t, 0
            elif size > LAGGED_GROWTH_LIMIT * self._growth_start:
                self.status = Status.SELF_LOCKING
                self.reason = (f"{self.mode} friction grew geometrically by more than "
                               f"{LAGGED_GROWTH_LIMIT:g}x over {self._growth_steps} steps up to "
                               f"t = {self._step_t:.6g} s: the friction feedback loop gain is >= 1"
                               + self._band_hint())
        else:
            self._growth_steps = 0

    def diagnostics(self) -> FrictionDiagnostics:
        """The run's counters and loop-gain estimates (the loop gain: the median and the largest
        of the estimates; the median is robust to the start-up steps)."""
        iterations = np.asarray(self.log.iterations, dtype=float)
        return FrictionDiagnostics(
            coupling=self.settings.coupling,
            sign_bands_m_s={p.name: tuple(self.bands[p.name]) for p in self.pairs},
            pairs_with_friction=tuple(p.name for p in self.pairs),
            tolerance=self.settings.tolerance if self.mode != "lagged" else None,
            mean_iterations_per_step=float(iterations.mean()) if iterations.size else 0.0,
            max_iterations_in_a_step=int(iterations.max()) if iterations.size else 0,
            unconverged_steps=self.unconverged_steps,
            escalated_to_converged_at=self.escalated_at,
            steps_iterated_at_reversals=self.iterated_steps,
            loop_gain_estimate=float(np.median(self._gains)) if self._gains else None,
            loop_gain_estimate_max=float(np.max(self._gains)) if self._gains else None,
            gain_probes=self.probes,
        )

    def columns(self, times: np.ndarray) -> dict[str, np.ndarray]:
        """Friction applied in the step ending at each recorded time, per pair (zeros elsewhere)."""
        n = len(times)
        out = {f"{name}_{kind}": np.zeros(n) for name in PAIR_NAMES
               for kind in ("friction_torque", "friction_force")}
        if not self.log.t:
            return out
        # the initial row (no step yet): the initial friction, else that of the first step
        t_log = np.asarray(self.log.t)
        applied = np.asarray(self.log.applied).reshape(len(self.log.applied), self.n, 2)
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
