"""Dynamics of the Cardan joint with the paper's friction: Newton-Euler, batched over samples.

For a given input motion the kinematics (:func:`reference.physics.joint_motion.joint_motion`: closed
form for the ideal joint, the dual-number loop with mounting errors) give every body's motion.
Newton-Euler for the three moving bodies (force balance and moment balance about the global
origin O) is then linear in the 18 unknowns

- ``frame_input`` (revolute): fx, fy, fz, mx, my;
- ``input_spider``, ``spider_output``, ``output_frame`` (cylindrical): fx, fy, mx, my;
- the drive torque on the input about +x (inverse dynamics) or the input acceleration
  (forward dynamics, the drive torque given),

each reaction being the force and moment (about the pair origin) that body ``a`` exerts on body
``b``, in the pair frame attached to body ``a`` (:func:`reference.physics.kinematics.pair_frames`). Body
``b`` receives the wrench, body ``a`` its opposite.

Friction (eqs. (3) and (5), :mod:`reference.physics.friction`) is an applied load that depends on the
reactions, and the reactions depend on it. With ``phi`` the friction values (a torque per pair
with friction, an axial force per cylindrical pair with friction), the equations are
``K x = r - W phi`` and ``phi = G(x)``: linear in ``x``, so ``x = x0 - S phi`` with
``x0 = K^-1 r`` and ``S = K^-1 W``, and the fixed point reduces to at most seven unknowns,
``phi = G(x0 - S phi)``. It is solved by Newton's method with the analytic Jacobian of ``G``,
every sample at once. A sample whose fixed point does not converge, or converges to a point where
the loop gain (spectral radius of ``dG/dphi``) is 1 or more, is *self-locking*: friction grows
faster than the reactions that cause it, the Coulomb problem has no unique finite solution.

Pair origins and frames come with the joint motion: in the ideal joint the origins are fixed in
space (``frame_input`` at ``-input_bearing e_x``, the spider pairs at O, ``output_frame`` at
``output_bearing a2``) and no pair slides, so the regularised sign of the zero sliding speed is 0
and the axial friction of eq. (5) vanishes. With mounting errors the cylindrical pairs slide and
their axial friction does work (``power_loss_<pair>_sliding``).

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3 (RCCC model, reactions in the joint frames, eqs. (8)-(9)),
eqs. (3), (5) (friction from the reactions) and eq. (18) (instantaneous efficiency).
"""

from __future__ import annotations

import numpy as np

from reference.engine.fixed_point import FixedPoint, friction_law_values, reduced_law_values, solve_friction
from reference.physics.bands import sign_bands
from reference.physics.friction import friction_magnitudes, pair_power_loss, regularised_sign
from reference.physics.joint_motion import JointMotion, joint_motion
from reference.physics.rccc.motion import BodyMotion
from reference.results.schema import (
    PAIR_SUFFIXES,
    instantaneous_efficiency,
)
from reference.scene.joint import BODY_NAMES, PAIR_BODIES, PAIR_KIND, PAIR_NAMES, Body
from reference.scene.scene import Scene

DRIVE_ROW = 3  # the input's moment about x (rows: per body force x, y, z, moment x, y, z)
_COMPONENTS = {"revolute": ("fx", "fy", "fz", "mx", "my"), "cylindrical": ("fx", "fy", "mx", "my")}


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis (``numpy.cross`` without its per-call overhead)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def unknowns() -> list[tuple[str, str]]:
    """The 18 unknowns in solution order: ``(pair, component)`` and ``("drive", "torque_in")``."""
    out = [(pair, c) for pair in PAIR_NAMES for c in _COMPONENTS[PAIR_KIND[pair]]]
    return out + [("drive", "torque_in")]


def body_kinematics(body: Body, motion: BodyMotion) -> dict[str, np.ndarray]:
    """Centre-of-mass position, velocity, acceleration and inertia of a body, global components.

    Parameters
    ----------
    body : Body
        Mass properties; :meth:`Body.canonical` places them in the canonical body frame, whose
        origin is the body's frame origin (the joint centre O for the ideal joint).
    motion : reference.physics.rccc.motion.BodyMotion
        Pose and motion of the body.

    Returns
    -------
    dict
        ``mass`` [kg]; ``r``, ``v``, ``a``: centre of mass relative to O [m], its velocity [m/s]
        and acceleration [m/s^2], shape (..., 3); ``inertia`` about the centre of mass
        [kg m^2], shape (..., 3, 3).
    """
    return mass_kinematics(*body.canonical(), motion)


