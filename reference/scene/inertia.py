"""Rigid-body mass properties: frame changes, the parallel-axis theorem, and checks (numpy, SI)."""

from __future__ import annotations

import numpy as np

__all__ = ["skew", "shift_inertia_to_com", "rotate_inertia", "inertia_problems"]


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix of a 3-vector: ``skew(a) @ b == np.cross(a, b)``."""
    x, y, z = np.asarray(v, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def shift_inertia_to_com(inertia: np.ndarray, mass: float, com: np.ndarray) -> np.ndarray:
    """Inertia [kg m^2] about the centre of mass from ``inertia`` about a point P, ``mass`` [kg] and
    ``com`` relative to P [m], same axes.
    """
    s = skew(com)
    # J_P = J_C + m * skew(c)^T skew(c)  (Steiner)
    return np.asarray(inertia, dtype=float) - mass * (s.T @ s)


def rotate_inertia(inertia: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """``inertia`` [kg m^2] in new axes, ``R J R^T``, ``rotation`` ``R`` mapping old to new coordinates."""
    r = np.asarray(rotation, dtype=float)
    return r @ np.asarray(inertia, dtype=float) @ r.T


def inertia_problems(inertia: np.ndarray, rtol: float = 1e-9) -> list[str]:
    """One sentence per reason ``inertia`` [kg m^2] is not a physical tensor (symmetry, positive
    definiteness, triangle inequality of the principal moments, to ``rtol`` of the largest entry).
    """
    j = np.asarray(inertia, dtype=float)
    if j.shape != (3, 3):
        return [f"shape must be (3, 3), got {j.shape}"]
    if not np.all(np.isfinite(j)):
        return ["entries must be finite"]
    scale = max(float(np.max(np.abs(j))), 1e-300)
    problems = []
    if np.max(np.abs(j - j.T)) > rtol * scale:
        problems.append("tensor is not symmetric")
    principal = np.linalg.eigvalsh(0.5 * (j + j.T))
    if principal[0] <= 0.0:
        problems.append(f"not positive definite (principal moments {principal.tolist()})")
    elif principal[2] > principal[0] + principal[1] + rtol * scale:
        problems.append(
            "principal moments violate the triangle inequality "
            f"({principal[2]:.6g} > {principal[0]:.6g} + {principal[1]:.6g})"
        )
    return problems
