"""Velocity projection of recorded Exudyn states onto the joint's velocity constraints (post-processing:
nothing feeds back into the integration).

Index-3 generalized-alpha keeps positions on the constraints but velocities miss them by
``O(h^2)``, the whole of Exudyn's speed-ratio error (measured:
docs/bench.md#velocity-projection-what-it-is-and-what-it-is-not). Per pair (a's frame columns
``x_j``, points ``p_a``, ``p_b``): ``x_j . (v_b(p_b) - v_a(p_b)) = 0`` and
``(omega_b - omega_a) . x_j = 0`` for ``j = x, y``. A prescribed input fixes all 18 velocities;
a torque drive gets the closest consistent velocity in the kinetic-energy metric.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES

__all__ = ["BODIES", "cross_rows", "constraint_jacobian", "project_velocities"]

BODIES = ("input", "spider", "output")


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` row by row, shapes (n, 3) or (3,) broadcasting: ``np.cross`` without its axis handling."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def _skew_rows(rho: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Coefficients of omega in ``axis . (omega x rho)``, i.e. ``rho x axis`` (rows)."""
    return cross_rows(rho, axis)


def constraint_jacobian(states: dict[str, dict[str, np.ndarray]],
                        pairs: dict[str, dict[str, np.ndarray]]) -> np.ndarray:
    """The (n, 17, 18) velocity-constraint Jacobian of the four pairs, from body CoMs ``states[b]["r"]``
    [m] and pair ``frame_a``, ``pa``, ``pb``; unknowns per body in :data:`BODIES` order: CoM velocity,
    then angular velocity (global)."""
    n = next(iter(pairs.values()))["pa"].shape[0]
    jac = np.zeros((n, 17, 18))
    row = 0
    for name in PAIR_NAMES:
        body_a, body_b = PAIR_BODIES[name]
        k = pairs[name]
        frame = k["frame_a"][:n]
        p_b = k["pb"][:n]
        bodies = [(BODIES.index(body), sign) for body, sign in ((body_b, 1.0), (body_a, -1.0))
                  if body != "ground"]
        for j in (0, 1, 2) if PAIR_KIND[name] == "revolute" else (0, 1):
            axis = frame[:, :, j]
            for i, sign in bodies:
                jac[:, row, 6 * i:6 * i + 3] = sign * axis
                jac[:, row, 6 * i + 3:6 * i + 6] = sign * _skew_rows(p_b - states[BODIES[i]]["r"][:n], axis)
            row += 1
        for j in (0, 1):
            for i, sign in bodies:
                jac[:, row, 6 * i + 3:6 * i + 6] = sign * frame[:, :, j]
            row += 1
    return jac


def project_velocities(states: dict[str, dict[str, np.ndarray]],
                       pairs: dict[str, dict[str, np.ndarray]],
                       mass: dict[str, float], inertia_node: dict[str, np.ndarray],
                       input_axis: np.ndarray,
                       input_speed: Callable[[np.ndarray], np.ndarray] | None) -> dict:
    """``states`` with every body's ``v`` and ``omega`` projected, plus ``"max_velocity_correction"``.
    ``mass`` [kg], ``inertia_node`` [kg m^2] the torque drive's metric; ``input_axis`` the input's unit
    axis; ``input_speed(t)`` the prescribed input speed [rad/s] (None: torque drive)."""
    n = next(iter(pairs.values()))["pa"].shape[0]
    jac = constraint_jacobian(states, pairs)
    u_rec = np.concatenate([np.concatenate([states[b]["v"][:n], states[b]["omega"][:n]], axis=1)
                            for b in BODIES], axis=1)
    if input_speed is not None:
        drive = np.zeros((n, 1, 18))
        drive[:, 0, 3:6] = input_axis
        a = np.concatenate([jac, drive], axis=1)
        rhs = np.zeros((n, 18))
        rhs[:, -1] = input_speed(states["input"]["t"][:n])
        u = np.linalg.solve(a, rhs[..., None])[..., 0]
    else:
        m_inv = np.zeros((n, 18, 18))
        for i, body in enumerate(BODIES):
            rot = states[body]["A"][:n]
            j_global = rot @ inertia_node[body] @ np.swapaxes(rot, 1, 2)
            m_inv[:, 6 * i:6 * i + 3, 6 * i:6 * i + 3] = np.eye(3) / mass[body]
            m_inv[:, 6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = np.linalg.inv(j_global)
        mj = m_inv @ np.swapaxes(jac, 1, 2)                         # M^-1 J^T
        schur = jac @ mj                                            # J M^-1 J^T
        lam = np.linalg.solve(schur, (jac @ u_rec[..., None]))     # (J M^-1 J^T)^-1 J u
        u = u_rec - (mj @ lam)[..., 0]
    out = {}
    for i, body in enumerate(BODIES):
        out[body] = {**states[body], "v": u[:, 6 * i:6 * i + 3], "omega": u[:, 6 * i + 3:6 * i + 6]}
    out["max_velocity_correction"] = float(np.max(np.abs(u - u_rec))) if n else 0.0
    return out
