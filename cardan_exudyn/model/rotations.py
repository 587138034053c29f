"""Rotation coordinates of Exudyn's rigid-body nodes, vectorised over time, without Exudyn (checked
against its node outputs by ``tests/test_node_types.py``).

Rxyz: ``A = Rx(psi0) Ry(psi1) Rz(psi2)``, ``omega = G(psi) psi_t``, ``G = [e_x, Rx e_y, Rx Ry e_z]``
(global). EP: Euler parameters ``(e0, e1, e2, e3)``. RotVecLG: ``A = exp(skew(nu))``, velocity
coordinates the local angular velocity, ``omega = A p_t``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["rxyz_matrix", "rxyz_angular_velocity", "rxyz_from_matrix", "rxyz_rates", "rxyz_frame",
           "rxyz_frame_one", "ep_frame", "ep_frame_one", "ep_from_matrix", "ep_rates", "rotvec_frame",
           "rotvec_frame_one", "rotvec_from_matrix", "rotvec_rates", "RotationCoordinates", "TWO_PI",
           "WholeTurns", "ROTATION_COORDINATES"]


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
    """Global angular velocity ``G(psi) psi_t`` [rad/s], shape (n, 3), of Rxyz angles ``psi`` [rad] and
    rates ``psi_t`` [rad/s]."""
    psi = np.atleast_2d(psi)
    psi_t = np.atleast_2d(psi_t)
    c0 = np.cos(psi[:, 0])
    c1 = np.cos(psi[:, 1])
    s0 = np.sin(psi[:, 0])
    s1 = np.sin(psi[:, 1])
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
    """Angle rates ``psi_t`` [rad/s] with ``G(psi) psi_t = omega`` (global [rad/s])."""
    c0 = np.cos(psi[0])
    c1 = np.cos(psi[1])
    s0 = np.sin(psi[0])
    s1 = np.sin(psi[1])
    g = np.array([[1.0, 0.0, s1], [0.0, c0, -s0 * c1], [0.0, s0, c0 * c1]])
    return np.linalg.solve(g, omega)


def rxyz_frame(psi: np.ndarray, psi_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation matrices (n, 3, 3), body to global, and global angular velocities [rad/s] of Rxyz
    angles ``psi`` [rad] and rates ``psi_t``."""
    return rxyz_matrix(psi), rxyz_angular_velocity(psi, psi_t)


