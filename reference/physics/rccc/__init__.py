"""The Cardan joint as an RCCC loop, solved in dual numbers from Denavit-Hartenberg parameters.

The four joints, in chain order, are the pairs of :data:`reference.scene.joint.PAIR_NAMES`: joint 1
``frame_input`` (revolute), 2 ``input_spider``, 3 ``spider_output``, 4 ``output_frame``
(cylindrical). Link k carries joints k and k + 1 (joint 5 is joint 1): link 1 is the input,
2 the spider, 3 the output and 4 the frame (ground), so joint k joins link k - 1 (body ``a`` of
the pair) to link k (body ``b``).

Modules: :mod:`~reference.physics.rccc.parameters` (the D-H parameters),
:mod:`~reference.physics.rccc.positions` (closing the loop), :mod:`~reference.physics.rccc.frames`
(frames, axes and poses of the solved loop), :mod:`~reference.physics.rccc.motion` (rates).

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

from reference.lazy import lazy_face

_HOMES = {
    "reference.physics.rccc.parameters": ("LINK_NAMES", "DHParameters"),
    "reference.physics.rccc.positions": ("BRANCHES", "WINDING_SAMPLES", "LoopPositions", "solve_positions",
                                         "winding_jumps", "continuous_angles", "loop_closure_residual"),
    "reference.physics.rccc.frames": ("BodyPose", "joint_frames", "axial_positions", "pair_frames",
                                      "joint_screws", "pair_axes", "body_poses"),
    "reference.physics.rccc.motion": ("LoopRates", "BodyMotion", "PairMotion", "solve_rates", "solve_motion",
                                      "body_motions", "pair_motions", "output_motion", "spider_motion"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
