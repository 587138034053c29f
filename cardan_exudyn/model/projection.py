"""Velocity projection of recorded Exudyn states onto the joint's velocity constraints.

Generalized-alpha with index-3 constraints keeps the *positions* on the constraint manifold to
the Newton tolerance, but its velocities come from the Newmark update and miss the velocity
constraints by ``O(h^2)``: that is the whole of Exudyn's error in ``omega_out / omega_in``
(measured: docs/bench.md#velocity-projection-what-it-is-and-what-it-is-not). Projecting the
recorded velocities onto the velocity constraints at the recorded positions removes that part:

- with a prescribed input (constant speed or angle history) the joint has no degree of freedom
  left, the 17 pair constraints and the drive fix all 18 velocity components, and the projection
  is the exact velocity *of the computed positions*: its error is then the position error, which
  index-3 keeps at the Newton tolerance;
- with a torque drive one degree of freedom remains and the projection is the closest
  consistent velocity in the kinetic-energy metric (the usual velocity projection of index-3
  integrators).

It is post-processing: the projected velocities do not feed back into the integration, so the
drive torque, the reactions and the friction keep the integrator's ``O(h^2)`` error.

The constraint rows are the time derivatives of the pair constraints of
``ObjectJointGeneric`` (relative displacement normal to the axis, or all of it for the revolute;
relative rotation about the two axes normal to the pair axis), written here from the pair
geometry: for a pair with body ``a`` (frame ``x_j`` columns, point ``p_a``) and body ``b``
(point ``p_b``), ``x_j . (v_b(p_b) - v_a(p_b)) = 0`` (the velocity of ``p_b`` relative to body
``a``; this includes the rotation of ``x_j`` when a cylindrical pair's points are apart along the
axis) and ``(omega_b - omega_a) . x_j = 0`` for ``j = x, y``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES

__all__ = ["BODIES", "cross_rows", "constraint_jacobian", "project_velocities"]

BODIES = ("input", "spider", "output")


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` row by row: ``np.cross`` without its axis handling, which costs more than the
    product on short runs.

    Parameters
    ----------
    a, b : ndarray, shape (n, 3) or (3,)
        Vectors (any unit); a ``(3,)`` vector broadcasts against the rows of the other.

    Returns
    -------
    ndarray, shape (n, 3) or (3,)
        The cross products (unit of ``a`` times unit of ``b``).
    """
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
    """Velocity-constraint Jacobian of the four pairs at every recorded row.

    Parameters
    ----------
    states : dict
        Per body ``r``, shape (n, 3): centre-of-mass position [m].
    pairs : dict
        Per pair ``frame_a``, shape (n, 3, 3) (columns the pair axes of body a), and ``pa``,
        ``pb``, shape (n, 3): marker points [m].

    Returns
    -------
    ndarray, shape (n, 17, 18)
        ``J``; the unknowns per body (in :data:`BODIES` order) are the centre-of-mass velocity
        (3) then the angular velocity (3), global components. Rows are dimensionless (velocity
        rows) or in m (the lever of an angular velocity in a velocity row).
    """
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
    """Replace ``v`` and ``omega`` of every body by their projection (see the module docstring).

    Parameters
    ----------
    states : dict
        Per body ``t, r, v, A, omega`` (n rows), as :func:`cardan_exudyn.model.postprocess.body_states`.
    pairs : dict
        Per pair the geometry of :func:`constraint_jacobian`.
    mass, inertia_node : dict
        Per body the mass [kg] and inertia about the centre of mass in node coordinates [kg m^2]
        (the metric of a torque-driven projection).
    input_axis : ndarray
        Unit vector of the input shaft axis (global).
    input_speed : callable or None
        ``t -> omega_in`` of a prescribed input (the 18th row), None for a torque drive.

    Returns
    -------
    dict
        ``states`` with ``v`` and ``omega`` replaced (new arrays), and the largest velocity
        correction ``|u - u_recorded|`` in ``"max_velocity_correction"`` (rad/s or m/s, mixed).
    """
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