def mass_kinematics(mass: float | np.ndarray, com: np.ndarray, inertia: np.ndarray,
                    motion: BodyMotion) -> dict[str, np.ndarray]:
    """:func:`body_kinematics` from the canonical mass properties (:meth:`Body.canonical`):
    ``mass`` [kg], ``com`` (3,) [m] and ``inertia`` (3, 3) [kg m^2], or one per sample, shapes
    (...,), (..., 3), (..., 3, 3) (many scenes in one pass, :mod:`reference.engine.batch.solve`)."""
    rot = motion.rotation
    c = rot @ com if np.ndim(com) == 1 else np.einsum("...ij,...j->...i", rot, com)
    w_c = cross(motion.omega, c)
    return {"mass": mass, "r": motion.origin + c, "v": motion.velocity + w_c,
            "a": motion.acceleration + cross(motion.alpha, c) + cross(motion.omega, w_c),
            "inertia": rot @ inertia @ np.swapaxes(rot, -1, -2)}


def required_wrench(body: Body, motion: BodyMotion,
                    gravity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force [N] and moment about O [N m] the pairs, drive and load must apply to a body.

    Newton-Euler with gravity moved to the left: ``F = m (a_c - g)``,
    ``M_O = r_c x F + J alpha + omega x J omega`` (J about the centre of mass, global axes).
    """
    k = body_kinematics(body, motion)
    force = k["mass"] * (k["a"] - gravity)
    j_omega = np.einsum("...ij,...j->...i", k["inertia"], motion.omega)
    j_alpha = np.einsum("...ij,...j->...i", k["inertia"], motion.alpha)
    return force, cross(k["r"], force) + j_alpha + cross(motion.omega, j_omega)


def mechanical_energy(scene: Scene,
                      motions: dict[str, BodyMotion]) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy of the three bodies [J] (potential zero at O)."""
    gravity = np.asarray(scene.gravity)
    kinetic, potential = 0.0, 0.0
    for name, body in scene.joint.bodies():
        k = body_kinematics(body, motions[name])
        w = motions[name].omega
        j_omega = np.einsum("...ij,...j->...i", k["inertia"], w)
        kinetic = kinetic + 0.5 * k["mass"] * np.sum(k["v"] ** 2, -1) + 0.5 * np.sum(w * j_omega, -1)
        potential = potential - k["mass"] * (k["r"] @ gravity)
    return kinetic, potential


def wrench_columns(motion: JointMotion, components: list[tuple[str, str]]) -> np.ndarray:
    """Body wrenches of unit pair loads, rows as :func:`reaction_system`, shape (..., 18, m).

    Each component ``(pair, "fx" | "fy" | "fz" | "mx" | "my" | "mz")`` is a unit force along
    (at the pair origin) or moment about that axis of the pair frame, acting on body b; body a
    receives the opposite. All components are built in one vectorised pass.
    """
    shape = motion.bodies["input"].omega.shape[:-1]
    if not components:
        return np.zeros(shape + (6 * len(BODY_NAMES), 0))
    d = np.stack([motion.frames[p][..., :, "xyz".index(c[1])] for p, c in components], -2)
    is_force = np.array([c[0] == "f" for _, c in components])[:, None]
    lever = np.stack([motion.origins[p] for p, _ in components], -2)
    unit = np.concatenate([np.where(is_force, d, 0.0),
                           np.where(is_force, cross(lever, d), d)], -1)  # (..., m, 6)
    incidence = np.zeros((len(BODY_NAMES), len(components)))
    for j, (pair, _) in enumerate(components):
        a, b = PAIR_BODIES[pair]
        for body, sign in ((b, 1.0), (a, -1.0)):
            if body in BODY_NAMES:
                incidence[BODY_NAMES.index(body), j] = sign
    out = np.einsum("bm,...mk->...bkm", incidence, unit)
    return out.reshape(shape + (6 * len(BODY_NAMES), len(components)))


def reaction_system(scene: Scene, motion: JointMotion,
                    load_torque: float | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Newton-Euler equations of the three bodies as ``matrix @ unknowns = rhs``.

    ``load_torque`` [N m] (scalar or one per sample) is the output load at these samples; None
    takes the scene's constant load (a load history needs it given: the motion has no time).

    Returns
    -------
    matrix : ndarray, shape (..., 18, 18)
        Rows: per body (input, spider, output) force x, y, z [N] and moment about O x, y, z
        [N m]; columns: :func:`unknowns`.
    rhs : ndarray, shape (..., 18)
        Required wrench minus the known applied wrench (the load torque on the output).
    """
    shape = motion.bodies["input"].omega.shape[:-1]
    rows = {name: 6 * i for i, name in enumerate(BODY_NAMES)}
    matrix = np.zeros(shape + (18, 18))
    matrix[..., :-1] = wrench_columns(motion, unknowns()[:-1])
    matrix[..., rows["input"] + DRIVE_ROW, -1] = 1.0  # drive torque about +x (the fixed input axis)
    rhs = np.concatenate([np.concatenate(required_wrench(body, motion.bodies[name],
                                                         np.asarray(scene.gravity)), -1)
                          for name, body in scene.joint.bodies()], -1)
    # the load's moment -T u on the output (u its axis, the output_frame pair's z), to the right
    load = np.asarray(constant_load(scene) if load_torque is None else load_torque, float)
    rhs[..., rows["output"] + 3:rows["output"] + 6] += (load[..., None]
                                                       * motion.frames["output_frame"][..., :, 2])
    return matrix, rhs


def constant_load(scene: Scene) -> float:
    """The scene's load torque [N m]; a history needs the instants, so it is refused here."""
    if not scene.load.constant:
        raise ValueError("the scene's load is a torque history: pass `load_torque` for the samples")
    return float(scene.load.torque)


def friction_slots(scene: Scene) -> list[tuple[str, str]]:
    """The friction values the scene produces: ``(pair, "torque" | "force")`` in solution order.

    A pair with friction gets a torque about its axis; a cylindrical one also an axial force.
    Frictionless pairs get none, so a frictionless scene has no friction unknowns at all.
    """
    slots = []
    for pair, data in scene.joint.pairs.items():
        if data.friction_coefficient > 0.0:
            slots.append((pair, "torque"))
            if PAIR_KIND[pair] == "cylindrical":
                slots.append((pair, "force"))
    return slots


def friction_matrix(motion: JointMotion, slots: list[tuple[str, str]]) -> np.ndarray:
    """Body wrenches of unit friction values, rows as :func:`reaction_system`, shape (..., 18, K).

    A friction torque acts on body b about the pair axis, an axial force along it at the pair
    origin; body a receives the opposite.
    """
    return wrench_columns(motion, [(pair, "mz" if kind == "torque" else "fz") for pair, kind in slots])


class FrictionLaw:
    """Eqs. (3) and (5) as a function of the reaction vector, with its Jacobian.

    The law is linear in the normal force and moment magnitudes ``|F|``, ``|M|``; its
    coefficients per slot are taken from :func:`reference.physics.friction.friction_magnitudes`.

    Parameters
    ----------
    scene : Scene
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
    """

    def __init__(self, scene: Scene, slots: list[tuple[str, str]]) -> None:
        position = {key: j for j, key in enumerate(unknowns()[:-1])}
        self.index = np.array([[position[(pair, c)] for c in ("fx", "fy", "mx", "my")]
                               for pair, _ in slots], dtype=int).reshape(len(slots), 4)
        coefficients = []
        pairs = dict(scene.joint.friction_pairs())
        for pair, kind in slots:
            which = 0 if kind == "torque" else 1  # eq. (3) torque or eq. (5) axial force
            data = pairs[pair]
            coefficients.append((float(friction_magnitudes(data, 1.0, 0.0)[which]),
                                 float(friction_magnitudes(data, 0.0, 1.0)[which])))
        self.k_force, self.k_moment = np.array(coefficients, float).reshape(len(slots), 2).T

    def __call__(self, x: np.ndarray, signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Friction values ``G(x)`` and Jacobian ``dG/dx``.

        Parameters
        ----------
        x : ndarray, shape (n, 18)
            Reactions (and the drive unknown, unused), ordered as :func:`unknowns`.
        signs : ndarray, shape (n, K)
            Regularised sign of the relative motion for each slot, or under the resultant-slip
            law the slot's component of the regularised unit slip vector (:func:`slot_signs`;
            fixed by the kinematics).

        Returns
        -------
        values : ndarray, shape (n, K)
            Friction torque [N m] / axial force [N] on body b.
        jacobian : ndarray, shape (n, K, 18)
            Derivatives with respect to ``x``; where a norm is exactly zero, the zero
            subgradient.
        """
        return friction_law_values(x, self.index, signs, self.k_force, self.k_moment)

    def reduced(self, c: np.ndarray, signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`reduced_law_values` of the slots' reaction components ``c`` = ``x[:, index]``."""
        return reduced_law_values(c, signs, self.k_force, self.k_moment)


def slot_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """Relative surface speed (rotation: ``omega_rel d / 2``) or sliding speed of each slot [m/s].

    These are the speeds whose sign the friction law takes, shape (..., K).
    """
    out = []
    for pair, kind in slots:
        if kind == "torque":
            out.append(0.5 * getattr(scene.joint.pairs, pair).journal_diameter * omega_rel[pair])
        else:
            out.append(slide_rel[pair])
    return np.stack(out, -1)


def slot_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Width of each slot's sign ramp [m/s] (``bands``, or :func:`reference.physics.bands.sign_bands`),
    shape (K,).

    Under the resultant-slip law (``scene.friction.law``) both slots of a pair share the ramp of
    its resultant slip speed.
    """
    bands = sign_bands(scene) if bands is None else bands
    if scene.friction.law == "resultant":
        return np.array([bands[pair].resultant for pair, _ in slots], dtype=float)
    return np.array([bands[pair].rotation if kind == "torque" else bands[pair].sliding
                     for pair, kind in slots], dtype=float)


def slip_speeds(slots: list[tuple[str, str]], speeds: np.ndarray) -> np.ndarray:
    """Per slot, the resultant slip speed of its pair [m/s]: the hypotenuse of the pair's slot
    speeds (:func:`slot_speeds`, shape (..., K)), shape (..., K)."""
    out = np.empty_like(speeds)
    for pair in dict.fromkeys(pair for pair, _ in slots):
        mine = [j for j, (p, _) in enumerate(slots) if p == pair]
        out[..., mine] = np.sqrt(np.sum(np.square(speeds[..., mine]), -1))[..., None]
    return out


def slot_signs(scene: Scene, slots: list[tuple[str, str]], speeds: np.ndarray,
               bands: np.ndarray) -> np.ndarray:
    """The factor of each slot's Coulomb magnitude, in [-1, 1], shape (..., K).

    ``speeds`` from :func:`slot_speeds`, ``bands`` from :func:`slot_bands`. The paper's law: the
    regularised sign of each slot's speed (:func:`reference.physics.friction.regularised_sign`). The
    resultant-slip law: the slot's component of its pair's regularised unit slip vector
    ``v / max(|v|, band)`` (:mod:`reference.physics.friction`).
    """
    if scene.friction.law != "resultant":
        return regularised_sign(speeds, bands)
    size = np.maximum(slip_speeds(slots, speeds), bands)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(size > 0.0, speeds / size, 0.0)


def ramp_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """Speeds [m/s] whose crossings of ``+-`` :func:`ramp_bands` are the kinks of the friction
    factors (:func:`slot_signs`), shape (..., K'): the slot speeds (:func:`slot_speeds`), and under
    the resultant-slip law also the pairs' slip speeds (the slot speeds' zero crossings stay: with
    a zero band the factor jumps there when the pair does not slide)."""
    speeds = slot_speeds(scene, slots, omega_rel, slide_rel)
    if scene.friction.law != "resultant":
        return speeds
    return np.concatenate([speeds, slip_speeds(slots, speeds)], -1)


def ramp_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Ramp widths [m/s] of :func:`ramp_speeds`, shape (K',) (``bands`` as for :func:`slot_bands`)."""
    bands = slot_bands(scene, slots, bands)
    return np.concatenate([bands, bands]) if scene.friction.law == "resultant" else bands


def solve_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                   theta_tt: np.ndarray | None = None,
                   torque_in: float | np.ndarray | None = None,
                   method: str = "auto",
                   load_torque: float | np.ndarray | None = None,
                   bands: np.ndarray | None = None) -> tuple[JointMotion, FixedPoint]:
    """Reactions, friction and the drive unknown for every sample.

    Exactly one of ``theta_tt`` (inverse dynamics: the drive torque is the unknown) and
    ``torque_in`` (forward dynamics: the input acceleration is the unknown) is given.
    ``method`` chooses the kinematics (:func:`reference.physics.joint_motion.joint_motion`);
    ``load_torque`` [N m] the output load per sample (None: the scene's constant load);
    ``bands`` the sign ramps' widths (None: :func:`slot_bands`, looked up by the scene, whose
    hash a caller solving one sample at a time may save by passing them).

    Returns
    -------
    motion : JointMotion
        The joint's motion (with the solved acceleration in forward dynamics).
    fixed_point : FixedPoint
        ``x[..., -1]`` is the drive torque [N m] or the input acceleration [rad/s^2].
    """
    if (theta_tt is None) == (torque_in is None):
        raise ValueError("give exactly one of `theta_tt` (inverse) and `torque_in` (forward)")
    joint = scene.joint
    theta, theta_t = np.atleast_1d(np.asarray(theta, float)), np.atleast_1d(np.asarray(theta_t, float))
    n = theta.size
    if theta_tt is not None:
        motion = joint_motion(joint, theta, theta_t, np.broadcast_to(theta_tt, theta.shape), method)
        matrix, rhs = reaction_system(scene, motion, load_torque)
        omega_rel, slide_rel = motion.omega_rel, motion.slide_rel
        wrenches = friction_matrix(motion, friction_slots(scene))
    else:  # one batch at accelerations 0 and 1: the right-hand side is affine in theta_tt
        pair = joint_motion(joint, np.tile(theta, 2), np.tile(theta_t, 2), np.repeat([0.0, 1.0], n),
                            method)
        load = None if load_torque is None else np.tile(np.broadcast_to(load_torque, theta.shape), 2)
        matrix, rhs = reaction_system(scene, pair, load)
        matrix, rhs_one, rhs = matrix[:n], rhs[n:], rhs[:n]
        matrix[..., :, -1] = -(rhs_one - rhs)  # the acceleration's share moves to the left
        rhs[..., DRIVE_ROW] -= torque_in
        # velocity-level quantities and the pair geometry do not depend on the acceleration
        omega_rel = {p: v[:n] for p, v in pair.omega_rel.items()}
        slide_rel = {p: v[:n] for p, v in pair.slide_rel.items()}
        wrenches = friction_matrix(pair, friction_slots(scene))[:n]
    slots = friction_slots(scene)
    both = np.linalg.solve(matrix, np.concatenate([rhs[..., None], wrenches], -1))
    if bands is None:
        bands = slot_bands(scene, slots)
    signs = (slot_signs(scene, slots, slot_speeds(scene, slots, omega_rel, slide_rel), bands)
             if slots else np.zeros(theta.shape + (0,)))
    law = FrictionLaw(scene, slots)
    if scene.friction.coupling == "uncoupled":  # evaluated on the frictionless reactions only
        fixed = FixedPoint(both[..., 0], law(both[..., 0], signs)[0], np.ones(n, bool), np.zeros(n), 0)
    else:
        fixed = solve_friction(law, both[..., 0], both[..., 1:], signs)
    if torque_in is not None:
        motion = joint_motion(joint, theta, theta_t, fixed.x[..., -1], method)
    return motion, fixed


def dynamics_columns(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray | None = None,
                     torque_in: float | None = None,
                     method: str = "auto",
                     load_torque: float | np.ndarray | None = None,
                     ) -> tuple[dict[str, np.ndarray], FixedPoint]:
    """Result-schema columns (without ``t``) for the given motion, with friction.

    Inverse dynamics when ``theta_tt`` is given, forward dynamics when ``torque_in`` is (see
    :func:`solve_dynamics`). Samples that self-lock carry NaN reactions, friction and powers.

    Returns
    -------
    columns : dict of str to ndarray, shape (n,)
        Every column of :func:`reference.results.schema.table_columns` but ``t``, plus
        ``input_acceleration`` [rad/s^2], ``friction_loop_gain`` [-], ``self_locking`` and, per
        pair, ``<pair>_slide`` [m] (the D-H slide; zero in the ideal joint) and the two parts of
        its loss, ``power_loss_<pair>_rotation`` and ``power_loss_<pair>_sliding`` [W].
    fixed_point : FixedPoint
    """
    motion, fixed = solve_dynamics(scene, theta, theta_t, theta_tt, torque_in, method, load_torque)
    theta, theta_t = np.atleast_1d(np.asarray(theta, float)), np.atleast_1d(np.asarray(theta_t, float))
    unknown = np.where(fixed.self_locking, np.nan, fixed.x[:, -1])  # drive torque or acceleration
    if torque_in is None:
        accel, drive = np.broadcast_to(np.asarray(theta_tt, float), theta.shape) + 0.0, unknown
    else:
        accel, drive = unknown, np.where(fixed.self_locking, np.nan, np.broadcast_to(torque_in, theta.shape))
    load = constant_load(scene) if load_torque is None else load_torque
    return solution_columns(motion, fixed, friction_slots(scene), (theta, theta_t, accel), drive, load,
                            mechanical_energy(scene, motion.bodies)), fixed


def solution_columns(motion: JointMotion, fixed: FixedPoint, slots: list[tuple[str, str]],
                     inputs: tuple[np.ndarray, np.ndarray, np.ndarray], drive: np.ndarray,
                     load: float | np.ndarray,
                     energy: tuple[np.ndarray, np.ndarray]) -> dict[str, np.ndarray]:
    """:func:`dynamics_columns`' columns from the solution: ``inputs`` the input angle [rad],
    speed [rad/s] and acceleration [rad/s^2], ``drive`` the drive torque [N m], ``load`` the
    output load [N m], ``energy`` the kinetic and potential energy [J], all per sample (n,)."""
    (theta, theta_t, accel), locked = inputs, fixed.self_locking
    x = np.where(locked[:, None], np.nan, fixed.x)
    phi = np.where(locked[:, None], np.nan, fixed.friction)
    theta_out, omega_out, _ = motion.output
    zero = np.zeros_like(theta_out)
    cols = {"theta_in": theta + zero, "theta_out": theta_out, "omega_in": theta_t + zero,
            "omega_out": omega_out, "torque_in": drive + zero, "torque_out": zero + load}
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * omega_out
    cols["energy_kinetic"], cols["energy_potential"] = energy
    applied = {(pair, kind): phi[:, j] for j, (pair, kind) in enumerate(slots)}
    loss_total = zero.copy()
    for pair in PAIR_NAMES:
        torque = applied.get((pair, "torque"), zero)
        force = applied.get((pair, "force"), zero)
        omega_rel, slide_rel = motion.omega_rel[pair] + zero, motion.slide_rel[pair] + zero
        rotation = pair_power_loss(torque, zero, omega_rel, zero)
        sliding = pair_power_loss(zero, force, zero, slide_rel)
        loss_total = loss_total + rotation + sliding
        cols[f"power_loss_{pair}"] = rotation + sliding
        cols[f"power_loss_{pair}_rotation"] = rotation
        cols[f"power_loss_{pair}_sliding"] = sliding
        cols.update({f"{pair}_{suffix}": zero for suffix in PAIR_SUFFIXES})
        cols[f"{pair}_friction_torque"] = torque + zero
        cols[f"{pair}_friction_force"] = force + zero
        cols[f"{pair}_omega_rel"] = omega_rel
        cols[f"{pair}_slide_rel"] = slide_rel
        cols[f"{pair}_slide"] = motion.slide[pair] + zero
    for j, (pair, component) in enumerate(unknowns()[:-1]):
        cols[f"{pair}_{component}"] = x[:, j]
    cols["power_loss"] = loss_total
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], loss_total)
    cols["input_acceleration"], cols["friction_loop_gain"] = accel, fixed.loop_gain
    cols["self_locking"] = locked
    return cols


def inverse_dynamics(scene: Scene, theta: np.ndarray, theta_t: np.ndarray,
                     theta_tt: np.ndarray) -> dict[str, np.ndarray]:
    """Result-schema columns (without ``t``) for a prescribed input motion, with friction.

    Parameters
    ----------
    scene : Scene
        Joint, load, gravity and friction (the drive is replaced by the given motion).
    theta, theta_t, theta_tt : ndarray, shape (n,)
        Input angle [rad], speed [rad/s] and acceleration [rad/s^2].
    """
    return dynamics_columns(scene, theta, theta_t, theta_tt=theta_tt)[0]
