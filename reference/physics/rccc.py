"""The Cardan joint as an RCCC loop, solved in dual numbers from Denavit-Hartenberg parameters.

The four joints, in chain order, are the pairs of :data:`reference.scene.joint.PAIR_NAMES`: joint 1
``frame_input`` (revolute), 2 ``input_spider``, 3 ``spider_output``, 4 ``output_frame``
(cylindrical). Link k carries joints k and k + 1 (joint 5 is joint 1): link 1 is the input,
2 the spider, 3 the output and 4 the frame (ground), so joint k joins link k - 1 (body ``a`` of
the pair) to link k (body ``b``).

Denavit-Hartenberg convention
-----------------------------
Frame ``F_k`` has its z axis on joint k, its x axis on the common normal of link k - 1 (from
joint k - 1 towards joint k) and its origin at that normal's foot on joint k. With the dual angles
``theta_hat_k = theta_k + eps s_k`` (joint rotation [rad] and slide [m]) and
``alpha_hat_k = alpha_k + eps a_k`` (link twist [rad] and offset [m], about and along link k's
common normal),

    F_{k+1} = F_k Z(theta_hat_k) X(alpha_hat_k),   prod_{k=1..4} Z(theta_hat_k) X(alpha_hat_k) = I.

``theta_k`` is the rotation of link k relative to link k - 1 about joint k, i.e. of body ``b``
relative to body ``a`` about the pair axis, and ``s_k`` the distance along joint k from the foot of
link k - 1's normal to the foot of link k's. ``F_k Z(theta_hat_k)`` is link k's own frame.

Placement in the scene (:mod:`reference.physics.kinematics`)
----------------------------------------------------
``F_1`` is fixed to the ground: its z axis (joint 1) is global x, its x axis (the frame link's
common normal) global z, its origin the global origin. The ideal joint with shaft angle ``b``
(:meth:`DHParameters.ideal`) has all ``a_k = 0``, ``s_1 = 0`` and twists
``(90, 90, 90, -b)`` deg. At ``theta_1 = 0`` the joint axes are then global x, y, z and
``a2 = (cos b, sin b, 0)``, exactly the pair axes of :mod:`reference.physics.kinematics` at input angle
0, and ``theta_1`` is that module's input angle.

Assembly branches and continuity
--------------------------------
The real part of the loop is a spherical four-bar whose input-output equation has two roots
(:mod:`reference.physics.loop_closure`, which solves it). Branch ``"hooke"`` takes the minus sign: for
the ideal joint it is the project's configuration (``theta_4 = 90 deg`` at ``theta_1 = 0``), and
under mounting errors it continues it as long as the discriminant stays positive. ``"flipped"``
is the other assembly (for the ideal joint: the spider turned by half a turn about the input yoke
and the output about its axis, with the same motion relative to ``theta_1 = 0``).

Joint angles are reported continuous in ``theta_1``, independently of the sampling: each is its
value at ``theta_1 = 0`` on the same branch, plus ``w_k theta_1`` with windings
``w = (1, 0, 0, -1)`` (input and output turn once per input turn, the spider stays near both),
plus the deviation from that wrapped into (-pi, pi]. Assumption: the deviation stays within
+-pi, true for any Cardan joint (it is at most about the shaft angle) and for mounting errors that
keep the loop a double crank. The loop must close at ``theta_1 = 0``.

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation", section 3.2, eqs. (10)-(14), Figure 3 (RCCC model and its parameters).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from reference.physics import dual
from reference.physics.dual import Dual
from reference.scene.joint import PAIR_NAMES, Geometry, Joint
from reference.physics.loop_closure import E_Z, LoopClosureError, angle_listing, solve_wrapped

LINK_NAMES = ("input", "spider", "output", "ground")
BRANCHES = ("hooke", "flipped")
_BRANCH_SIGN = {"hooke": -1.0, "flipped": 1.0}
_WINDING = np.array([1.0, 0.0, 0.0, -1.0])
# Global components of F_1's axes (columns): x_F1 = e_z, y_F1 = -e_y, z_F1 = e_x.
_GLOBAL_FROM_F1 = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
# Canonical body axes (reference.scene.joint) in the link's own D-H frame F_k Z(theta_hat_k), chosen so
# that both coincide for the ideal joint: input (z_F, -y_F, x_F), spider (x_F, z_F, -y_F),
# output (-y_F, x_F, z_F).
_CANONICAL_IN_LINK = {
    "input": _GLOBAL_FROM_F1.T,
    "spider": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
    "output": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
}


def _finite(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"`{name}` must be a number, got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"`{name}` must be finite, got {value!r}")
    return float(value)


def _four(name: str, values) -> tuple[float, float, float, float]:
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)) \
            or len(values) != 4:
        raise ValueError(f"`{name}` must be a sequence of 4 numbers (one per link), got {values!r}")
    return tuple(_finite(f"{name}[{k}]", v) for k, v in enumerate(values))


@dataclass(frozen=True)
class DHParameters:
    """Denavit-Hartenberg parameters of the single RCCC loop.

    Attributes
    ----------
    alpha : tuple of 4 float
        Twists of the input, spider, output and frame links [rad]: the angle from joint k's axis
        to joint k + 1's about link k's common normal. The first three in (0, 180) deg, the frame
        link's (minus the shaft angle) in (-90, 90) deg.
    a : tuple of 4 float
        Offsets of the same links [m]: the signed length of each common normal.
    s1 : float
        Axial offset of the revolute joint 1 [m]: from the frame link's normal to the input's.
    """

    alpha: tuple[float, float, float, float]
    a: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    s1: float = 0.0

    def __post_init__(self) -> None:
        alpha = _four("alpha", self.alpha)
        for k in range(3):
            if not 0.0 < alpha[k] < math.pi:
                raise ValueError(f"`alpha[{k}]` (twist of the {LINK_NAMES[k]}) must be in (0, 180) "
                                 f"deg, got {math.degrees(alpha[k])!r} deg")
        if not abs(alpha[3]) < 0.5 * math.pi:
            raise ValueError(f"`alpha[3]` (twist of the ground, minus the shaft angle) must be in "
                             f"(-90, 90) deg, got {math.degrees(alpha[3])!r} deg")
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "a", _four("a", self.a))
        object.__setattr__(self, "s1", _finite("s1", self.s1))

    @classmethod
    def ideal(cls, shaft_angle: float) -> DHParameters:
        """The ideal Cardan joint: twists (90, 90, 90, -shaft_angle) deg, no offsets.

        Parameters
        ----------
        shaft_angle : float
            Angle between the input and output shafts [rad], in [0, pi/2).
        """
        beta = _finite("shaft_angle", shaft_angle)
        if not 0.0 <= beta < 0.5 * math.pi:
            raise ValueError(f"`shaft_angle` must be in [0, 90) deg, got {math.degrees(beta)!r} deg")
        return cls(alpha=(0.5 * math.pi, 0.5 * math.pi, 0.5 * math.pi, -beta))

    def with_errors(self, a: Sequence[float] = (0.0,) * 4, alpha: Sequence[float] = (0.0,) * 4,
                    s1: float = 0.0) -> DHParameters:
        """These parameters with errors added: offsets ``a`` [m], twists ``alpha`` [rad], ``s1`` [m]."""
        d_a, d_alpha, d_s1 = _four("a", a), _four("alpha", alpha), _finite("s1", s1)
        return DHParameters(alpha=tuple(x + y for x, y in zip(self.alpha, d_alpha, strict=True)),
                            a=tuple(x + y for x, y in zip(self.a, d_a, strict=True)), s1=self.s1 + d_s1)

    @classmethod
    def of_joint(cls, joint: Joint) -> DHParameters:
        """The scene joint's loop: the ideal joint of its shaft angle plus its mounting errors."""
        e = joint.errors
        return cls.ideal(joint.geometry.shaft_angle).with_errors(
            a=(e.a1, e.a2, e.a3, e.a4), alpha=(e.alpha1, e.alpha2, e.alpha3, e.alpha4), s1=e.s1)

    def twists(self) -> Dual:
        """Dual link twists ``alpha_k + eps a_k``, shape (4,)."""
        return Dual(np.array(self.alpha), np.array(self.a))


