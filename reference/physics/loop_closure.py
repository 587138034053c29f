"""Closing the RCCC loop at given input angles: its input-output equation in dual numbers.

The real part of ``prod_k Z(theta_hat_k) X(alpha_hat_k) = I`` is a spherical four-bar,
``A cos theta_4 + B sin theta_4 = C``, with roots ``atan2(B, A) -+ atan2(sqrt(A^2 + B^2 - C^2), C)``
(one per assembly branch); the dual part is linear in ``s_4``; joints 2 and 3 follow as the angles
turning known lines onto their axes. A negative discriminant (no assembly) or a zero one
(branches meet, ``s_4`` undetermined) is a :class:`LoopClosureError`. Angles wrapped into (-pi, pi].
"""

from __future__ import annotations

import numpy as np

from reference.physics import dual
from reference.physics.dual import Dual

__all__ = ["MIN_BRANCH_SEPARATION", "E_Z", "LoopClosureError", "angle_listing", "solve_wrapped"]

MIN_BRANCH_SEPARATION = 1e-6
"""Smallest ``sin`` of the half-angle between the two branches' ``theta_4`` that is solved [-].

Below it the branches (nearly) meet: the slides and rates grow like its inverse, and the real
solution has lost about half of its digits to the discriminant's cancellation."""

E_Z = Dual(np.array([0.0, 0.0, 1.0]))
"""The unit line along z through the origin: a joint's axis in its own D-H frame."""


class LoopClosureError(ValueError):
    """The loop cannot close, or its branches meet, at the input ``angles`` ``theta_1`` [rad]."""

    def __init__(self, message: str, angles: np.ndarray) -> None:
        super().__init__(message)
        self.angles = angles


def angle_listing(angles: np.ndarray) -> str:
    """The first eight input angles [rad] and their count, for an error message."""
    shown = ", ".join(f"{v:.6g}" for v in angles[:8])
    return f"[{shown}{', ...' if angles.size > 8 else ''}] rad ({angles.size} sample(s))"


def _defects(disc: np.ndarray, radius2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the loop cannot close (discriminant < 0) and where its branches (nearly) meet."""
    open_ = disc < -MIN_BRANCH_SEPARATION**2 * radius2
    return open_, ~open_ & (disc <= MIN_BRANCH_SEPARATION**2 * radius2)


def _check_closure(disc: np.ndarray, radius2: np.ndarray, theta1: np.ndarray, where: str) -> None:
    """Raise where the discriminant is negative or (relative to ``A^2 + B^2``) nearly zero."""
    open_, meet = _defects(disc, radius2)
    if open_.any():
        bad = theta1[open_]
        raise LoopClosureError(f"the RCCC loop cannot close (discriminant < 0) at {where} "
                               f"theta_1 = {angle_listing(bad)}", bad)
    if meet.any():
        bad = theta1[meet]
        raise LoopClosureError(f"the two assembly branches meet (singular configuration, sin of "
                               f"their half-separation < {MIN_BRANCH_SEPARATION:g}) at {where} "
                               f"theta_1 = {angle_listing(bad)}", bad)


def _angle_about_z(v: Dual) -> Dual:
    """Dual angle ``t`` of the line ``Z(t) X(alpha) e_z = (sin t sin alpha, -cos t sin alpha, .)``."""
    return dual.atan2(v[..., 0], -v[..., 1])


def solve_wrapped(twists: Dual, s1: float | np.ndarray, theta1: np.ndarray, sign: float, where: str,
                  strict: bool = True) -> Dual:
    """Dual joint angles ``theta_k + eps s_k`` (..., 4) closing the loop at input angles ``theta1`` [rad],
    real parts in (-pi, pi], from dual ``twists`` ``alpha_k + eps a_k`` and the slide ``s1`` [m], on
    root ``sign`` (the branch). ``strict``: :class:`LoopClosureError` (naming ``where``) where the loop
    does not close or the branches meet; else NaN there.
    """
    tw = twists
    t1 = Dual(theta1, np.full_like(theta1, s1))
    # joint 2 in F_4 Z(theta_4) coordinates, against joint 3 = X(-alpha_4) Z(-theta_4) (0, w_y, w_z)
    z2 = dual.matvec(dual.rot_x(tw[..., 3]) @ dual.screw_transform(t1, tw[..., 0]), E_Z)
    w_y = dual.sin(tw[..., 2])
    w_z = dual.cos(tw[..., 2])
    a = z2[..., 1] * w_y
    b = z2[..., 0] * w_y
    c = dual.cos(tw[..., 1]) - z2[..., 2] * w_z
    radius2 = a.re**2 + b.re**2
    disc = radius2 - c.re**2
    if strict:
        _check_closure(disc, radius2, theta1, where)
    x = np.arctan2(b.re, a.re) + sign * np.arctan2(np.sqrt(np.maximum(disc, 0.0)), c.re)
    if not strict:
        open_, meet = _defects(disc, radius2)
        x = np.where(open_ | meet, np.nan, x)
    cx = np.cos(x)
    sx = np.sin(x)
    # eps part of A cos t4 + B sin t4 = C, linear in s_4; the coefficient is -+sqrt(disc) != 0
    s4 = (c.du - a.du * cx - b.du * sx) / (b.re * cx - a.re * sx)
    t4 = Dual(np.arctan2(sx, cx), s4)
    z3_in_f1 = dual.matvec(dual.rot_x(-tw[..., 3]) @ dual.rot_z(-t4) @ dual.rot_x(-tw[..., 2]), E_Z)
    t2 = _angle_about_z(dual.matvec(dual.rot_x(-tw[..., 0]) @ dual.rot_z(-t1), z3_in_f1))
    z4_in_f2 = dual.matvec(dual.rot_x(-tw[..., 0]) @ dual.rot_z(-t1) @ dual.rot_x(-tw[..., 3]), E_Z)
    t3 = _angle_about_z(dual.matvec(dual.rot_x(-tw[..., 1]) @ dual.rot_z(-t2), z4_in_f2))
    return dual.stack([t1, t2, t3, t4], -1)
