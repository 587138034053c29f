"""The friction law of eqs. (3) and (5) on the reactions: each slot's friction value and its
slopes from the four reaction components it reads (the normal force and the bending moment in the
pair frame), for many samples at once. The law objects of :mod:`reference.engine.slots` and
:mod:`reference.engine.batch.model` evaluate it; :func:`reference.engine.fixed_point.solve_friction`
calls those objects.
"""

from __future__ import annotations

import numpy as np

__all__ = ["friction_law_values", "reduced_law_values"]


def friction_law_values(x: np.ndarray, index: np.ndarray, signs: np.ndarray, k_force: np.ndarray,
                        k_moment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`reference.engine.slots.FrictionLaw.__call__` with its coefficients given.

    Parameters
    ----------
    x : ndarray, shape (n, 18)
        Reactions and the drive unknown.
    index : ndarray of int, shape (K, 4)
        The columns of ``x`` holding each slot's fx, fy, mx, my.
    signs : ndarray, shape (n, K)
        Each slot's friction factor in [-1, 1].
    k_force, k_moment : ndarray, shape (K,) or (n, K)
        The law's factors of ``|F|`` [m or -] and ``|M|`` [- or 1/m].

    Returns
    -------
    values : ndarray, shape (n, K)
        Friction values [N m or N].
    jacobian : ndarray, shape (n, K, 18)
        ``dG/dx``.
    """
    values, slopes = reduced_law_values(x[:, index], signs, k_force, k_moment)
    jacobian = np.zeros(x.shape[:1] + index.shape[:1] + x.shape[1:])
    jacobian[:, np.arange(index.shape[0])[:, None], index] = slopes
    return values, jacobian


def reduced_law_values(c: np.ndarray, signs: np.ndarray, k_force: np.ndarray,
                       k_moment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The law of eqs. (3) and (5) on the components it reads.

    Parameters
    ----------
    c : ndarray, shape (n, K, 4)
        Each slot's fx, fy [N], mx, my [N m].
    signs, k_force, k_moment
        As for :func:`friction_law_values`.

    Returns
    -------
    values : ndarray, shape (n, K)
        Friction values [N m or N].
    slopes : ndarray, shape (n, K, 4)
        Their derivatives with respect to ``c`` (the zero subgradient where a norm is exactly
        zero); :func:`friction_law_values` scatters them into ``dG/dx``.
    """
    force = np.hypot(c[..., 0], c[..., 1])
    moment = np.hypot(c[..., 2], c[..., 3])
    per_force = -signs * k_force
    per_moment = -signs * k_moment
    with np.errstate(invalid="ignore", divide="ignore"):
        along_force = np.where(force > 0, per_force / force, 0.0)
        along_moment = np.where(moment > 0, per_moment / moment, 0.0)
    slopes = np.empty(np.broadcast_shapes(c.shape, along_force.shape + (4,)))
    np.multiply(c[..., :2], along_force[..., None], out=slopes[..., :2])
    np.multiply(c[..., 2:], along_moment[..., None], out=slopes[..., 2:])
    return per_force * force + per_moment * moment, slopes