@dataclass(frozen=True)
class LoopPositions:
    """Solved configuration of the loop for an array of input angles.

    Attributes
    ----------
    theta : ndarray, shape (..., 4)
        Joint angles ``theta_1..theta_4`` [rad], continuous in ``theta_1``.
    s : ndarray, shape (..., 4)
        Joint slides ``s_1..s_4`` [m]; ``s_1`` is the constant parameter.
    reference : ndarray, shape (4,) or (..., 4)
        Joint angles at ``theta_1 = 0`` on the same branch [rad].
    branch : str
        One of :data:`BRANCHES`.
    reference_slide : ndarray, shape (..., 4), or None
        Joint slides at ``theta_1 = 0`` [m] when given with the positions (many parameter sets
        in one array, :mod:`reference.engine.batch.solve`); None: solved from the parameters when needed.
    """

    theta: np.ndarray
    s: np.ndarray
    reference: np.ndarray
    branch: str
    reference_slide: np.ndarray | None = None

    def dual_angles(self) -> Dual:
        """``theta_k + eps s_k``, shape (..., 4)."""
        return Dual(self.theta, self.s)


@dataclass(frozen=True)
class LoopRates:
    """First and second time derivatives of the joint variables, shape (..., 4) each.

    Attributes
    ----------
    theta_t, theta_tt : ndarray
        Joint angular speeds [rad/s] and accelerations [rad/s^2].
    s_t, s_tt : ndarray
        Joint sliding speeds [m/s] and accelerations [m/s^2] (zero for joint 1).
    """

    theta_t: np.ndarray
    s_t: np.ndarray
    theta_tt: np.ndarray
    s_tt: np.ndarray


