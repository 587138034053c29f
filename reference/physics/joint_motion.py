"""Every body's and pair's motion for a given input motion: what the dynamics need from kinematics.

The ideal joint uses the closed form of :mod:`reference.physics.kinematics` (no pair slides); a
joint with mounting errors the dual-number RCCC loop of :mod:`reference.physics.rccc`. ``"auto"``
takes the closed form when ideal; ``"loop"`` agrees with it to rounding there. Mass properties are
in each body's canonical frame; each pair's frame is attached to its body ``a``, z on the axis, its
origin at the bearing (:func:`reference.physics.rccc.frames.pair_frames`), moving with body ``b``.
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
    """Motion of the joint at a batch of samples, global components: ``bodies`` (``ground``, ``input``,
    ``spider``, ``output``: :class:`BodyMotion`), pair ``frames`` (on body a) and ``origins`` [m],
    ``omega_rel`` [rad/s], ``slide`` [m], ``slide_rel`` [m/s] of b relative to a, and ``output``
    (angle [rad], speed, acceleration about its own axis).
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
    """:class:`JointMotion` from the loop ``params``' solved ``positions`` and ``rates`` with the pairs'
    ``axial`` positions [m] (:func:`reference.physics.rccc.axial_positions`; one set or one per sample).
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
    """:class:`JointMotion` of ``joint`` at input angles ``theta`` [rad], speeds ``theta_t`` [rad/s] and
    accelerations ``theta_tt`` [rad/s^2] (broadcast together) by ``method`` ``"auto"``, ``"closed_form"``
    (refuses mounting errors) or ``"loop"``; LoopClosureError where the loop does not close.
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
