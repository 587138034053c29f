"""Many constant-speed scenes as one model: per-sample parameters, one vectorised evaluation.

:meth:`SceneStack.columns` gives each sample :func:`reference.engine.table.columns_at`'s values for
its own scene, to rounding. A scene whose loop does not close goes to :attr:`SceneStack.failed`
(the caller runs it on its own) and is evaluated at input angle 0 so the others go on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from reference.engine.dynamics import solution_columns
from reference.engine.fixed_point import FixedPoint, solve_friction
from reference.engine.law_values import friction_law_values, reduced_law_values
from reference.engine.newton_euler import DRIVE_ROW, cross, mass_kinematics, unknowns, wrench_columns
from reference.engine.slots import (
    friction_matrix,
    friction_slots,
    ramp_bands,
    slip_speeds,
    slot_bands,
    slot_signs,
)
from reference.physics import kinematics, rccc
from reference.physics.bands import (
    PairBands,
    PairSpeeds,
    bands_from_speeds,
    needs_speeds,
    profile_angles,
    speeds_from_profile,
)
from reference.physics.dual import Dual
from reference.physics.friction import friction_magnitudes
from reference.physics.joint_motion import JointMotion, ideal_pair_origins, loop_motion
from reference.physics.loop_closure import solve_wrapped
from reference.scene.joint import BODY_NAMES, PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["CHUNK_SAMPLES", "HOOKE", "SceneStack", "StackedLaw", "StackedLoop"]

HOOKE = -1.0
"""Root of the loop's input-output equation on the ``"hooke"`` branch (the one every engine uses)."""
CHUNK_SAMPLES = 4096
"""Samples per vectorised evaluation: bounds the memory and is the fastest size measured (larger
calls leave the caches). Measured: docs/engines.md#constants-of-the-reference-engine."""


class StackedLoop:
    """The loop parameters of many scenes, one row per sample: twists ``alpha`` [rad], offsets ``a`` [m]
    (n, 4), ``s1`` [m] (n,); stands in for :class:`DHParameters` where only twists are asked for.
    """

    def __init__(self, alpha: np.ndarray, a: np.ndarray, s1: np.ndarray) -> None:
        self.alpha = alpha
        self.a = a
        self.s1 = s1

    def twists(self) -> Dual:
        """Dual link twists ``alpha_k + eps a_k``, shape (n, 4)."""
        return Dual(self.alpha, self.a)


