"""The friction law of eqs. (3) and (5) on the reactions: each slot's friction value and its slopes
from the four reaction components it reads, for many samples at once.
"""

from __future__ import annotations

import numpy as np

__all__ = ["friction_law_values", "reduced_law_values"]


def friction_law_values(x: np.ndarray, index: np.ndarray, signs: np.ndarray, k_force: np.ndarray,
                        k_moment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(values (n, K) [N m or N], jacobian dG/dx (n, K, 18))`` at reactions ``x`` (n, 18), ``index``
    (K, 4) the columns of each slot's fx, fy, mx, my, factors ``signs`` (n, K) and the law's factors
    ``k_force`` of ``|F|``, ``k_moment`` of ``|M|``.
    """
    values, slopes = reduced_law_values(x[:, index], signs, k_force, k_moment)
    jacobian = np.zeros(x.shape[:1] + index.shape[:1] + x.shape[1:])
    jacobian[:, np.arange(index.shape[0])[:, None], index] = slopes
    return values, jacobian


def reduced_law_values(c: np.ndarray, signs: np.ndarray, k_force: np.ndarray,
                       k_moment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(values (n, K), slopes (n, K, 4))`` of the law on each slot's fx, fy [N], mx, my [N m] ``c``
    (n, K, 4); the zero subgradient where a norm is exactly zero.
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
