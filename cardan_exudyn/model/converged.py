"""The ``converged`` friction coupling: every step iterated to its fixed point.

After each Newton solve the post-Newton function returns the relative change of the friction as
the error of Exudyn's *discontinuous iteration*; Exudyn repeats the solve of the same step with
the updated friction until the change is below ``friction.tolerance``. The friction applied in a
step is then that of the step's own reactions. The iteration is Broyden's quasi-Newton method on
``r(x) = Phi(x) - x`` (``Phi``: friction -> reactions -> friction), its secant matrix kept across
steps; an accepted step's friction is extrapolated quadratically over the last three steps as
the next step's first guess. Cost: measured in docs/engines.md#friction-coupling-measurements.

Self-locking: the plain map contracts with the loop gain of the friction feedback (the spectral
radius of the secant estimate of ``dPhi/dx``, ``loop_gain_estimate``). A step whose residual
shrank by less than :data:`STALL_RATIO` after ``friction.max_iterations`` has no consistent
friction state and stops the run (``self_locking``); one that still converges, slowly, is
counted in ``unconverged_steps`` and the run goes on.
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
"""The loop-gain estimate (the secant matrix's eigenvalues, as costly as a friction evaluation) is
taken every this many accepted steps."""


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
        """Friction consistent with the initial state, the first accepted state.

        Parameters
        ----------
        solver : exudyn.MainSolverImplicitSecondOrder
            Initialised (``solver.InitializeSolver`` called).
        settings : exudyn.SimulationSettings
            The run's settings.

        Returns
        -------
        (friction, inputs) or None
            :meth:`~cardan_exudyn.model.coupling.FrictionCoupling.consistent_start`'s.
        """
        start = self.consistent_start(solver, settings)
        if start is not None:
            self._accepted = [tuple(start[0].ravel().tolist())]
        return start

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function: :meth:`update`, an exception kept
        (:meth:`~cardan_exudyn.model.coupling.FrictionCoupling.failed`).

        Parameters
        ----------
        mbs : exudyn MainSystem
            The system just solved.
        t : float
            Time of the solve [s].

        Returns
        -------
        list of float
            Exudyn's ``[error, -1]``: a positive error repeats the step's solve.
        """
        try:
            return self.update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            return self.failed(exc)

    def update(self, t: float) -> list[float]:
        """One evaluation of the step at ``t`` [s] (:meth:`iterate`), the step :meth:`accept`-ed
        when it is done."""
        error, done = self.iterate(t)
        if done is not None:
            self.accept(done)
        return error

    def iterate(self, t: float, counted: bool = False) -> tuple[list[float], tuple | None]:
        """One evaluation of the fixed point of a step.

        Parameters
        ----------
        t : float
            Time of the step [s].
        counted : bool
            Whether :meth:`new_step` was already called for this evaluation.

        Returns
        -------
        error : list of float
            Exudyn's ``[error, -1]``: the relative change, above the tolerance while the step is
            solved again with the next Broyden iterate (applied here), 0 when it is done.
        done : tuple or None
            The step's friction (flat) when it is done: within the tolerance, or at
            ``friction.max_iterations`` (self-locking when stalled); None while it iterates.
        """
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
        """The change from ``applied`` to ``friction`` relative to the larger of the friction and
        :attr:`scale_floor`; forces enter as the torque they make at the journal radius, so one
        relative measure covers both kinds of load."""
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
        """The step reached ``friction.max_iterations``: counted, and self-locking when the
        residual stalled (:data:`STALL_RATIO`)."""
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
        """Next friction guess (flat): Broyden's quasi-Newton method on ``r(x) = Phi(x) - x``.

        The map is nearly linear within a step (signs fixed) and changes slowly from step to
        step, so the secant approximation ``B`` of ``dr/dx`` is kept across steps (it starts as
        ``-I``, a plain fixed-point update, and is updated with every pair of iterates of the same
        step). Works on the loads that can be non-zero; the others stay 0.
        """
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
        """The step is accepted with ``friction`` (flat): record the loop gain, and apply the
        quadratic extrapolation of the last three steps as the next step's first guess.

        Loop gain: the spectral radius of ``B + I``, the secant estimate of d(friction out) /
        d(friction in): the contraction of the plain map at this step (exact for the directions
        the iterations have explored). The extrapolation (error O(h^3)) only sets the starting
        guess.
        """
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