@dataclass(frozen=True)
class BodyPose:
    """Canonical body frame (:mod:`reference.scene.joint`) of one link, global components.

    Attributes
    ----------
    rotation : ndarray, shape (..., 3, 3)
        Columns: the body's canonical axes [-].
    origin : ndarray, shape (..., 3)
        The link's D-H frame origin: the foot of its common normal on its first joint [m]
        (the joint centre for the ideal joint; the global origin for the ground).
    """

    rotation: np.ndarray
    origin: np.ndarray


@dataclass(frozen=True)
class BodyMotion:
    """Pose and motion of one link, global components.

    Attributes
    ----------
    rotation, origin : ndarray
        As :class:`BodyPose` [-], [m].
    omega, alpha : ndarray, shape (..., 3)
        Angular velocity [rad/s] and acceleration [rad/s^2].
    velocity, acceleration : ndarray, shape (..., 3)
        Velocity [m/s] and acceleration [m/s^2] of the body point at ``origin``.
    """

    rotation: np.ndarray
    origin: np.ndarray
    omega: np.ndarray
    velocity: np.ndarray
    alpha: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class PairMotion:
    """Motion of body ``b`` relative to body ``a`` along and about one pair's axis.

    Attributes
    ----------
    angle, speed, acceleration : ndarray
        Rotation since ``theta_1 = 0`` [rad], its speed [rad/s] and acceleration [rad/s^2].
    slide, slide_speed, slide_acceleration : ndarray
        Joint slide ``s_k`` [m] and its rates [m/s], [m/s^2] (constant for the revolute pair).
    """

    angle: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    slide: np.ndarray
    slide_speed: np.ndarray
    slide_acceleration: np.ndarray


def _samples(name: str, value, shape: tuple[int, ...] | None = None) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a numeric array, got {value!r}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"`{name}` must be finite, got {value!r}")
    if shape is None:
        return arr
    try:
        return np.broadcast_to(arr, shape)
    except ValueError:
        raise ValueError(f"`{name}` must broadcast to the shape {shape} of the solved input angles, "
                         f"got shape {arr.shape}") from None


