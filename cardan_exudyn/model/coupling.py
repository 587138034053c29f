"""Friction of eqs. (1)-(5) in the Exudyn model, computed from the pairs' reaction outputs: what
every coupling scheme shares (:class:`FrictionCoupling`).

What is added to the model
--------------------------
For each pair with a non-zero friction coefficient (and only for those) a friction torque about
the pair axis, and for cylindrical pairs of a joint with mounting errors an axial force, on each
moving body of the pair: merged per body into one body-fixed torque vector, and a force vector
only where a pair slides (:class:`cardan_exudyn.model.friction_io.BodyLoads`). Body ``b``
receives the friction (torque ``M_z``, force ``F_z``), body ``a`` the opposite. The ideal
joint's cylindrical pairs cannot slide: their axial friction is 0 (as the reference engine
computes it), so that the solver's noise in their slide (at the Newton tolerance) is never
turned into force by the sign ramp.

How the friction is updated
---------------------------
One Python post-Newton user function (``mbs.SetPostNewtonUserFunction``) reads, after each Newton
solve, the law's inputs -- per pair the magnitudes of the reaction force normal to the axis and of
the bending moment (from the Lagrange multipliers), and the relative angular and sliding speeds
(BDF2 of the joint's own angle and slide outputs) -- computes the friction and sets the loads
(:mod:`cardan_exudyn.model.friction_io`, :class:`cardan_exudyn.model.friction_law.LawTable`). The
friction is carried as one flat tuple ``(M_z, F_z)`` per pair. Before the first step it is
iterated to consistency with the initial state (:meth:`FrictionCoupling.initialise`), so no
scheme starts frictionless. The schemes (``scene.friction.coupling``) differ in what the function
does after a solve: :mod:`~cardan_exudyn.model.extrapolated` (the default, one solve per step),
:mod:`~cardan_exudyn.model.converged` (a fixed point per step), :mod:`~cardan_exudyn.model.lagged`
(the paper's: the friction one step late).

Self-locking
------------
The friction feedback (friction -> reactions -> friction) has a loop gain; at a gain of 1 or more
there is no consistent friction. A scheme that iterates a step to its fixed point sees this as a
stalled iteration; a scheme with one solve per step as geometric growth of the friction from
step to step, and growth by more than :data:`LAGGED_GROWTH_LIMIT` over consecutive growing steps
is handled by the scheme (:meth:`FrictionCoupling.grown`). Either way the run ends with
status ``self_locking``.
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
"""The fixed-point tolerance is relative to the largest friction load, but at least to this share
of the largest load the pairs would carry sliding: when every rubbing pair is at rest (inside its
sign ramp, e.g. the spider pairs at 0 deg) the loads are rounding noise of the relative speeds,
and a tolerance relative to the noise itself is never met."""


@dataclass
class PairData:
    """A pair with friction as the coupling sees it.

    Attributes
    ----------
    name : str
        One of :data:`reference.scene.joint.PAIR_NAMES`.
    law : PairLaw
        Its friction law.
    joint : int
        Its Exudyn ``ObjectJointGeneric``.
    bands : (float, float, float)
        Half-widths of its sign ramps [m/s]: rotation, sliding, resultant.
    slides : bool
        Whether it carries an axial force (cylindrical, with mounting errors).
    weight : float
        The lever that makes a force count as a torque, ``d / 2`` [m].
    """

    name: str
    law: PairLaw
    joint: int
    bands: tuple[float, float, float]
    slides: bool
    weight: float


@dataclass
class FrictionLog:
    """Per accepted step: its time [s], the friction in effect in its final solve (flat
    ``(M_z, F_z)`` per pair [N m, N]) and the evaluations it took."""

    t: list = field(default_factory=list)
    applied: list = field(default_factory=list)
    iterations: list = field(default_factory=list)


class FrictionCoupling:
    """Friction loads of a model, their bookkeeping and the services every coupling scheme uses.

    A scheme (a subclass: :class:`~cardan_exudyn.model.lagged.LaggedCoupling`,
    :class:`~cardan_exudyn.model.converged.ConvergedCoupling`,
    :class:`~cardan_exudyn.model.extrapolated.ExtrapolatedCoupling`) adds ``initialise(solver,
    settings)`` and ``post_newton(mbs, t)``, Exudyn's user function, and calls down into these;
    nothing here calls a scheme's methods, so each scheme reads from the top down.

    Parameters
    ----------
    model : cardan_exudyn.model.build.ExudynModel
        The model being built, its bodies, joints, markers and pair frames added.
    """

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
        """Exudyn's discontinuous-iteration settings: a scheme that :attr:`iterates` repeats a
        step's solve while the friction changes by more than the tolerance."""
        d = settings.timeIntegration.discontinuous
        d.iterationTolerance = self.settings.tolerance if self.iterates else 1.0
        d.maxIterations = self.settings.max_iterations + 1 if self.iterates else 1
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

    def consistent_start(self, solver: Any, settings: Any,
                         max_iterations: int = 60) -> tuple[np.ndarray, list] | None:
        """Friction consistent with the initial reactions, before the first step.

        Exudyn computes the initial accelerations and reactions from the initial state and the
        loads in place; the friction loads are iterated with them (Broyden) until consistent,
        so that the first recorded row and the first step include friction.

        Parameters
        ----------
        solver : exudyn.MainSolverImplicitSecondOrder
            Initialised (``solver.InitializeSolver`` called).
        settings : exudyn.SimulationSettings
            The run's settings.
        max_iterations : int
            Broyden iterations before the start is declared self-locking.

        Returns
        -------
        (friction, inputs) or None
            The friction in effect, shape (n, 2) [N m, N], and the law's inputs read there
            (:meth:`_read_inputs`); None, with :attr:`status` ``self_locking``, when the
            iteration does not converge in ``max_iterations``.
        """
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
        """Set every friction load.

        Parameters
        ----------
        friction : tuple or ndarray
            Flat ``(M_z, F_z)`` per pair [N m, N], or an array of shape (n, 2).
        size : float, optional
            Its largest magnitude, when known.
        """
        values = tuple(friction.ravel().tolist()) if isinstance(friction, np.ndarray) else friction
        self.loads.apply(values)
        self.applied = values
        self._applied_size = max(map(abs, values)) if size is None else size

    def failed(self, exc: Exception) -> list[float]:
        """What a scheme's post-Newton function returns when its update raised ``exc``.

        Exudyn reports any Python exception raised in a user function as a solver failure; the
        exception is kept in :attr:`error` instead (the pre-step function then stops the run) so
        that :func:`cardan_exudyn.model.solve.solve` re-raises it: a bug is not a physical
        outcome.
        """
        self.error = exc
        self.status = Status.INTEGRATION_FAILURE
        self.reason = f"friction update raised {exc!r}"
        return [0.0, -1.0]

    def new_step(self, t: float) -> bool:
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
        self._step_t = t
        self._step_iter = 0
        log.t.append(t)
        log.applied.append(self.applied)
        log.iterations.append(1)
        return True

    def change(self, friction: tuple, before: tuple) -> float:
        """Largest change between two friction states, forces weighted by ``d / 2``.

        Parameters
        ----------
        friction, before : tuple of float
            Flat ``(M_z, F_z)`` per pair [N m, N].

        Returns
        -------
        float
            The largest weighted change [N m].
        """
        return max((w * abs(a - b) for w, a, b in zip(self._flat_weight, friction, before, strict=True)),
                   default=0.0)

    def grown(self, size: float) -> bool:
        """Self-locking watch of a scheme with one solve per step: whether the friction about to
        be applied (largest magnitude ``size``) has grown by more than
        :data:`LAGGED_GROWTH_LIMIT` over consecutive growing steps. Growth out of rounding noise
        (pairs at rest) is no locking: it counts from :attr:`scale_floor` at least."""
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
        """The run's counters and loop-gain estimates (median and largest; the median is robust
        to the start-up steps)."""
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
        """Friction applied in the step ending at each recorded time ``times`` [s], per pair
        (``<pair>_friction_torque`` [N m], ``<pair>_friction_force`` [N]; zeros elsewhere)."""
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
    """The pairs of ``model``'s scene with a non-zero friction coefficient, in order.

    Parameters
    ----------
    model : ExudynModel
        The model being built (its joints added).
    bands : dict of str to (float, float, float)
        Each pair's sign ramps [m/s] (:func:`reference.physics.bands.sign_bands`).

    Returns
    -------
    list of PairData
    """
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
    """The moving bodies of a pair that carry its friction.

    Parameters
    ----------
    model : ExudynModel
        The model being built (bodies and markers added).
    name : str
        One of :data:`reference.scene.joint.PAIR_NAMES`.

    Returns
    -------
    list of (int, ndarray, int)
        Per moving body its body number, the marker position in the body [m], shape (3,), and
        -1 for body ``a``, +1 for body ``b``.
    """
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
