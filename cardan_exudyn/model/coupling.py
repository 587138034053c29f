"""Friction of eqs. (1)-(5) in the Exudyn model from the pairs' reactions: what every coupling scheme
shares (:class:`FrictionCoupling`).

Per pair with friction, a torque ``M_z`` about the pair axis (and an axial force ``F_z`` where a
cylindrical pair slides, i.e. with mounting errors) on body b, the opposite on body a, set by a
post-Newton user function from the reactions and relative speeds (BDF2). Loop gain >= 1 (friction
-> reactions -> friction) ends the run ``self_locking``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cardan_exudyn.model import friction_io as io
from cardan_exudyn.model.friction_law import LawTable, PairLaw
from reference.physics.bands import sign_bands
from reference.results.friction_diagnostics import FrictionDiagnostics
from reference.results.summary import Status
from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES

__all__ = ["LAGGED_GROWTH_LIMIT", "REST_FLOOR", "PairData", "FrictionLog", "FrictionCoupling"]

LAGGED_GROWTH_LIMIT = 1e3
"""Geometric growth of the friction over consecutive growing steps (schemes with one solve per
step) taken as a loop gain of 1 or more."""
REST_FLOOR = 1e-6
"""Floor of the fixed-point tolerance, as a share of the largest sliding load: with every pair at
rest the loads are rounding noise, and a tolerance relative to the noise is never met."""


@dataclass
class PairData:
    """A pair with friction as the coupling sees it: ``name``, friction ``law``, Exudyn ``joint``, sign
    ramp half-widths ``bands`` (rotation, sliding, resultant) [m/s], whether it ``slides``, and the
    ``weight`` ``d / 2`` [m] that makes a force count as a torque."""

    name: str
    law: PairLaw
    joint: int
    bands: tuple[float, float, float]
    slides: bool
    weight: float


@dataclass
class FrictionLog:
    """Per accepted step: time [s], the friction in effect in its final solve (flat ``(M_z, F_z)`` per
    pair [N m, N]) and its evaluations."""

    t: list = field(default_factory=list)
    applied: list = field(default_factory=list)
    iterations: list = field(default_factory=list)


class FrictionCoupling:
    """Friction loads of ``model`` (being built, joints and markers added), their bookkeeping and the
    services every scheme uses. A scheme adds ``initialise(solver, settings)`` and
    ``post_newton(mbs, t)`` and calls down into these; nothing here calls a scheme."""

    iterates = True
    """Whether Exudyn's discontinuous iteration may repeat a step's solve (:meth:`configure`)."""

    def __init__(self, model: Any) -> None:
        scene = model.scene
        self.model = model
        self.mbs = model.mbs
        self.settings = scene.friction
        self.mode = scene.friction.coupling
        self.bands = sign_bands(scene)  # per pair (rotation, sliding, resultant) [m/s], as every engine
        self.pairs = friction_pairs(model, self.bands)
        self.n = len(self.pairs)
        self.loads = io.BodyLoads(self.mbs, [body_contributions(model, p.name) for p in self.pairs],
                                  [model.pair_frames[p.name][:, 2].copy() for p in self.pairs],
                                  [p.slides for p in self.pairs])
        self.table = LawTable([p.law for p in self.pairs], [p.bands for p in self.pairs],
                              [p.slides for p in self.pairs])
        self.channels: list[io.PairChannel] = []
        self.reader: io.PairReader | None = None
        self._flat_weight = tuple(w for p in self.pairs for w in (1.0, p.weight))
        self._weight = np.array(self._flat_weight).reshape(self.n, 2)
        self._mask = np.array([m for p in self.pairs for m in (True, p.slides)])  # loads that can act
        self._mask_index = tuple(int(i) for i in np.flatnonzero(self._mask))
        self._reset_state()

    def _reset_state(self) -> None:
        """The state of a run before its first step."""
        self.applied: tuple = (0.0,) * (2 * self.n)  # flat (M_z, F_z) per pair, in effect
        self._applied_size = 0.0                     # the largest of its magnitudes
        self.log = FrictionLog()
        self.initial: np.ndarray | None = None       # friction consistent with the initial state
        self._step_t: float | None = None
        self._step_iter = 0
        self._accepted_steps = 0
        self._gains: list[float] = []
        self._last_inputs: list = []
        self._growth_steps = 0
        self._growth_start = 0.0
        self.scale_floor = 0.0  # set by each evaluation of the law (REST_FLOOR)
        self.unconverged_steps = 0
        self.escalated_at: float | None = None
        self.iterated_steps = 0
        self.probes = 0
        self.status = Status.OK
        self.reason = ""
        self.error: Exception | None = None  # raised inside the user function (see post_newton)

    def prepare(self) -> None:
        """Look up the multipliers (after ``mbs.Assemble``) and register the user function."""
        self.channels = [io.pair_channel(self.mbs, p.joint, PAIR_BODIES[p.name][0] == "ground",
                                         self.model.pair_frames[p.name], p.slides) for p in self.pairs]
        self.reader = io.PairReader(self.mbs, self.channels, self.model.start_time,
                                    [(p.weight, *p.bands[:2]) for p in self.pairs])
        self.mbs.SetPostNewtonUserFunction(self.post_newton)
        self.model.user_functions.append(self.post_newton)

    def configure(self, settings: Any) -> None:
        """Exudyn's discontinuous-iteration settings: a scheme that :attr:`iterates` repeats a step's solve
        while the friction changes by more than the tolerance."""
        d = settings.timeIntegration.discontinuous
        d.iterationTolerance = self.settings.tolerance if self.iterates else 1.0
        d.maxIterations = self.settings.max_iterations + 1 if self.iterates else 1
        d.ignoreMaxIterations = True
        d.useRecommendedStepSize = False

    def _read_inputs(self, t: float | None) -> list[tuple[float, float, float, float]]:
        """Per pair the law's inputs ``(|F|, |M|, omega_rel, slide_rel)`` at the current state (``t``
        None: the initial state, velocity-level speeds)."""
        self._last_inputs = self.reader.read(t)
        return self._last_inputs

    def _law(self, inputs: list) -> tuple[float, ...]:
        """Friction, flat ``(M_z, F_z)`` per pair, for the law's ``inputs``; sets :attr:`scale_floor`."""
        friction, _, sliding, _ = self.table.loads(inputs)
        self.scale_floor = REST_FLOOR * sliding
        return friction

    def evaluate(self, t: float | None) -> tuple[float, ...]:
        """Friction at the current state, flat ``(M_z, F_z)`` on body b of each pair [N m, N] (``t``
        None: the initial state)."""
        return self._law(self._read_inputs(t))

    def consistent_start(self, solver: Any, settings: Any,
                         max_iterations: int = 60) -> tuple[np.ndarray, list] | None:
        """``(friction (n, 2) [N m, N], inputs)`` consistent with the initial reactions, by Broyden
        iteration of the loads before the first step (so the first row and step include friction); None,
        status ``self_locking``, without convergence in ``max_iterations``."""
        b = None
        x_prev = None
        r_prev = None
        x = np.zeros(int(self._mask.sum()))
        for _ in range(max_iterations):
            inputs = self._read_inputs(None)
            friction = np.array(self._law(inputs)).reshape(self.n, 2)
            r = friction.ravel()[self._mask] - x
            scale = max(float((np.abs(friction) * self._weight).max()), self.scale_floor)
            weighted = np.abs(r) * self._weight.ravel()[self._mask]
            if scale == 0.0 or weighted.max() <= self.settings.tolerance * scale:
                self.apply(friction)
                solver.InitializeSolverInitialConditions(self.mbs, settings)
                self.initial = friction.copy()
                return friction, inputs
            b = -np.eye(x.size) if b is None else _broyden_update(b, x, x_prev, r, r_prev)
            x_prev = x
            r_prev = r
            x = x + np.linalg.solve(b, -r)
            full = np.zeros(self._mask.size)
            full[self._mask] = x
            self.apply(full.reshape(self.n, 2))
            solver.InitializeSolverInitialConditions(self.mbs, settings)
        self.status = Status.SELF_LOCKING
        self.reason = (f"no consistent friction state at the start: the fixed-point iteration "
                       f"did not converge in {max_iterations} iterations (loop gain >= 1)")
        return None

    def apply(self, friction: Any, size: float | None = None) -> None:
        """Set every friction load from ``friction`` (flat ``(M_z, F_z)`` per pair or shape (n, 2)); ``size``
        its largest magnitude when known."""
        values = tuple(friction.ravel().tolist()) if isinstance(friction, np.ndarray) else friction
        self.loads.apply(values)
        self.applied = values
        self._applied_size = max(map(abs, values)) if size is None else size

    def failed(self, exc: Exception) -> list[float]:
        """Keep ``exc`` raised in a scheme's update in :attr:`error` (the pre-step function stops the run
        and ``solve`` re-raises it: a bug is not a physical outcome); the post-Newton return value."""
        self.error = exc
        self.status = Status.INTEGRATION_FAILURE
        self.reason = f"friction update raised {exc!r}"
        return [0.0, -1.0]

    def new_step(self, t: float) -> bool:
        """Bookkeeping at each evaluation; True at a step's first evaluation (the previous step is then
        accepted)."""
        log = self.log
        if t == self._step_t:
            self._step_iter += 1
            log.applied[-1] = self.applied
            log.iterations[-1] = self._step_iter + 1
            return False
        if self._step_t is not None:
            self.reader.accept(self._step_t)
        self._step_t = t
        self._step_iter = 0
        log.t.append(t)
        log.applied.append(self.applied)
        log.iterations.append(1)
        return True

    def change(self, friction: tuple, before: tuple) -> float:
        """Largest change [N m] between flat friction states ``friction`` and ``before``, forces weighted
        by ``d / 2``."""
        return max((w * abs(a - b) for w, a, b in zip(self._flat_weight, friction, before, strict=True)),
                   default=0.0)

    def grown(self, size: float) -> bool:
        """Whether friction of largest magnitude ``size`` has grown over :data:`LAGGED_GROWTH_LIMIT` times
        over consecutive growing steps (counted from :attr:`scale_floor` at least: noise is no locking)."""
        before = self._applied_size
        if not (before > 0.0 and size > before):
            self._growth_steps = 0
            return False
        if self._growth_steps == 0:
            self._growth_start = max(before, self.scale_floor)
        self._growth_steps += 1
        return size > LAGGED_GROWTH_LIMIT * self._growth_start

    def growth_reason(self) -> str:
        """Why a run whose friction has :meth:`grown` is self-locking, in one sentence."""
        return (f"{self.mode} friction grew geometrically by more than "
                f"{LAGGED_GROWTH_LIMIT:g}x over {self._growth_steps} steps up to "
                f"t = {self._step_t:.6g} s: the friction feedback loop gain is >= 1"
                + self.band_hint())

    def band_hint(self) -> str:
        """What to add to a self-locking reason when a pair's sign band is 0, else ``""``."""
        if all(min(self.bands[p.name]) > 0.0 for p in self.pairs):
            return ""
        return (" (with a sign band of 0 the exact sign of rounding-level relative speeds decides "
                "the direction of friction in pairs that do not move; use a positive band)")

    def diagnostics(self) -> FrictionDiagnostics:
        """The run's counters and loop-gain estimates (median, robust to the start-up steps, and largest)."""
        iterations = np.asarray(self.log.iterations, dtype=float)
        return FrictionDiagnostics(
            coupling=self.settings.coupling,
            sign_bands_m_s={p.name: tuple(self.bands[p.name]) for p in self.pairs},
            pairs_with_friction=tuple(p.name for p in self.pairs),
            tolerance=self.settings.tolerance if self.iterates else None,
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
        """Friction applied in the step ending at each of ``times`` [s], per pair ``<pair>_friction_torque``
        [N m] and ``<pair>_friction_force`` [N] (zeros elsewhere)."""
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


def friction_pairs(model: Any, bands: dict[str, Any]) -> list[PairData]:
    """The :class:`PairData` of ``model``'s pairs with friction, in order; ``bands`` per pair [m/s]."""
    scene = model.scene
    out = []
    for name, pair in scene.joint.friction_pairs():
        if pair.friction_coefficient <= 0.0:
            continue
        slides = PAIR_KIND[name] == "cylindrical" and scene.joint.errors.any
        law = PairLaw.of(PAIR_KIND[name], pair, scene.friction.law)
        out.append(PairData(name, law, model.joints[name], tuple(bands[name]), slides, 0.5 * law.d))
    return out


def body_contributions(model: Any, name: str) -> list[tuple[int, Any, int]]:
    """Per moving body of pair ``name``: body number, marker position in the body [m], -1 (a) or +1 (b)."""
    return [(model.bodies[body], local, role) for role, body, local in
            zip((-1, 1), PAIR_BODIES[name], model.marker_local[name], strict=True) if body != "ground"]


def _broyden_update(b: np.ndarray, x: np.ndarray, x_prev: np.ndarray | None, r: np.ndarray,
                    r_prev: np.ndarray | None) -> np.ndarray:
    """Broyden's update of the secant matrix ``b`` of ``r(x)`` from the last two iterates."""
    if x_prev is None:
        return b
    dx = x - x_prev
    dr = r - r_prev
    if dx @ dx > 0.0:
        b += np.outer(dr - b @ dx, dx) / (dx @ dx)
    return b