def _solve(params: DHParameters, theta1: np.ndarray, branch: str, where: str) -> Dual:
    """:func:`reference.physics.loop_closure.solve_wrapped` for ``params`` on ``branch``."""
    return solve_wrapped(params.twists(), params.s1, theta1, _BRANCH_SIGN[branch], where)


@functools.lru_cache(maxsize=256)
def _at_zero(params: DHParameters, branch: str) -> tuple[np.ndarray, np.ndarray]:
    """Joint angles (4,) [rad] and slides (4,) [m] at ``theta_1 = 0`` on a branch (cached).

    Every solve and every pair-frame evaluation of a parameter set needs them; solved once.
    """
    angles = _solve(params, np.zeros(1), branch, "the reference input angle")
    theta, slide = angles.re[0].copy(), angles.du[0].copy()
    theta.flags.writeable = slide.flags.writeable = False  # shared by every caller
    return theta, slide


WINDING_SAMPLES = 1440
"""Input angles per turn at which :func:`solve_positions` checks the windings (0.25 deg apart)."""


@functools.lru_cache(maxsize=256)
def _check_windings(params: DHParameters, branch: str) -> None:
    """Raise unless every joint angle turns as the Cardan joint's do over one input turn.

    The continuity rule of the module docstring assumes that the spider stays near both shafts
    and the output turns once per input turn (windings ``(1, 0, 0, -1)``). Large twist errors
    can make the spherical loop a crank-rocker (e.g. an input twist below the shaft angle): the
    loop still closes, but a joint angle then jumps by a full turn between neighbouring input
    angles. Checked once per parameter set on a fine grid.
    """
    theta1 = np.linspace(0.0, 2.0 * np.pi, WINDING_SAMPLES + 1)
    try:
        reference = _at_zero(params, branch)[0]
        raw = _solve(params, theta1, branch, "input angles").re
    except LoopClosureError:  # reported by the caller's own solve, at the caller's angles
        return
    jumps = winding_jumps(raw, reference, theta1)
    if np.any(jumps):
        at = theta1[1:][np.any(jumps, -1)]
        raise LoopClosureError(
            "with these mounting errors the loop is not a Cardan joint's double crank: a joint "
            "angle does not follow the input turn for turn (it jumps by a full turn near input "
            f"angle(s) {angle_listing(at)})", at)


def winding_jumps(raw: np.ndarray, reference: np.ndarray, theta1: np.ndarray) -> np.ndarray:
    """Joint angles jumping a quarter turn or more between neighbours against the Cardan joint's
    windings, (..., m - 1, 3): ``raw`` (..., m, 4) the wrapped loop solution at the input angles
    ``theta1`` (m,) [rad], ``reference`` (..., 4) its value at 0 (any True: not a double crank)."""
    nominal = reference[..., None, :] + _WINDING * theta1[:, None]
    deviation = np.remainder(raw - nominal + np.pi, 2.0 * np.pi) - np.pi
    return np.abs(np.diff(deviation[..., 1:], axis=-2)) > 0.5 * np.pi


def solve_positions(params: DHParameters, theta1: ArrayLike, branch: str = "hooke") -> LoopPositions:
    """Joint angles and slides closing the loop for given input angles.

    Parameters
    ----------
    params : DHParameters
        The loop.
    theta1 : array_like
        Input angles ``theta_1`` [rad], any shape.
    branch : {"hooke", "flipped"}
        Assembly branch (module docstring).

    Returns
    -------
    LoopPositions

    Raises
    ------
    LoopClosureError
        If the loop cannot close, or its branches meet, at some input angle or at 0.
    """
    if branch not in BRANCHES:
        raise ValueError(f"`branch` must be one of {list(BRANCHES)}, got {branch!r}")
    theta1 = _samples("theta1", theta1)
    _check_windings(params, branch)
    reference = _at_zero(params, branch)[0]
    raw = _solve(params, theta1, branch, "input angles")
    return LoopPositions(theta=continuous_angles(raw.re, reference, theta1), s=raw.du,
                         reference=reference, branch=branch)


