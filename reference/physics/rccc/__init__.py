"""The Cardan joint as an RCCC loop, solved in dual numbers from Denavit-Hartenberg parameters.

Joints in chain order are the pairs of :data:`reference.scene.joint.PAIR_NAMES` (1 revolute, 2-4
cylindrical); link k carries joints k and k + 1 (1 input, 2 spider, 3 output, 4 frame), so joint k
joins link k - 1 (body ``a``) to link k (body ``b``).

Convention: ``F_k`` has z on joint k, x on link k - 1's common normal, origin at its foot; with
``theta_hat_k = theta_k + eps s_k`` and ``alpha_hat_k = alpha_k + eps a_k``,

    F_{k+1} = F_k Z(theta_hat_k) X(alpha_hat_k),   prod_{k=1..4} Z(theta_hat_k) X(alpha_hat_k) = I.

``F_1`` is fixed: z global x, x global z. The ideal joint (:meth:`DHParameters.ideal`) has all
``a_k = 0``, ``s_1 = 0``, twists ``(90, 90, 90, -b)`` deg, and ``theta_1`` is the input angle of
:mod:`reference.physics.kinematics`. Branch ``"hooke"`` takes the minus root of the four-bar
equation (the project's configuration), ``"flipped"`` the other. Joint angles are continuous in
``theta_1``: the value at 0 plus ``w_k theta_1`` (``w = (1, 0, 0, -1)``) plus a deviation wrapped
into (-pi, pi] (assumed within +-pi: a double crank). The loop must close at ``theta_1 = 0``.
References: the paper's section 3.2, eqs. (10)-(14), Figure 3.
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