def rxyz_frame_one(psi, psi_t) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rxyz_frame` of one state with scalar math (the per-Newton-solve friction update)."""
    c0, c1, c2 = math.cos(psi[0]), math.cos(psi[1]), math.cos(psi[2])
    s0, s1, s2 = math.sin(psi[0]), math.sin(psi[1]), math.sin(psi[2])
    a = np.array([
        [c1 * c2, -c1 * s2, s1],
        [s0 * s1 * c2 + c0 * s2, -s0 * s1 * s2 + c0 * c2, -s0 * c1],
        [-c0 * s1 * c2 + s0 * s2, c0 * s1 * s2 + s0 * c2, c0 * c1],
    ])
    omega = np.array([psi_t[0] + s1 * psi_t[2],
                      c0 * psi_t[1] - s0 * c1 * psi_t[2],
                      s0 * psi_t[1] + c0 * c1 * psi_t[2]])
    return a, omega


# Exudyn's NodeRigidBodyEP: p = (e0, e1, e2, e3), e0 the scalar part, |p| = 1 kept by an algebraic
# constraint; A(p) and omega = G(p) p_t (global) in the unnormalised form Exudyn evaluates
# (RigidBodyMath::EP2RotationMatrix, EP2G), so that the post-processing sees what the solver saw.


def ep_frame(p: np.ndarray, p_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation matrices (n, 3, 3) and global angular velocities [rad/s] of Euler parameters ``p``
    (n, 4) and rates ``p_t`` [1/s]."""
    p = np.atleast_2d(p)
    p_t = np.atleast_2d(p_t)
    e0, e1, e2, e3 = p.T
    a = np.empty((p.shape[0], 3, 3))
    a[:, 0, 0] = 1.0 - 2.0 * (e2 * e2 + e3 * e3)
    a[:, 0, 1] = 2.0 * (e1 * e2 - e0 * e3)
    a[:, 0, 2] = 2.0 * (e1 * e3 + e0 * e2)
    a[:, 1, 0] = 2.0 * (e1 * e2 + e0 * e3)
    a[:, 1, 1] = 1.0 - 2.0 * (e1 * e1 + e3 * e3)
    a[:, 1, 2] = 2.0 * (e2 * e3 - e0 * e1)
    a[:, 2, 0] = 2.0 * (e1 * e3 - e0 * e2)
    a[:, 2, 1] = 2.0 * (e2 * e3 + e0 * e1)
    a[:, 2, 2] = 1.0 - 2.0 * (e1 * e1 + e2 * e2)
    d0, d1, d2, d3 = p_t.T
    omega = 2.0 * np.stack([-e1 * d0 + e0 * d1 - e3 * d2 + e2 * d3,
                            -e2 * d0 + e3 * d1 + e0 * d2 - e1 * d3,
                            -e3 * d0 - e2 * d1 + e1 * d2 + e0 * d3], axis=1)
    return a, omega


def ep_frame_one(p, p_t) -> tuple[np.ndarray, np.ndarray]:
    """:func:`ep_frame` of one state with scalar math."""
    e0, e1, e2, e3 = float(p[0]), float(p[1]), float(p[2]), float(p[3])
    d0, d1, d2, d3 = float(p_t[0]), float(p_t[1]), float(p_t[2]), float(p_t[3])
    a = np.array([
        [1.0 - 2.0 * (e2 * e2 + e3 * e3), 2.0 * (e1 * e2 - e0 * e3), 2.0 * (e1 * e3 + e0 * e2)],
        [2.0 * (e1 * e2 + e0 * e3), 1.0 - 2.0 * (e1 * e1 + e3 * e3), 2.0 * (e2 * e3 - e0 * e1)],
        [2.0 * (e1 * e3 - e0 * e2), 2.0 * (e2 * e3 + e0 * e1), 1.0 - 2.0 * (e1 * e1 + e2 * e2)],
    ])
    omega = np.array([2.0 * (-e1 * d0 + e0 * d1 - e3 * d2 + e2 * d3),
                      2.0 * (-e2 * d0 + e3 * d1 + e0 * d2 - e1 * d3),
                      2.0 * (-e3 * d0 - e2 * d1 + e1 * d2 + e0 * d3)])
    return a, omega


def ep_from_matrix(a: np.ndarray) -> np.ndarray:
    """Unit Euler parameters (e0 >= 0) of one rotation matrix (Shepperd's method)."""
    a = np.asarray(a, dtype=float)
    trace = a[0, 0] + a[1, 1] + a[2, 2]
    k = int(np.argmax([trace, a[0, 0], a[1, 1], a[2, 2]]))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        p = [0.25 * s, (a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s]
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + a[0, 0] - a[1, 1] - a[2, 2])
        p = [(a[2, 1] - a[1, 2]) / s, 0.25 * s, (a[0, 1] + a[1, 0]) / s, (a[0, 2] + a[2, 0]) / s]
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 + a[1, 1] - a[0, 0] - a[2, 2])
        p = [(a[0, 2] - a[2, 0]) / s, (a[0, 1] + a[1, 0]) / s, 0.25 * s, (a[1, 2] + a[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + a[2, 2] - a[0, 0] - a[1, 1])
        p = [(a[1, 0] - a[0, 1]) / s, (a[0, 2] + a[2, 0]) / s, (a[1, 2] + a[2, 1]) / s, 0.25 * s]
    p = np.array(p)
    p /= np.linalg.norm(p)
    return -p if p[0] < 0.0 else p


def ep_rates(p: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Rates ``p_t`` [1/s] of unit ``p`` with ``G(p) p_t = omega`` and ``p . p_t = 0``: ``G^T omega / 4``."""
    e0, e1, e2, e3 = p
    g = 2.0 * np.array([[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]])
    return 0.25 * g.T @ np.asarray(omega, dtype=float)


# Exudyn's NodeRigidBodyRotVecLG: p = nu, A = exp(skew(nu)) (Rodrigues, as in
# RigidBodyMath::RotationVector2RotationMatrix; Exudyn's Lie-group update keeps |nu| <= 2 pi), and
# the velocity coordinates are the *local* angular velocity: omega = A p_t.


def _rotvec_coefficients(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sin(phi)/phi and (1 - cos(phi))/phi^2, also at phi = 0."""
    safe = np.where(phi == 0.0, 1.0, phi)
    half = np.sin(0.5 * safe)
    return (np.where(phi == 0.0, 1.0, np.sin(safe) / safe),
            np.where(phi == 0.0, 0.5, 2.0 * half * half / (safe * safe)))


def rotvec_frame(p: np.ndarray, p_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation matrices (n, 3, 3) and global angular velocities [rad/s] of rotation vectors ``p``
    [rad] and local angular velocities ``p_t`` [rad/s]."""
    p = np.atleast_2d(p)
    p_t = np.atleast_2d(p_t)
    x, y, z = p.T
    s, c = _rotvec_coefficients(np.sqrt(x * x + y * y + z * z))
    a = np.empty((p.shape[0], 3, 3))
    a[:, 0, 0] = 1.0 - c * (y * y + z * z)
    a[:, 0, 1] = -s * z + c * x * y
    a[:, 0, 2] = s * y + c * x * z
    a[:, 1, 0] = s * z + c * x * y
    a[:, 1, 1] = 1.0 - c * (x * x + z * z)
    a[:, 1, 2] = -s * x + c * y * z
    a[:, 2, 0] = -s * y + c * x * z
    a[:, 2, 1] = s * x + c * y * z
    a[:, 2, 2] = 1.0 - c * (x * x + y * y)
    return a, np.einsum("nij,nj->ni", a, p_t)


def rotvec_frame_one(p, p_t) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rotvec_frame` of one state with scalar math."""
    x, y, z = float(p[0]), float(p[1]), float(p[2])
    phi = math.sqrt(x * x + y * y + z * z)
    if phi == 0.0:
        s = 1.0
        c = 0.5
    else:
        half = math.sin(0.5 * phi)
        s = math.sin(phi) / phi
        c = 2.0 * half * half / (phi * phi)
    a = np.array([
        [1.0 - c * (y * y + z * z), -s * z + c * x * y, s * y + c * x * z],
        [s * z + c * x * y, 1.0 - c * (x * x + z * z), -s * x + c * y * z],
        [-s * y + c * x * z, s * x + c * y * z, 1.0 - c * (x * x + y * y)],
    ])
    return a, a @ np.asarray(p_t, dtype=float)


def rotvec_from_matrix(a: np.ndarray) -> np.ndarray:
    """Rotation vector (|nu| <= pi) of one rotation matrix, via its unit Euler parameters."""
    p = ep_from_matrix(a)
    sine = float(np.linalg.norm(p[1:]))
    if sine == 0.0:
        return np.zeros(3)
    return 2.0 * math.atan2(sine, p[0]) / sine * p[1:]


def rotvec_rates(p: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Velocity coordinates of a RotVecLG node: the local angular velocity ``A(nu)^T omega`` [rad/s]."""
    a, _ = rotvec_frame_one(p, np.zeros(3))
    return a.T @ np.asarray(omega, dtype=float)