def continuous_angles(wrapped: np.ndarray, reference: np.ndarray, theta1: np.ndarray) -> np.ndarray:
    """Joint angles continuous in ``theta_1`` (module docstring), shape (..., 4) [rad].

    ``wrapped`` (..., 4): the loop's solution in (-pi, pi]; ``reference`` (4,) or (..., 4): its
    value at ``theta_1 = 0`` on the same branch; ``theta1`` (...): the input angles [rad].
    """
    nominal = reference + _WINDING * theta1[..., None]
    theta = nominal + np.remainder(wrapped - nominal + np.pi, 2.0 * np.pi) - np.pi
    theta[..., 0] = theta1
    return theta


def _joint_frames(params: DHParameters, positions: LoopPositions) -> Dual:
    """``F_1..F_4`` as dual matrices in global components, shape (..., 4, 3, 3); kept with the
    positions (frozen) for these parameters, since rates, poses and pair frames all need them."""
    cached = positions.__dict__.get("_frames")
    if cached is not None and cached[0] is params:
        return cached[1]
    steps = dual.screw_transform(positions.dual_angles(), params.twists())
    frame = Dual(np.broadcast_to(_GLOBAL_FROM_F1, steps.shape[:-3] + (3, 3)))
    frames = [frame]
    for k in range(3):
        frame = frame @ steps[..., k, :, :]
        frames.append(frame)
    out = dual.stack(frames, -3)
    object.__setattr__(positions, "_frames", (params, out))
    return out


def joint_frames(params: DHParameters, positions: LoopPositions) -> tuple[np.ndarray, np.ndarray]:
    """The D-H frames ``F_1..F_4``: rotations (..., 4, 3, 3) [-] and origins (..., 4, 3) [m].

    ``F_k`` is fixed in link k - 1, body ``a`` of joint k; its z axis is the joint axis.
    """
    return dual.displacement(_joint_frames(params, positions))


# Each pair's frame of reference.physics.kinematics.pair_frames in its D-H frame F_k (checked by the tests):
# F_1 turned by -90 deg about its z axis (the pair's x is global y at input angle 0), the rest F_k.
_PAIR_IN_F = np.stack([np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
                       np.eye(3), np.eye(3), np.eye(3)])


def axial_positions(geometry: Geometry) -> tuple[float, float, float, float]:
    """Where each pair's bearing sits along its axis from the D-H frame origin [m].

    The frame bearings at ``-input_bearing`` (input axis, towards the input) and
    ``+output_bearing`` (output axis); the spider pairs at the foot of the common normal.
    """
    return (-geometry.input_bearing, 0.0, 0.0, geometry.output_bearing)


def pair_frames(params: DHParameters, positions: LoopPositions,
                axial: Sequence[float] = (0.0,) * 4) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each pair's frame (global components) and origin, the point reactions are taken about.

    The frame is the D-H frame ``F_k`` of the pair's joint, fixed in body ``a``, with the axes of
    :func:`reference.physics.kinematics.pair_frames` (z the pair axis). The origin is the point of body
    ``b`` on the axis that sits ``axial[k]`` from ``F_k``'s origin at input angle 0
    (:func:`axial_positions`; or one row per sample, shape (..., 4)); when the pair slides it
    moves along the axis with body ``b``.
    Body ``b`` carries the bearing of the ``spider_output`` (output yoke) and ``output_frame``
    (frame) pairs; it is also the point Exudyn's joint reactions refer to.

    Returns
    -------
    dict of str to (rotation (..., 3, 3) [-], origin (..., 3) [m])
    """
    rotation, origin = joint_frames(params, positions)
    axial = np.asarray(axial, float) if np.ndim(axial) > 1 else np.asarray(_four("axial", axial))
    start = (_at_zero(params, positions.branch)[1] if positions.reference_slide is None
             else positions.reference_slide)
    frames = rotation @ _PAIR_IN_F
    origins = origin + (axial + positions.s - start)[..., None] * rotation[..., :, 2]
    return {p: (frames[..., k, :, :], origins[..., k, :]) for k, p in enumerate(PAIR_NAMES)}


def joint_screws(params: DHParameters, positions: LoopPositions) -> Dual:
    """Joint axes as unit lines ``u + eps (p x u)`` in global components, shape (..., 4, 3).

    The direction is each pair's z axis of :func:`reference.physics.kinematics.pair_frames` [-]; the
    moment is about the global origin [m].
    """
    return dual.matvec(_joint_frames(params, positions), E_Z)


def pair_axes(params: DHParameters, positions: LoopPositions) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each pair's axis: unit direction [-] and its point closest to the origin [m], (..., 3) each."""
    screws = joint_screws(params, positions)
    return {p: (screws.re[..., k, :], dual.line_point(screws[..., k, :]))
            for k, p in enumerate(PAIR_NAMES)}


