"""Instants where a friction sign ramp starts or ends: the kinks of the work integrands."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from reference.engine.crossings import (
    SCAN_PER_REVOLUTION,
    distinct_instants,
    grazing_brackets,
    grazing_candidates,
    sign_change_brackets,
)
from reference.engine.motion import InputMotion
from reference.engine.slots import friction_slots, ramp_bands, ramp_speeds
from reference.physics.joint_motion import joint_motion
from reference.scene.scene import Scene

__all__ = ["sign_breakpoints"]


def sign_breakpoints(scene: Scene, motion: InputMotion, t_a: float, t_b: float,
                     per_revolution: int = SCAN_PER_REVOLUTION) -> np.ndarray:
    """The distinct instants [s] in ``(t_a, t_b)``, ascending, where a friction sign ramp of ``scene``
    driven by ``motion`` starts or ends: each ramp speed sampled at ``per_revolution`` (at least 64 in
    all), crossings of ``+-band`` bracketed (:mod:`reference.engine.crossings`) and refined to rounding.
    """
    slots = friction_slots(scene)
    if not slots or t_b <= t_a:
        return np.zeros(0)

    def speeds(t: np.ndarray) -> np.ndarray:
        theta, theta_t, _ = motion.state(t)
        kin = joint_motion(scene.joint, theta, theta_t, 0.0)  # speeds do not need accelerations
        return ramp_speeds(scene, slots, kin.omega_rel, kin.slide_rel)  # resultant law: slip speeds too

    theta_a = motion.angle(t_a)
    theta_b = motion.angle(t_b)
    n = max(64, int(per_revolution * abs(theta_b - theta_a) / (2.0 * math.pi)))
    grid = np.linspace(t_a, t_b, n + 1)
    values = speeds(grid)
    brackets = _brackets(grid, values, ramp_bands(scene, slots), speeds)
    if not brackets:
        return np.zeros(0)
    return distinct_instants(_refine(brackets, speeds), t_b - t_a)


def _brackets(grid: np.ndarray, values: np.ndarray, bands: np.ndarray,
              speeds: Callable[[np.ndarray], np.ndarray]) -> list[tuple]:
    """Brackets of every crossing of ``+-bands`` (K,) by ``values`` (m, K) on ``grid`` [s]: sign changes,
    and grazing crossings checked at their vertices by ``speeds``.
    """
    brackets = []
    grazing = []
    for levels in (-bands, bands):  # twice 0 for the exact sign: duplicates merge later
        brackets += sign_change_brackets(grid, values, levels)
        grazing += [(levels, c) for c in grazing_candidates(grid, values, levels)]
    if grazing:  # every vertex in one evaluation
        at = speeds(np.array([c[0] for _, c in grazing]))
        for row, (levels, c) in enumerate(grazing):
            brackets += grazing_brackets(grid, values, levels, [c], at[row, c[2]:c[2] + 1])
    return brackets


def _refine(brackets: list[tuple], speeds: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Each bracket's crossing [s] to rounding: Illinois regula falsi on all brackets at once."""
    a, b, f_a, f_b, j, level = (np.array(v) for v in zip(*brackets, strict=True))
    rows = np.arange(a.size)
    for _ in range(100):
        c = b - f_b * (b - a) / (f_b - f_a)
        f_c = speeds(c)[rows, j] - level
        same = np.sign(f_c) == np.sign(f_b)
        a = np.where(same, a, b)
        f_a = np.where(same, 0.5 * f_a, f_b)
        b = c
        f_b = f_c
        if np.all((np.abs(b - a) <= 1e-15) | (f_b == 0.0)):
            break
    return b
