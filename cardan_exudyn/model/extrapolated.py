"""The ``extrapolated`` friction coupling (the default): one Newton solve per step, the law evaluated
on the inputs extrapolated to the end of the next step, ``x_{n+1} ~ 1.5 x_n - 0.5 x_{n-2}``.

Second order where friction is smooth; the feedback map ``z^3 = g (1.5 z^2 - 0.5)`` is stable for
loop gains ``g`` in (-1, 1). Reversal steps are iterated to their fixed point; a probed gain above
:data:`ESCALATE_GAIN` or runaway growth switches the run to the converged scheme (near locking the
extrapolation's error grows as ``1 / (1 - g)``).
"""

from __future__ import annotations

import math
from typing import Any

from cardan_exudyn.model.converged import ConvergedCoupling
from cardan_exudyn.model.coupling import REST_FLOOR

__all__ = ["PROBE_EVERY", "PROBES_PER_REVOLUTION", "ESCALATE_GAIN", "RAMP_STEPS", "PROBE_NOISE",
           "ExtrapolatedCoupling"]

PROBE_EVERY = 25
"""Every this many steps one step is solved twice to estimate the loop gain. Measured:
docs/engines.md#friction-coupling-measurements."""
PROBES_PER_REVOLUTION = 8
"""Probes per input revolution at least: the gain varies over a revolution. Measured:
docs/engines.md#friction-coupling-measurements."""
ESCALATE_GAIN = 0.95
"""A probed loop gain above this switches the run to the converged scheme."""
RAMP_STEPS = 4
"""A sign ramp crossed in fewer steps than this counts as a jump (a reversal step)."""
PROBE_NOISE = 1e-9
"""A probe whose first friction change is below this share of the largest load estimates nothing."""


class ExtrapolatedCoupling(ConvergedCoupling):
    """One solve per step on extrapolated inputs; reversal steps, and every step after an
    escalation, iterated as :class:`~cardan_exudyn.model.converged.ConvergedCoupling` does."""

    def __init__(self, model: Any) -> None:
        super().__init__(model)
        self._probe_every = PROBE_EVERY     # steps between probes (initialise sets it for the step)
        self._probe: tuple | None = None    # (friction of the first solve, its change) in a probe
        self._iterating = False             # this step is iterated (a reversal)
        self._inputs: list[list] = []       # the law's inputs of the last 3 steps
        self._regimes: list = []            # their regimes (PairReader.regime)
        self._predicted_regime: tuple = ()  # the regime the step was solved with

    def initialise(self, solver: Any, settings: Any) -> tuple[Any, list] | None:
        """The probe interval (at least :data:`PROBES_PER_REVOLUTION` per revolution, at most every
        :data:`PROBE_EVERY`-th step), then the consistent initial friction that starts the extrapolation."""
        ti = settings.timeIntegration
        speed = self.model.scene.drive.max_speed()
        duration = ti.endTime - ti.startTime
        if speed > 0.0 and duration > 0.0:
            steps = 2.0 * math.pi / speed * ti.numberOfSteps / duration
            self._probe_every = int(min(PROBE_EVERY, max(2, steps // PROBES_PER_REVOLUTION)))
        start = ConvergedCoupling.initialise(self, solver, settings)
        if start is not None:
            self._inputs = [start[1]]
            self._predicted_regime = self.reader.regime
            self._regimes = [self._predicted_regime]
        return start

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function at ``t`` [s]: :meth:`update`'s ``[error, -1]``, an
        exception kept."""
        try:
            return self.update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            return self.failed(exc)

    def update(self, t: float) -> list[float]:
        """One evaluation at ``t`` [s]: the extrapolated scheme's until it escalates, the
        converged scheme's after."""
        if self.escalated_at is not None:
            return self._iterated(t, counted=False)
        return self._one_solve(t)

    def _iterated(self, t: float, counted: bool) -> list[float]:
        """One evaluation of a step solved to its fixed point; when done, a reversal step returns to one
        solve per step and an escalated run accepts it."""
        error, done = self.iterate(t, counted)
        if done is None:
            return error
        if self.escalated_at is not None:
            self.accept(done)
        else:
            self._iterating = False
            self._predict(self._last_inputs, self.reader.regime)
        return error

    def _one_solve(self, t: float) -> list[float]:
        """After a step's solve: the next step's friction from the extrapolated inputs; a probe step is
        solved twice, a reversal step to its fixed point."""
        first = self.new_step(t)
        if self._iterating:
            return self._iterated(t, counted=True)
        inputs = self._read_inputs(t)
        regime = self.reader.regime
        if first:
            self._accepted_steps += 1
            if self._reversed(inputs, regime):
                self._iterating = True
                self.iterated_steps += 1
                return self._iterated(t, counted=True)
            if self._accepted_steps % self._probe_every == 0:
                friction = self._law(inputs)
                self._probe = (friction, self.change(friction, self.applied))
                self.apply(friction)
                return [1.0, -1.0]  # above any tolerance: Exudyn solves the step again
        elif self._probe is not None:
            self._finish_probe(t, self._law(inputs))
            if self.escalated_at is not None:
                return self._iterated(t, counted=True)
        self._predict(inputs, regime)
        return [0.0, -1.0]

    def _reversed(self, inputs: list, regime: tuple) -> bool:
        """Whether a pair's motion crossed its sign ramp in fewer than :data:`RAMP_STEPS` steps between
        ``inputs`` (of ``regime``) and the extrapolation's steps or prediction: friction and reactions
        jump, and a line through the jump would carry an O(1) error."""
        others = (self._predicted_regime, *self._regimes)
        if all(other == regime for other in others):
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
        """Accept the step's ``inputs`` (of ``regime``) and apply the law on the inputs extrapolated to the
        next step's end."""
        hist = self._inputs
        regimes = self._regimes
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
        if self.grown(size):  # a gain >= 1 or an unstable step: only the fixed point can tell
            self.escalated_at = self._step_t
            self._growth_steps = 0
        self.apply(friction, size)

    def _finish_probe(self, t: float, friction: tuple) -> None:
        """Second solve of a probe step at ``t`` [s]: the loop gain from the two friction changes;
        escalation above :data:`ESCALATE_GAIN`."""
        first, change0 = self._probe
        self._probe = None
        self.probes += 1
        size = self.change(friction, (0.0,) * (2 * self.n))
        if change0 <= PROBE_NOISE * max(size, self.scale_floor):
            return
        gain = self.change(friction, first) / change0
        self._gains.append(gain)
        if gain > ESCALATE_GAIN:
            self.escalated_at = t
            self._xs = []  # the converged iteration takes over
            self._gs = []
            self._rs = []
