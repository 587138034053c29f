"""Joint angles and slides that close the RCCC loop, continuous in the input angle.

The real part of the loop is a spherical four-bar whose input-output equation has two roots
(:mod:`reference.physics.loop_closure` solves it); :data:`BRANCHES` picks one. Joint angles are
continuous in ``theta_1`` independently of the sampling: each is its value at ``theta_1 = 0`` on
the same branch, plus ``w_k theta_1`` with windings ``w = (1, 0, 0, -1)``, plus the deviation from
that wrapped into (-pi, pi] (:mod:`reference.physics.rccc`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from reference.physics import dual
from reference.physics.dual import Dual
from reference.physics.loop_closure import LoopClosureError, angle_listing, solve_wrapped
from reference.physics.rccc.parameters import DHParameters

__all__ = ["BRANCHES", "WINDING", "WINDING_SAMPLES", "LoopPositions", "at_zero", "continuous_angles",
           "loop_closure_residual", "sample_array", "solve_positions", "winding_jumps"]

BRANCHES = ("hooke", "flipped")
"""Assembly branches: ``hooke`` the minus sign of the input-output equation, ``flipped`` the plus."""
BRANCH_SIGN = {"hooke": -1.0, "flipped": 1.0}
WINDING = np.array([1.0, 0.0, 0.0, -1.0])
"""Turns of each joint angle per input turn."""


@dataclass(frozen=True)
class LoopPositions:
    """Solved loop at an array of input angles: joint angles ``theta`` [rad] continuous in ``theta_1`` and
    slides ``s`` [m] (..., 4), their ``reference`` at ``theta_1 = 0``, the ``branch``, and
    ``reference_slide`` [m] when given with the positions (None: solved when needed).
    """

    theta: np.ndarray
    s: np.ndarray
    reference: np.ndarray
    branch: str
    reference_slide: np.ndarray | None = None

    def dual_angles(self) -> Dual:
        """``theta_k + eps s_k``, shape (..., 4)."""
        return Dual(self.theta, self.s)


def sample_array(name: str, value, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """``value`` as a finite float array broadcast to ``shape``; ValueError naming ``name`` otherwise."""
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
    return solve_wrapped(params.twists(), params.s1, theta1, BRANCH_SIGN[branch], where)


@functools.lru_cache(maxsize=256)
def at_zero(params: DHParameters, branch: str) -> tuple[np.ndarray, np.ndarray]:
    """Joint angles [rad] and slides [m] (4,), read-only, at ``theta_1 = 0`` on ``branch`` of ``params``
    (cached).
    """
    angles = _solve(params, np.zeros(1), branch, "the reference input angle")
    theta = angles.re[0].copy()
    slide = angles.du[0].copy()
    theta.flags.writeable = slide.flags.writeable = False  # shared by every caller
    return theta, slide


WINDING_SAMPLES = 1440
"""Input angles per turn at which :func:`solve_positions` checks the windings (0.25 deg apart)."""


@functools.lru_cache(maxsize=256)
def _check_windings(params: DHParameters, branch: str) -> None:
    """Raise unless every joint angle of ``params`` on ``branch`` turns as the Cardan joint's over one input
    turn, on a fine grid (a large twist error can make the loop a crank-rocker: it closes, but an angle
    jumps a full turn).
    """
    theta1 = np.linspace(0.0, 2.0 * np.pi, WINDING_SAMPLES + 1)
    try:
        reference = at_zero(params, branch)[0]
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
    """Per interval and joint 2..4 (..., m - 1, 3), whether the ``raw`` wrapped solution [rad] at input
    angles ``theta1`` jumps a quarter turn or more against the Cardan windings from its ``reference``
    (any True: not a double crank).
    """
    nominal = reference[..., None, :] + WINDING * theta1[:, None]
    deviation = np.remainder(raw - nominal + np.pi, 2.0 * np.pi) - np.pi
    return np.abs(np.diff(deviation[..., 1:], axis=-2)) > 0.5 * np.pi


def solve_positions(params: DHParameters, theta1: ArrayLike, branch: str = "hooke") -> LoopPositions:
    """:class:`LoopPositions` closing the loop ``params`` at input angles ``theta1`` [rad] (any shape) on
    assembly ``branch`` ``"hooke"`` or ``"flipped"``; LoopClosureError where the loop cannot close, or
    its branches meet, at some input angle or at 0.
    """
    if branch not in BRANCHES:
        raise ValueError(f"`branch` must be one of {list(BRANCHES)}, got {branch!r}")
    theta1 = sample_array("theta1", theta1)
    _check_windings(params, branch)
    reference = at_zero(params, branch)[0]
    raw = _solve(params, theta1, branch, "input angles")
    return LoopPositions(theta=continuous_angles(raw.re, reference, theta1), s=raw.du,
                         reference=reference, branch=branch)


def continuous_angles(wrapped: np.ndarray, reference: np.ndarray, theta1: np.ndarray) -> np.ndarray:
    """Joint angles (..., 4) [rad] continuous in ``theta1`` (the first equal to it) from the ``wrapped``
    solution in (-pi, pi] and its ``reference`` value at ``theta_1 = 0`` (:mod:`reference.physics.rccc`).
    """
    nominal = reference + WINDING * theta1[..., None]
    theta = nominal + np.remainder(wrapped - nominal + np.pi, 2.0 * np.pi) - np.pi
    theta[..., 0] = theta1
    return theta


def loop_closure_residual(params: DHParameters, positions: LoopPositions) -> tuple[float, float]:
    """Largest deviation of ``prod_k Z(theta_hat_k) X(alpha_hat_k)`` from the identity over the
    ``positions``: of the real part [-] and of the dual part [m].
    """
    steps = dual.screw_transform(positions.dual_angles(), params.twists())
    loop = steps[..., 0, :, :] @ steps[..., 1, :, :] @ steps[..., 2, :, :] @ steps[..., 3, :, :]
    return float(np.max(np.abs(loop.re - np.eye(3)), initial=0.0)), \
        float(np.max(np.abs(loop.du), initial=0.0))
