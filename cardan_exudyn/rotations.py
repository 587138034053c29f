"""Tait-Bryan (Rxyz) rotation parameters, vectorised over time.

Exudyn's ``NodeRigidBodyRxyz`` uses ``A = Rx(psi0) Ry(psi1) Rz(psi2)`` (body to global) and
angular velocity ``omega = G(psi) psi_t`` with ``G = [e_x, Rx e_y, Rx Ry e_z]`` (global
components). These helpers post-process recorded node coordinates without calling Exudyn.
"""

from __future__ import annotations

import numpy as np


def rxyz_matrix(psi: np.ndarray) -> np.ndarray:
    """Rotation matrices ``Rx(psi0) Ry(psi1) Rz(psi2)``, shape (n, 3, 3), for psi of shape (n, 3)."""
    psi = np.atleast_2d(psi)
    c0, c1, c2 = np.cos(psi).T
    s0, s1, s2 = np.sin(psi).T
    a = np.empty((psi.shape[0], 3, 3))
    a[:, 0, 0] = c1 * c2
    a[:, 0, 1] = -c1 * s2
    a[:, 0, 2] = s1
    a[:, 1, 0] = s0 * s1 * c2 + c0 * s2
    a[:, 1, 1] = -s0 * s1 * s2 + c0 * c2
    a[:, 1, 2] = -s0 * c1
    a[:, 2, 0] = -c0 * s1 * c2 + s0 * s2
    a[:, 2, 1] = c0 * s1 * s2 + s0 * c2
    a[:, 2, 2] = c0 * c1
    return a


def rxyz_angular_velocity(psi: np.ndarray, psi_t: np.ndarray) -> np.ndarray:
    """Global angular velocity ``G(psi) psi_t``, shape (n, 3) [rad/s]."""
    psi = np.atleast_2d(psi)
    psi_t = np.atleast_2d(psi_t)
    c0, c1 = np.cos(psi[:, 0]), np.cos(psi[:, 1])
    s0, s1 = np.sin(psi[:, 0]), np.sin(psi[:, 1])
    w = np.empty_like(psi_t, dtype=float)
    w[:, 0] = psi_t[:, 0] + s1 * psi_t[:, 2]
    w[:, 1] = c0 * psi_t[:, 1] - s0 * c1 * psi_t[:, 2]
    w[:, 2] = s0 * psi_t[:, 1] + c0 * c1 * psi_t[:, 2]
    return w


def rxyz_from_matrix(a: np.ndarray) -> np.ndarray:
    """Rxyz angles of one rotation matrix (|psi1| < pi/2 branch)."""
    a = np.asarray(a, dtype=float)
    psi1 = np.arcsin(np.clip(a[0, 2], -1.0, 1.0))
    psi0 = np.arctan2(-a[1, 2], a[2, 2])
    psi2 = np.arctan2(-a[0, 1], a[0, 0])
    return np.array([psi0, psi1, psi2])


def rxyz_rates(psi: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Angle rates psi_t with ``G(psi) psi_t = omega`` (global angular velocity)."""
    c0, c1 = np.cos(psi[0]), np.cos(psi[1])
    s0, s1 = np.sin(psi[0]), np.sin(psi[1])
    g = np.array([[1.0, 0.0, s1], [0.0, c0, -s0 * c1], [0.0, s0, c0 * c1]])
    return np.linalg.solve(g, omega)