def body_poses(params: DHParameters, positions: LoopPositions) -> dict[str, BodyPose]:
    """Canonical frames of ``ground``, ``input``, ``spider`` and ``output`` (global components).

    For the ideal joint these are the rotations of :func:`reference.physics.kinematics.body_motions`
    and all origins are the joint centre.
    """
    links = _joint_frames(params, positions) @ dual.rot_z(positions.dual_angles())
    rotation, origin = dual.displacement(links)
    shape = positions.theta.shape[:-1]
    poses = {"ground": BodyPose(np.broadcast_to(np.eye(3), shape + (3, 3)), np.zeros(shape + (3,)))}
    for k, name in enumerate(LINK_NAMES[:3]):
        poses[name] = BodyPose(rotation[..., k, :, :] @ _CANONICAL_IN_LINK[name], origin[..., k, :])
    return poses


def _with_input(first: np.ndarray, rest: Dual) -> Dual:
    """Prepend the (slide-free) joint 1 value to dual values of joints 2..4, shape (..., 4)."""
    return Dual(np.concatenate([first[..., None], rest.re], -1),
                np.concatenate([np.zeros_like(first)[..., None], rest.du], -1))


def _screw_rates(screws: Dual, joint_rates: Dual) -> Dual:
    """``dS_k/dt = V_k x S_k``, ``V_k`` the velocity screw of link k (``V_k x S_k = V_{k-1} x S_k``)."""
    return dual.cross((joint_rates[..., None] * screws).cumsum(-2), screws)


def solve_rates(params: DHParameters, positions: LoopPositions, theta1_t: ArrayLike,
                theta1_tt: ArrayLike) -> LoopRates:
    """Joint speeds and accelerations for a given input motion (analytic, no differencing).

    The relative velocity screws close the loop, ``sum_k (theta_k_t + eps s_k_t) S_k = 0``, six
    linear equations for the rates of joints 2..4; differentiated once more with
    ``dS_k/dt = V_k x S_k`` they give the accelerations with the same matrix.

    Parameters
    ----------
    params : DHParameters
        The loop.
    positions : LoopPositions
        From :func:`solve_positions` for the same ``params``.
    theta1_t, theta1_tt : array_like
        Input speed [rad/s] and acceleration [rad/s^2], broadcastable to the input angles' shape.

    Returns
    -------
    LoopRates
    """
    shape = positions.theta.shape[:-1]
    theta1_t = _samples("theta1_t", theta1_t, shape)
    theta1_tt = _samples("theta1_tt", theta1_tt, shape)
    screws = joint_screws(params, positions)
    matrix = screws[..., 1:, :].T
    rates = _with_input(theta1_t, dual.solve(matrix, -(theta1_t[..., None] * screws[..., 0, :])))
    drift = (rates[..., None] * _screw_rates(screws, rates)).sum(-2)
    accels = _with_input(theta1_tt,
                         dual.solve(matrix, -(theta1_tt[..., None] * screws[..., 0, :] + drift)))
    return LoopRates(theta_t=rates.re, s_t=rates.du, theta_tt=accels.re, s_tt=accels.du)