class StackedLaw:
    """Eqs. (3) and (5) with per-sample coefficients for :func:`reference.engine.fixed_point.solve_friction`:
    ``signs`` packs, on a last axis of 3, each slot's friction factor, ``k_force`` and ``k_moment``.
    """

    def __init__(self, slots: list[tuple[str, str]]) -> None:
        position = {key: j for j, key in enumerate(unknowns()[:-1])}
        self.index = np.array([[position[(pair, c)] for c in ("fx", "fy", "mx", "my")]
                               for pair, _ in slots], dtype=int).reshape(len(slots), 4)

    def __call__(self, x: np.ndarray, packed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Friction values (n, K) and their Jacobian (n, K, 18)."""
        return friction_law_values(x, self.index, packed[..., 0], packed[..., 1], packed[..., 2])

    def reduced(self, c: np.ndarray, packed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(values, slopes)`` of :func:`reference.engine.law_values.reduced_law_values` on ``c`` (n, K, 4)
        with the ``packed`` (n, K, 3) per-sample factors and coefficients.
        """
        return reduced_law_values(c, packed[..., 0], packed[..., 1], packed[..., 2])


def _slot_coefficients(scene: Scene, slots: list[tuple[str, str]]) -> np.ndarray:
    """Per slot: journal diameter [m], the law's factors of ``|F|`` and ``|M|``; shape (K, 3)."""
    out = []
    pairs = dict(scene.joint.friction_pairs())
    for pair, kind in slots:
        data = pairs[pair]
        which = 0 if kind == "torque" else 1
        out.append((data.journal_diameter, float(friction_magnitudes(data, 1.0, 0.0)[which]),
                    float(friction_magnitudes(data, 0.0, 1.0)[which])))
    return np.array(out, float).reshape(len(slots), 3)


class SceneStack:
    """The parameters of constant-speed ``scenes`` sharing one :func:`reference.engine.batch.solve.batch_key`.

    ``sign_bands``: each scene's :func:`reference.physics.bands.sign_bands` from an earlier stack (the
    windings are then not checked again); None: computed here for all at once, with the engine's
    checks. A scene failing a check is in :attr:`failed` with placeholder bands: evaluate a stack of
    the others (a loop that does not close makes the matrices singular).
    """

    def __init__(self, scenes: Sequence[Scene], sign_bands: Sequence[dict] | None = None) -> None:
        self.scenes = list(scenes)
        first = self.scenes[0]
        self.first = first
        self.slots = friction_slots(first)
        self.ideal = not first.joint.errors.any
        self.speed = np.array([s.drive.speed for s in self.scenes], float)
        self.load = np.array([float(s.load.torque) for s in self.scenes], float)
        self.gravity = np.array([s.gravity for s in self.scenes], float).reshape(-1, 3)
        self.mass = {}
        for name in BODY_NAMES:
            props = [getattr(s.joint, name).canonical() for s in self.scenes]
            self.mass[name] = tuple(np.array([p[k] for p in props], float) for k in range(3))
        coefficients = np.array([_slot_coefficients(s, self.slots) for s in self.scenes])
        self.diameter, self.k_force, self.k_moment = np.moveaxis(coefficients, -1, 0)
        self.failed: set[int] = set()
        self._geometry()
        # sign_bands (a joint motion over a revolution) only for scenes with friction, as the engine
        self.sign_bands = self._sign_bands() if sign_bands is None else list(sign_bands)
        self.bands = np.array([slot_bands(s, self.slots, b) if self.slots else np.zeros(0)
                               for s, b in zip(self.scenes, self.sign_bands, strict=True)]
                              ).reshape(len(self.scenes), -1)
        self.ramp_bands = np.array([ramp_bands(s, self.slots, b) if self.slots else np.zeros(0)
                                    for s, b in zip(self.scenes, self.sign_bands, strict=True)]
                                   ).reshape(len(self.scenes), -1)

    def _geometry(self) -> None:
        joints = [s.joint for s in self.scenes]
        if self.ideal:
            self.beta = np.array([j.geometry.shaft_angle for j in joints], float)
            self.origins = np.array([[ideal_pair_origins(j.geometry)[p] for p in PAIR_NAMES]
                                     for j in joints], float)
            return
        params = [rccc.DHParameters.of_joint(j) for j in joints]
        self.alpha = np.array([p.alpha for p in params], float)
        self.offset = np.array([p.a for p in params], float)
        self.s1 = np.array([p.s1 for p in params], float)
        self.axial = np.array([rccc.axial_positions(j.geometry) for j in joints], float)
        zero = solve_wrapped(Dual(self.alpha, self.offset), self.s1, np.zeros(len(joints)), HOOKE,
                             "the reference input angle", strict=False)
        self.failed.update(np.flatnonzero(~np.all(np.isfinite(zero.re), -1)).tolist())
        self.zero_angle = np.nan_to_num(zero.re)
        self.zero_slide = np.nan_to_num(zero.du)

    def _check_windings(self) -> None:
        """:func:`reference.physics.rccc.positions.solve_positions`' windings check for every scene at once;
        a scene whose angles jump or whose loop does not close joins :attr:`failed`.
        """
        live = np.array([k for k in range(len(self.scenes)) if k not in self.failed], int)
        if live.size == 0:
            return
        theta1 = np.linspace(0.0, 2.0 * np.pi, rccc.WINDING_SAMPLES + 1)
        idx = np.repeat(live, theta1.size)
        raw = solve_wrapped(Dual(self.alpha[idx], self.offset[idx]), self.s1[idx], np.tile(theta1, live.size),
                            HOOKE, "input angles", strict=False).re.reshape(live.size, theta1.size, 4)
        with np.errstate(invalid="ignore"):
            jumps = np.any(rccc.winding_jumps(raw, self.zero_angle[live], theta1), (-2, -1))
        self.failed.update(live[jumps | ~np.all(np.isfinite(raw), (-2, -1))].tolist())

    def _sign_bands(self) -> list[dict[str, PairBands]]:
        """Every scene's :func:`reference.physics.bands.sign_bands`, characteristic speeds in one pass
        (a failed scene's are placeholders).
        """
        if not self.ideal:
            self._check_windings()
        need = [k for k, s in enumerate(self.scenes)
                if self.slots and needs_speeds(s) and k not in self.failed]
        speeds: dict[int, dict] = {}
        if need:
            theta = profile_angles()
            idx = np.repeat(need, theta.size)
            angles = np.tile(theta, len(need))
            omega_rel, slide_rel = self._pair_speeds(idx, angles, np.ones_like(angles))
            for j, k in enumerate(need):
                part = slice(j * theta.size, (j + 1) * theta.size)
                speeds[k] = speeds_from_profile(self.scenes[k], {p: v[part] for p, v in omega_rel.items()},
                                                {p: v[part] for p, v in slide_rel.items()})
        zero = {p: PairSpeeds(0.0, 0.0) for p in PAIR_NAMES}
        return [bands_from_speeds(s, speeds.get(k, zero) if needs_speeds(s) else None)
                for k, s in enumerate(self.scenes)]

    def _pair_speeds(self, idx: np.ndarray, theta: np.ndarray, theta_t: np.ndarray) -> tuple[dict, dict]:
        """Per pair the relative angular [rad/s] and sliding [m/s] speeds of scenes ``idx`` at ``theta``
        [rad], ``theta_t`` [rad/s] (only the loop's rates: no frames, no body motions).
        """
        zero = np.zeros_like(theta)
        if self.ideal:
            motion = self.motion(idx, theta, theta_t, zero)
            return motion.omega_rel, motion.slide_rel
        rates = self._loop_rates(idx, theta, theta_t, zero)[2]
        return ({p: rates.theta_t[..., k] for k, p in enumerate(PAIR_NAMES)},
                {p: rates.s_t[..., k] for k, p in enumerate(PAIR_NAMES)})

    def motion(self, idx: np.ndarray, theta: np.ndarray, theta_t: np.ndarray,
               theta_tt: np.ndarray) -> JointMotion:
        """:func:`reference.physics.joint_motion.joint_motion` of each sample's scene ``idx`` at ``theta``
        [rad], ``theta_t`` [rad/s], ``theta_tt`` [rad/s^2].
        """
        if self.ideal:
            beta = self.beta[idx]
            simple = kinematics.body_motions(theta, theta_t, theta_tt, beta)
            zero = np.zeros(theta.shape + (3,))
            bodies = {name: rccc.BodyMotion(m.rotation, zero, m.omega, zero, m.alpha, zero)
                      for name, m in simple.items()}
            origins = {p: self.origins[idx, k] for k, p in enumerate(PAIR_NAMES)}
            still = {p: np.zeros(theta.shape) for p in PAIR_NAMES}
            return JointMotion(bodies, kinematics.pair_frames(simple), origins,
                               kinematics.relative_speeds(simple), still, still,
                               kinematics.output_motion(theta, theta_t, theta_tt, beta))
        return self._loop(idx, theta, theta_t, theta_tt)

    def _loop_rates(self, idx: np.ndarray, theta: np.ndarray, theta_t: np.ndarray, theta_tt: np.ndarray
                    ) -> tuple[StackedLoop, rccc.LoopPositions, rccc.LoopRates]:
        """The loop's positions and rates (:func:`reference.physics.rccc.motion.solve_motion`) per sample."""
        params = StackedLoop(self.alpha[idx], self.offset[idx], self.s1[idx])
        raw = solve_wrapped(params.twists(), params.s1, theta, HOOKE, "input angles", strict=False)
        bad = ~np.all(np.isfinite(raw.re), -1)
        if np.any(bad):  # its scene runs on its own; the sample becomes a harmless one
            self.failed.update(np.unique(idx[bad]).tolist())
            theta = np.where(bad, 0.0, theta)
            raw = Dual(np.where(bad[:, None], self.zero_angle[idx], raw.re),
                       np.where(bad[:, None], self.zero_slide[idx], raw.du))
        reference = self.zero_angle[idx]
        positions = rccc.LoopPositions(rccc.continuous_angles(raw.re, reference, theta), raw.du,
                                       reference, "hooke", self.zero_slide[idx])
        return params, positions, rccc.solve_rates(params, positions, theta_t, theta_tt)

    def _loop(self, idx: np.ndarray, theta: np.ndarray, theta_t: np.ndarray,
              theta_tt: np.ndarray) -> JointMotion:
        params, positions, rates = self._loop_rates(idx, theta, theta_t, theta_tt)
        return loop_motion(params, positions, rates, self.axial[idx])

    def _body(self, name: str, idx: np.ndarray, motion: JointMotion) -> dict[str, np.ndarray]:
        mass, com, inertia = self.mass[name]
        k = mass_kinematics(mass[idx], com[idx], inertia[idx], motion.bodies[name])
        k["mass"] = k["mass"][:, None]
        return k

    def _reaction_system(self, idx: np.ndarray, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """:func:`reference.engine.newton_euler.reaction_system` with each sample's masses, gravity, load."""
        matrix = np.zeros(idx.shape + (18, 18))
        matrix[..., :-1] = wrench_columns(motion, unknowns()[:-1])
        matrix[..., DRIVE_ROW, -1] = 1.0  # the input's rows come first
        gravity = self.gravity[idx]
        parts = []
        for name in BODY_NAMES:
            k = self._body(name, idx, motion)
            m = motion.bodies[name]
            force = k["mass"] * (k["a"] - gravity)
            j_omega = np.einsum("...ij,...j->...i", k["inertia"], m.omega)
            j_alpha = np.einsum("...ij,...j->...i", k["inertia"], m.alpha)
            moment = cross(k["r"], force) + j_alpha + cross(m.omega, j_omega)
            parts.append(np.concatenate([force, moment], -1))
        rhs = np.concatenate(parts, -1)
        out = 6 * BODY_NAMES.index("output")
        rhs[..., out + 3:out + 6] += self.load[idx][:, None] * motion.frames["output_frame"][..., :, 2]
        return matrix, rhs

    def _energy(self, idx: np.ndarray, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """:func:`reference.engine.newton_euler.mechanical_energy` per sample [J]."""
        kinetic = 0.0
        potential = 0.0
        gravity = self.gravity[idx]
        for name in BODY_NAMES:
            k = self._body(name, idx, motion)
            w = motion.bodies[name].omega
            j_omega = np.einsum("...ij,...j->...i", k["inertia"], w)
            kinetic = (kinetic + 0.5 * k["mass"][:, 0] * np.sum(k["v"] ** 2, -1)
                       + 0.5 * np.sum(w * j_omega, -1))
            potential = potential - k["mass"][:, 0] * np.sum(k["r"] * gravity, -1)
        return kinetic, potential

    def slot_speeds(self, idx: np.ndarray, omega_rel: dict[str, np.ndarray],
                    slide_rel: dict[str, np.ndarray]) -> np.ndarray:
        """:func:`reference.engine.slots.slot_speeds` (n, K) [m/s] with the journal diameters of each
        sample's scene ``idx``.
        """
        out = [0.5 * self.diameter[idx, j] * omega_rel[pair] if kind == "torque"
               else slide_rel[pair] for j, (pair, kind) in enumerate(self.slots)]
        return np.stack(out, -1) if out else np.zeros(idx.shape + (0,))

    def ramp_speeds(self, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
        """:func:`reference.engine.slots.ramp_speeds` (n, K') [m/s] of scenes ``idx`` at instants ``t`` [s],
        :data:`CHUNK_SAMPLES` at a time.
        """
        if idx.size <= CHUNK_SAMPLES:
            return self._ramp_speeds(idx, t)
        return np.concatenate([self._ramp_speeds(idx[k:k + CHUNK_SAMPLES], t[k:k + CHUNK_SAMPLES])
                               for k in range(0, idx.size, CHUNK_SAMPLES)])

    def _ramp_speeds(self, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
        w = self.speed[idx]
        omega_rel, slide_rel = self._pair_speeds(idx, w * t, w + 0.0)
        speeds = self.slot_speeds(idx, omega_rel, slide_rel)
        if self.first.friction.law != "resultant":
            return speeds
        return np.concatenate([speeds, slip_speeds(self.slots, speeds)], -1)

    def _fixed_point(self, idx: np.ndarray, motion: JointMotion, exact_gain: float) -> FixedPoint:
        matrix, rhs = self._reaction_system(idx, motion)
        wrenches = friction_matrix(motion, self.slots)
        both = np.linalg.solve(matrix, np.concatenate([rhs[..., None], wrenches], -1))
        n = idx.size
        if not self.slots:
            return solve_friction(StackedLaw(self.slots), both[..., 0], both[..., 1:], np.zeros((n, 0, 3)))
        speeds = self.slot_speeds(idx, motion.omega_rel, motion.slide_rel)
        signs = slot_signs(self.first, self.slots, speeds, self.bands[idx])
        packed = np.stack([signs, self.k_force[idx], self.k_moment[idx]], -1)
        law = StackedLaw(self.slots)
        if self.first.friction.coupling == "uncoupled":  # on the frictionless reactions only
            return FixedPoint(both[..., 0], law(both[..., 0], packed)[0], np.ones(n, bool), np.zeros(n), 0)
        return solve_friction(law, both[..., 0], both[..., 1:], packed, exact_gain=exact_gain)

    def columns(self, idx: np.ndarray, t: np.ndarray, energy: bool = True) -> dict[str, np.ndarray]:
        """:func:`reference.engine.table.columns_at` of scenes ``idx`` at instants ``t`` [s],
        :data:`CHUNK_SAMPLES` at a time; ``energy`` False leaves the energy columns zero and the loop gain
        exact only where it decides self-locking.
        """
        idx = np.asarray(idx, int)
        t = np.asarray(t, float)
        if idx.size <= CHUNK_SAMPLES:
            return self._columns(idx, t, energy)
        parts = [self._columns(idx[k:k + CHUNK_SAMPLES], t[k:k + CHUNK_SAMPLES], energy)
                 for k in range(0, idx.size, CHUNK_SAMPLES)]
        return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}

    def _columns(self, idx: np.ndarray, t: np.ndarray, energy: bool) -> dict[str, np.ndarray]:
        w = self.speed[idx]
        theta = w * t
        theta_t = w + 0.0
        theta_tt = np.zeros_like(t)
        motion = self.motion(idx, theta, theta_t, theta_tt)
        fixed = self._fixed_point(idx, motion, 0.5 if energy else 1.0)
        drive = np.where(fixed.self_locking, np.nan, fixed.x[:, -1])
        energies = self._energy(idx, motion) if energy else (np.zeros_like(t), np.zeros_like(t))
        cols = solution_columns(motion, fixed, self.slots, (theta, theta_t, theta_tt), drive,
                                self.load[idx], energies)
        return {"t": t, **cols}