@dataclass(frozen=True)
class RotationCoordinates:
    """How a node type stores its rotation: ``reference`` coordinates (the identity), ``frame`` /
    ``frame_one`` (coordinates, rates) -> (matrices, global angular velocities), ``from_matrix`` and
    ``rates`` the inverse maps."""

    name: str
    node_class: str
    size: int
    reference: tuple[float, ...]
    frame: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    frame_one: Callable[[Any, Any], tuple[np.ndarray, np.ndarray]]
    from_matrix: Callable[[np.ndarray], np.ndarray]
    rates: Callable[[np.ndarray, np.ndarray], np.ndarray]

    @property
    def zero_reference(self) -> bool:
        return not any(self.reference)


TWO_PI = 2.0 * math.pi


@dataclass
class WholeTurns:
    """Whole revolutions taken out of the input's unbounded angle coordinate (kept within ``[-pi, pi]``
    by :meth:`remove`): ``start`` in the initial angle, and the ``times`` [s] and total ``counts``
    of each removal, so :meth:`angle` gives back the continuous angle."""

    start: int = 0
    times: list[float] = field(default_factory=list)
    counts: list[int] = field(default_factory=list)

    @property
    def count(self) -> int:
        """Whole revolutions removed so far."""
        return self.counts[-1] if self.counts else self.start

    def reset(self) -> None:
        """Forget the revolutions removed (the model is solved again from its start)."""
        self.times.clear()
        self.counts.clear()

    def remove(self, coordinate: float, t: float) -> float:
        """``coordinate`` [rad] less its nearest whole revolutions at time ``t`` [s], recording the change."""
        k = round(coordinate / TWO_PI)
        if k == 0:
            return coordinate
        self.times.append(t)
        self.counts.append(self.count + k)
        return coordinate - k * TWO_PI

    def at(self, t: np.ndarray) -> np.ndarray:
        """Whole revolutions removed from the states at times ``t`` [s] (recorded after the hook)."""
        counts = np.asarray([self.start, *self.counts], dtype=float)
        return counts[np.searchsorted(np.asarray(self.times, dtype=float), t, side="right")]

    def angle(self, t: np.ndarray, coordinate: np.ndarray) -> np.ndarray:
        """The continuous angle [rad] of recorded states at times ``t`` [s], coordinates ``coordinate``."""
        return coordinate + TWO_PI * self.at(t)


ROTATION_COORDINATES = {
    "Rxyz": RotationCoordinates("Rxyz", "NodeRigidBodyRxyz", 3, (0.0, 0.0, 0.0), rxyz_frame,
                                rxyz_frame_one, rxyz_from_matrix, rxyz_rates),
    "EP": RotationCoordinates("EP", "NodeRigidBodyEP", 4, (1.0, 0.0, 0.0, 0.0), ep_frame,
                              ep_frame_one, ep_from_matrix, ep_rates),
    "RotVecLG": RotationCoordinates("RotVecLG", "NodeRigidBodyRotVecLG", 3, (0.0, 0.0, 0.0),
                                    rotvec_frame, rotvec_frame_one, rotvec_from_matrix,
                                    rotvec_rates),
}