def solve_motion(params: DHParameters, theta1: ArrayLike, theta1_t: ArrayLike, theta1_tt: ArrayLike,
                 branch: str = "hooke") -> tuple[LoopPositions, LoopRates]:
    """:func:`solve_positions` and :func:`solve_rates` in one call (same arguments)."""
    positions = solve_positions(params, theta1, branch)
    return positions, solve_rates(params, positions, theta1_t, theta1_tt)


def body_motions(params: DHParameters, positions: LoopPositions,
                 rates: LoopRates) -> dict[str, BodyMotion]:
    """Pose, velocity and acceleration of ``ground``, ``input``, ``spider`` and ``output``.

    Link k's velocity screw is ``V_k = sum_{j<=k} (theta_j_t + eps s_j_t) S_j``; its real part is
    the angular velocity, its dual part the velocity of the body point at the global origin.
    """
    screws = joint_screws(params, positions)
    joint_rates, joint_accels = Dual(rates.theta_t, rates.s_t), Dual(rates.theta_tt, rates.s_tt)
    twist = (joint_rates[..., None] * screws).cumsum(-2)
    twist_t = (joint_accels[..., None] * screws
               + joint_rates[..., None] * _screw_rates(screws, joint_rates)).cumsum(-2)
    poses = body_poses(params, positions)
    zero = np.zeros(positions.theta.shape[:-1] + (3,))
    out = {"ground": BodyMotion(poses["ground"].rotation, zero, zero, zero, zero, zero)}
    for k, name in enumerate(LINK_NAMES[:3]):
        p = poses[name].origin
        omega, alpha = twist.re[..., k, :], twist_t.re[..., k, :]
        velocity = twist.du[..., k, :] + np.cross(omega, p)
        acceleration = twist_t.du[..., k, :] + np.cross(alpha, p) + np.cross(omega, velocity)
        out[name] = BodyMotion(poses[name].rotation, p, omega, velocity, alpha, acceleration)
    return out


def pair_motions(positions: LoopPositions, rates: LoopRates) -> dict[str, PairMotion]:
    """Relative rotation (b relative to a, about the pair axis, from ``theta_1 = 0``) and slide."""
    angle = positions.theta - positions.reference
    return {p: PairMotion(angle[..., k], rates.theta_t[..., k], rates.theta_tt[..., k],
                          positions.s[..., k], rates.s_t[..., k], rates.s_tt[..., k])
            for k, p in enumerate(PAIR_NAMES)}


def output_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Output shaft angle [rad], speed [rad/s], acceleration [rad/s^2] about its own axis.

    Measured like :func:`reference.physics.kinematics.output_angle`: from the output's position at
    ``theta_1 = 0``; it is minus the ``output_frame`` pair's rotation (ground relative to output).
    """
    pair = pair_motions(positions, rates)["output_frame"]
    return -pair.angle, -pair.speed, -pair.acceleration


def spider_motion(positions: LoopPositions,
                  rates: LoopRates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spider angle ``gamma`` relative to the input about the input yoke [rad] and its rates.

    The ``input_spider`` pair's rotation, as :func:`reference.physics.kinematics.spider_motion`.
    """
    pair = pair_motions(positions, rates)["input_spider"]
    return pair.angle, pair.speed, pair.acceleration


def loop_closure_residual(params: DHParameters, positions: LoopPositions) -> tuple[float, float]:
    """Largest deviation of ``prod_k Z(theta_hat_k) X(alpha_hat_k)`` from the identity.

    Returns
    -------
    real : float
        Max abs entry of the real part minus the identity, over all samples [-].
    dual : float
        Max abs entry of the dual part [m].
    """
    steps = dual.screw_transform(positions.dual_angles(), params.twists())
    loop = steps[..., 0, :, :] @ steps[..., 1, :, :] @ steps[..., 2, :, :] @ steps[..., 3, :, :]
    return float(np.max(np.abs(loop.re - np.eye(3)), initial=0.0)), \
        float(np.max(np.abs(loop.du), initial=0.0))
