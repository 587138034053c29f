"""Every body's and pair's motion for a given input motion: what the dynamics need from kinematics.

Two sources give the same :class:`JointMotion`:

- the ideal joint (no mounting errors): the closed form of :mod:`reference.physics.kinematics`; every
  body turns about the joint centre O and no pair slides;
- a joint with mounting errors (:class:`reference.scene.joint.MountingErrors`): the dual-number RCCC
  loop of :mod:`reference.physics.rccc` from the Denavit-Hartenberg parameters. The bodies' frames
  translate, the pair axes do not meet, and the cylindrical pairs slide.

``method="auto"`` takes the closed form when the joint is ideal (it is exact there and cheaper)
and the loop otherwise; ``"loop"`` forces the loop, which for the ideal joint agrees with the
closed form to rounding (a test checks it, reactions included).

Conventions shared by both: a body's mass properties (:meth:`reference.scene.joint.Body.canonical`) are
given in its canonical frame, whose origin is the body's D-H link-frame origin (the joint centre O
for the ideal joint). Each pair's frame is attached to body ``a`` of the pair
(:data:`reference.scene.joint.PAIR_BODIES`), z along the pair axis; its origin, the point about
which reaction moments are taken, is where the bearing sits
(:func:`reference.physics.rccc.frames.axial_positions`) and moves with body ``b`` when the pair
slides (:func:`reference.physics.rccc.frames.pair_frames`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from reference.physics import kinematics, rccc
from reference.scene.joint import PAIR_NAMES, Geometry, Joint

__all__ = ["METHODS", "JointMotion", "ideal_pair_origins", "loop_motion", "joint_motion"]

METHODS = ("auto", "closed_form", "loop")


@dataclass(frozen=True)
class JointMotion:
    """Motion of the joint at a batch of samples (global components, arrays of shape (..., ...)).

    Attributes
    ----------
    bodies : dict of str to reference.physics.rccc.motion.BodyMotion
        ``ground``, ``input``, ``spider``, ``output``: rotation (canonical axes), frame origin and
        its velocity and acceleration, angular velocity and acceleration.
    frames : dict of str to ndarray, shape (..., 3, 3)
        Pair frames attached to body a [-].
    origins : dict of str to ndarray, shape (..., 3)
        Pair origins [m].
    omega_rel : dict of str to ndarray
        Angular speed of body b relative to body a about the pair axis [rad/s].
    slide : dict of str to ndarray
        D-H slide of each joint [m] (constant ``s1`` for the revolute pair; 0 in the ideal joint).
    slide_rel : dict of str to ndarray
        Sliding speed of body b relative to body a along the pair axis [m/s].
    output : tuple of 3 ndarray
        Output shaft angle [rad], speed [rad/s], acceleration [rad/s^2] about its own axis.
    """

    bodies: dict[str, rccc.BodyMotion]
    frames: dict[str, np.ndarray]
    origins: dict[str, np.ndarray]
    omega_rel: dict[str, np.ndarray]
    slide: dict[str, np.ndarray]
    slide_rel: dict[str, np.ndarray]
    output: tuple[np.ndarray, np.ndarray, np.ndarray]


def ideal_pair_origins(geometry: Geometry) -> dict[str, np.ndarray]:
    """Pair origins of the ideal joint in global coordinates [m] (fixed in space)."""
    return {
        "frame_input": np.array([-geometry.input_bearing, 0.0, 0.0]),
        "input_spider": np.zeros(3),
        "spider_output": np.zeros(3),
        "output_frame": geometry.output_bearing * geometry.output_axis(),
    }


def _closed_form(joint: Joint, theta: np.ndarray, theta_t: np.ndarray,
                 theta_tt: np.ndarray) -> JointMotion:
    beta = joint.geometry.shaft_angle
    simple = kinematics.body_motions(theta, theta_t, theta_tt, beta)
    zero = np.zeros(theta.shape + (3,))
    bodies = {name: rccc.BodyMotion(m.rotation, zero, m.omega, zero, m.alpha, zero)
              for name, m in simple.items()}
    origins = {p: np.broadcast_to(o, zero.shape) for p, o in ideal_pair_origins(joint.geometry).items()}
    still = {p: np.zeros(theta.shape) for p in PAIR_NAMES}
    return JointMotion(bodies, kinematics.pair_frames(simple), origins,
                       kinematics.relative_speeds(simple), still, still,
                       kinematics.output_motion(theta, theta_t, theta_tt, beta))


def _loop(joint: Joint, theta: np.ndarray, theta_t: np.ndarray, theta_tt: np.ndarray) -> JointMotion:
    params = rccc.DHParameters.of_joint(joint)
    positions = rccc.solve_positions(params, theta)
    rates = rccc.solve_rates(params, positions, theta_t, theta_tt)
    return loop_motion(params, positions, rates, rccc.axial_positions(joint.geometry))


def loop_motion(params: rccc.DHParameters, positions: rccc.LoopPositions, rates: rccc.LoopRates,
                axial) -> JointMotion:
    """The joint's motion from the loop's solved positions and rates.

    Parameters
    ----------
    params : reference.physics.rccc.DHParameters
        The loop.
    positions : reference.physics.rccc.LoopPositions
        Its solved positions at the samples.
    rates : reference.physics.rccc.LoopRates
        Its solved rates there.
    axial : sequence of 4 float, or ndarray, shape (..., 4)
        The pairs' axial positions [m] (:func:`reference.physics.rccc.axial_positions`), one set
        or one per sample.

    Returns
    -------
    JointMotion
    """
    frames = rccc.pair_frames(params, positions, axial)
    return JointMotion(
        bodies=rccc.body_motions(params, positions, rates),
        frames={p: f for p, (f, _) in frames.items()},
        origins={p: o for p, (_, o) in frames.items()},
        omega_rel={p: rates.theta_t[..., k] for k, p in enumerate(PAIR_NAMES)},
        slide={p: positions.s[..., k] for k, p in enumerate(PAIR_NAMES)},
        slide_rel={p: rates.s_t[..., k] for k, p in enumerate(PAIR_NAMES)},
        output=rccc.output_motion(positions, rates),
    )


def joint_motion(joint: Joint, theta: ArrayLike, theta_t: ArrayLike, theta_tt: ArrayLike,
                 method: str = "auto") -> JointMotion:
    """The joint's motion for input angles, speeds and accelerations (broadcast together).

    Parameters
    ----------
    joint : Joint
        Geometry and mounting errors.
    theta, theta_t, theta_tt : array_like
        Input angle [rad], speed [rad/s], acceleration [rad/s^2].
    method : {"auto", "closed_form", "loop"}
        See the module documentation; ``"closed_form"`` refuses a joint with errors.

    Returns
    -------
    JointMotion
        Arrays of the broadcast shape of the inputs.

    Raises
    ------
    reference.physics.loop_closure.LoopClosureError
        The loop with these errors does not close at some input angle.
    """
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    theta, theta_t, theta_tt = np.broadcast_arrays(*(np.asarray(v, float)
                                                     for v in (theta, theta_t, theta_tt)))
    if method == "closed_form" and joint.errors.any:
        raise ValueError("the closed form describes the ideal joint only; this joint has mounting "
                         "errors (use method='loop' or 'auto')")
    if method == "loop" or (method == "auto" and joint.errors.any):
        return _loop(joint, theta, theta_t, theta_tt)
    return _closed_form(joint, theta, theta_t, theta_tt)
