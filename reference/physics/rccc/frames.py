"""Frames of the solved RCCC loop: the D-H frames, the pair frames and axes, the bodies' poses."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from reference.physics import dual
from reference.physics.dual import Dual
from reference.physics.loop_closure import E_Z
from reference.physics.rccc.parameters import LINK_NAMES, DHParameters, four_numbers
from reference.physics.rccc.positions import LoopPositions, at_zero
from reference.scene.joint import PAIR_NAMES, Geometry

__all__ = ["BodyPose", "axial_positions", "body_poses", "joint_frames", "joint_screws", "pair_axes",
           "pair_frames"]

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



@dataclass(frozen=True)
class BodyPose:
    """Canonical body frame of one link, global components: ``rotation`` (..., 3, 3) (columns: the
    canonical axes [-]) and ``origin`` (..., 3) [m], the foot of its common normal on its first joint.
    """

    rotation: np.ndarray
    origin: np.ndarray



def _joint_frames(params: DHParameters, positions: LoopPositions) -> Dual:
    """``F_1..F_4`` as dual matrices (..., 4, 3, 3), global; cached with the (frozen) positions, since
    rates, poses and pair frames all need them.
    """
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
    """The D-H frames ``F_1..F_4`` of ``params`` at its solved ``positions``: axes (..., 4, 3, 3) [-] and
    origins (..., 4, 3) [m]; ``F_k`` is fixed in link k - 1 (body ``a`` of joint k), z on the joint axis.
    """
    return dual.displacement(_joint_frames(params, positions))


# Each pair's frame of reference.physics.kinematics.pair_frames in its D-H frame F_k (checked by the tests):
# F_1 turned by -90 deg about its z axis (the pair's x is global y at input angle 0), the rest F_k.
_PAIR_IN_F = np.stack([np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
                       np.eye(3), np.eye(3), np.eye(3)])


def axial_positions(geometry: Geometry) -> tuple[float, float, float, float]:
    """Each pair's bearing position [m] along its axis from the D-H frame origin: the frame bearings at
    ``-input_bearing`` and ``+output_bearing`` of ``geometry``, the spider pairs at 0.
    """
    return (-geometry.input_bearing, 0.0, 0.0, geometry.output_bearing)


def pair_frames(params: DHParameters, positions: LoopPositions,
                axial: Sequence[float] = (0.0,) * 4) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per pair ``(rotation (..., 3, 3) [-], origin (..., 3) [m])``, global: the pair's D-H frame (fixed
    in body ``a``, axes of :func:`reference.physics.kinematics.pair_frames`) and the point of body ``b``
    ``axial[k]`` [m] along the axis from its origin at input angle 0 (moving with ``b`` when the pair
    slides); the point reactions are taken about, as Exudyn's.
    """
    rotation, origin = joint_frames(params, positions)
    axial = np.asarray(axial, float) if np.ndim(axial) > 1 else np.asarray(four_numbers("axial", axial))
    start = (at_zero(params, positions.branch)[1] if positions.reference_slide is None
             else positions.reference_slide)
    frames = rotation @ _PAIR_IN_F
    origins = origin + (axial + positions.s - start)[..., None] * rotation[..., :, 2]
    return {p: (frames[..., k, :, :], origins[..., k, :]) for k, p in enumerate(PAIR_NAMES)}


def joint_screws(params: DHParameters, positions: LoopPositions) -> Dual:
    """Joint axes as unit lines ``u + eps (p x u)`` (..., 4, 3), global: the pair z axes [-], moments
    about the origin [m].
    """
    return dual.matvec(_joint_frames(params, positions), E_Z)


def pair_axes(params: DHParameters, positions: LoopPositions) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per pair the unit axis direction [-] and its point closest to the origin [m], (..., 3) each."""
    screws = joint_screws(params, positions)
    return {p: (screws.re[..., k, :], dual.line_point(screws[..., k, :]))
            for k, p in enumerate(PAIR_NAMES)}


def body_poses(params: DHParameters, positions: LoopPositions) -> dict[str, BodyPose]:
    """:class:`BodyPose` of ``ground``, ``input``, ``spider``, ``output`` at the solved ``positions``
    (for the ideal joint, :func:`reference.physics.kinematics.body_motions`' rotations at the joint centre).
    """
    links = _joint_frames(params, positions) @ dual.rot_z(positions.dual_angles())
    rotation, origin = dual.displacement(links)
    shape = positions.theta.shape[:-1]
    poses = {"ground": BodyPose(np.broadcast_to(np.eye(3), shape + (3, 3)), np.zeros(shape + (3,)))}
    for k, name in enumerate(LINK_NAMES[:3]):
        poses[name] = BodyPose(rotation[..., k, :, :] @ _CANONICAL_IN_LINK[name], origin[..., k, :])
    return poses
