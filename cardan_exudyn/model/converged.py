"""The ``converged`` friction coupling: every step iterated to its fixed point.

The post-Newton function returns the friction's relative change as the error of Exudyn's
discontinuous iteration, which repeats the step until it is below ``friction.tolerance``. The
iteration is Broyden's on ``r(x) = Phi(x) - x`` (``Phi``: friction -> reactions -> friction), its
secant matrix kept across steps. A step stalled after ``friction.max_iterations`` (residual shrunk
less than :data:`STALL_RATIO`) is ``self_locking``. Cost: docs/engines.md#friction-coupling-measurements.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cardan_exudyn.model.coupling import FrictionCoupling
from reference.results.summary import Status

__all__ = ["STALL_RATIO", "GAIN_EVERY", "ConvergedCoupling"]

STALL_RATIO = 0.1
"""A step whose fixed-point residual shrank less than this after ``friction.max_iterations`` is
taken as self-locking (no consistent friction state)."""
GAIN_EVERY = 4
"""The loop-gain estimate (eigenvalues, costly as a friction evaluation) every this many accepted steps."""


class ConvergedCoupling(FrictionCoupling):
    """Friction iterated to the fixed point of each step (module doc)."""

    def __init__(self, model: Any) -> None:
        super().__init__(model)
        self._xs: list[np.ndarray] = []  # the step's iterates: friction in (masked)
        self._gs: list[tuple] = []       # friction out (flat)
        self._rs: list[np.ndarray] = []  # residual out - in (masked)
        self._step_gain = 0.0            # contraction of the plain map in this step
        self._broyden_b: np.ndarray | None = None
        self._accepted: list[tuple] = []  # the last accepted steps' friction (flat)

    def initialise(self, solver: Any, settings: Any) -> tuple[np.ndarray, list] | None:
        """Friction consistent with the initial state, the first accepted state."""
        start = self.consistent_start(solver, settings)
        if start is not None:
            self._accepted = [tuple(start[0].ravel().tolist())]
        return start

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function at ``t`` [s]: :meth:`update`'s ``[error, -1]``, an
        exception kept."""
        try:
            return self.update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            return self.failed(exc)

    def update(self, t: float) -> list[float]:
        """One evaluation of the step at ``t`` [s], the step accepted when done."""
        error, done = self.iterate(t)
        if done is not None:
            self.accept(done)
        return error

    def iterate(self, t: float, counted: bool = False) -> tuple[list[float], tuple | None]:
        """One evaluation of a step's fixed point at ``t`` [s] (``counted``: :meth:`new_step` already called):
        ``(error, done)``, Exudyn's ``[relative change, -1]`` (next Broyden iterate applied while above
        the tolerance, 0 when done) and the step's flat friction when done (else None)."""
        if not counted:
            self.new_step(t)
        friction = self.evaluate(t)
        applied = self.applied
        error = self._relative_change(friction, applied)
        self._iterate(friction, applied)
        if error <= self.settings.tolerance:
            return [0.0, -1.0], friction
        if len(self._rs) >= self.settings.max_iterations:
            self._give_up(t)
            return [0.0, -1.0], friction
        self.apply(self._broyden())
        return [error, -1.0], None

    def _relative_change(self, friction: tuple, applied: tuple) -> float:
        """Change from ``applied`` to ``friction`` relative to the larger of the friction and
        :attr:`scale_floor`; forces count as their torque at the journal radius."""
        weights = self._flat_weight
        scale = max(max([w * abs(f) for w, f in zip(weights, friction, strict=True)]), self.scale_floor)
        change = max([w * abs(f - a) for w, f, a in zip(weights, friction, applied, strict=True)])
        return change / scale if scale > 0.0 else 0.0

    def _iterate(self, friction: tuple, applied: tuple) -> None:
        """Record the step's iterate (``applied`` in, ``friction`` out) and, after one plain
        update, the contraction of the map."""
        if self._step_iter == 0:
            self._xs = []
            self._gs = []
            self._rs = []
        index = self._mask_index
        x = np.array([applied[i] for i in index])
        self._xs.append(x)
        self._gs.append(friction)
        rs = self._rs
        rs.append(np.array([friction[i] for i in index]) - x)
        if len(rs) == 2:
            r0 = math.sqrt(rs[0] @ rs[0])
            r1 = math.sqrt(rs[1] @ rs[1])
            if r0 > 1e-7 * max(max(map(abs, friction)), 1e-300):
                self._step_gain = r1 / r0

    def _give_up(self, t: float) -> None:
        """At ``friction.max_iterations``: counted, and self-locking when the residual stalled."""
        rs = self._rs
        self.unconverged_steps += 1
        shrink = math.sqrt(rs[-1] @ rs[-1]) / max(math.sqrt(rs[0] @ rs[0]), 1e-300)
        if shrink >= STALL_RATIO:
            self.status = Status.SELF_LOCKING
            self.reason = (f"no consistent friction state at t = {t:.6g} s: the fixed-point "
                           f"iteration stalled (residual ratio {shrink:.3g} after "
                           f"{len(rs)} iterations, contraction of the plain map "
                           f"{self._step_gain:.3g}); the loop gain of the friction feedback "
                           "is >= 1" + self.band_hint())

    def _broyden(self) -> tuple[float, ...]:
        """Next flat friction guess by Broyden on ``r(x) = Phi(x) - x``; the secant ``B`` (from ``-I``) is
        kept across steps since the map changes slowly. Only loads that can be non-zero move."""
        xs = self._xs
        rs = self._rs
        x = xs[-1]
        r = rs[-1]
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

    def accept(self, friction: tuple) -> None:
        """Accept the step with flat ``friction``: record the loop gain (spectral radius of ``B + I``) and
        apply the quadratic extrapolation of the last three steps as the next first guess."""
        self._accepted_steps += 1
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
