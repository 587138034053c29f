"""Measurements of the long runs (:mod:`.runs`), from arrays alone: per step (constraint
violations of the pairs, health of the rotation coordinates), per revolution (maxima, values at
whole revolutions, work integrals), statistics (trends, first and last windows), the energy of
a free-spinning run, and the numerical damping of generalized-alpha.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from reference.scene.joint import PAIR_KIND

__all__ = ["WINDOW", "pair_violations", "rotation_health", "revolution_index", "per_revolution_max",
           "at_revolutions", "whole_revolutions", "linear_trend", "first_last", "window_size",
           "algorithmic_damping", "damping_coefficient", "energy_measures"]

# First/last window of revolutions compared (fewer in short runs: a quarter of the run).
WINDOW = 100


def pair_violations(pair_kinematics: dict[str, dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Per step, the largest violation over the four pairs at each constraint level.

    Position [m] and angle [rad] as :func:`cardan_exudyn.model.solve.constraint_violation` (marker
    distance, or distance of marker b from the axis for a cylindrical pair; misalignment of the
    axes). Velocity level: the constrained components of the relative velocity of the marker
    points [m/s] (all three for the revolute, those normal to the axis for a cylindrical pair)
    and of the relative angular velocity normal to the axis [rad/s]. Index-3 integration keeps
    the first pair at the Newton tolerance and leaves the second at O(h^2).
    """
    out: dict[str, np.ndarray] = {}
    for name, k in pair_kinematics.items():
        za = k["frame_a"][:, :, 2]
        zb = k["frame_b"][:, :, 2]
        d = k["pb"] - k["pa"]
        v = k["vb"] - k["va"]
        w = k["omega_b"] - k["omega_a"]
        w = w - np.einsum("ij,ij->i", w, za)[:, None] * za
        if PAIR_KIND[name] == "cylindrical":
            d = d - np.einsum("ij,ij->i", d, za)[:, None] * za
            v = v - np.einsum("ij,ij->i", v, za)[:, None] * za
        values = {"position_violation_m": np.linalg.norm(d, axis=1),
                  "angle_violation_rad": np.linalg.norm(np.cross(za, zb), axis=1),
                  "velocity_violation_m_s": np.linalg.norm(v, axis=1),
                  "angular_velocity_violation_rad_s": np.linalg.norm(w, axis=1)}
        for key, value in values.items():
            out[key] = np.maximum(out[key], value) if key in out else value
    return out


def rotation_health(kinds: Mapping[str, str], states: dict[str, dict[str, np.ndarray]],
                    n: int) -> dict[str, np.ndarray]:
    """Per step: orthogonality error of the bodies' rotation matrices (largest entry of
    ``A^T A - I`` over the three bodies), ``| |p| - 1 |`` of Euler-parameter nodes, ``|nu|`` of
    rotation-vector nodes, and the largest ``|psi|`` of the spider's and output's Tait-Bryan
    angles (NaN where the node type has none); ``kinds`` names each body's node type."""
    ortho = np.zeros(n)
    nan = np.full(n, np.nan)
    ep = nan.copy()
    rotvec = nan.copy()
    angles = nan.copy()
    for name, s in states.items():
        a = s["A"][:n]
        err = np.abs(np.einsum("nji,njk->nik", a, a) - np.eye(3)).max(axis=(1, 2))
        ortho = np.maximum(ortho, err)
        if name == "input":
            continue
        norm = np.linalg.norm(s["psi"][:n], axis=1)
        if kinds[name] == "EP":
            ep = np.fmax(ep, np.abs(norm - 1.0))
        elif kinds[name] == "RotVecLG":
            rotvec = np.fmax(rotvec, norm)
        else:
            angles = np.fmax(angles, np.abs(s["psi"][:n]).max(axis=1))
    return {"orthogonality_error": ortho, "ep_norm_error": ep, "rotvec_norm_max": rotvec,
            "max_abs_angle_rad": angles}


def revolution_index(theta: np.ndarray, revolutions: int) -> np.ndarray:
    """Revolution (1 ... revolutions) each row belongs to: row i ends a step inside revolution k
    when ``2 pi (k-1) < theta_i - theta_0 <= 2 pi k``; the initial row belongs to the first."""
    turned = np.abs(theta - theta[0]) / (2.0 * math.pi)
    return np.clip(np.ceil(turned - 1e-9), 1, revolutions).astype(int)


def per_revolution_max(values: np.ndarray, index: np.ndarray, revolutions: int) -> np.ndarray:
    """Largest value of each revolution (NaN-aware: all-NaN revolutions give NaN); rows with
    index 0 are left out."""
    out = np.full(revolutions, -np.inf)
    finite = np.isfinite(values) & (index >= 1)
    np.maximum.at(out, index[finite] - 1, values[finite])
    out[np.isinf(out)] = np.nan
    return out


def at_revolutions(values: np.ndarray, theta: np.ndarray, revolutions: int) -> np.ndarray:
    """``values`` interpolated (linearly in the input angle) at whole revolutions 0 ... n."""
    sign = 1.0 if theta[-1] >= theta[0] else -1.0
    th = sign * (theta - theta[0])
    return np.interp(2.0 * math.pi * np.arange(revolutions + 1), th, values)


def whole_revolutions(theta: np.ndarray) -> int:
    """Whole input revolutions turned; 1e-6 of a revolution short counts as whole (the input
    angle of a 2000-revolution run ends 7e-8 rad short of 2000 turns: the rounding of its update
    accumulates, ``input_angle_error_rad``; the step times themselves are exact multiples of dt,
    ``time_grid_error_s``)."""
    return int(math.floor(abs(theta[-1] - theta[0]) / (2.0 * math.pi) + 1e-6))


def linear_trend(x: np.ndarray, y: np.ndarray) -> dict[str, float]:
    """Least-squares line ``y = a + b x``: slope, its standard error, residual scatter."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    keep = np.isfinite(y)
    x = x[keep]
    y = y[keep]
    if x.size < 3:
        return {"slope": float("nan"), "slope_stderr": float("nan"), "scatter": float("nan")}
    xm = x - x.mean()
    sxx = float(xm @ xm)
    slope = float(xm @ (y - y.mean()) / sxx)
    resid = y - y.mean() - slope * xm
    scatter = float(np.sqrt(resid @ resid / (x.size - 2)))
    return {"slope": slope, "slope_stderr": scatter / math.sqrt(sxx), "scatter": scatter}


def first_last(y: np.ndarray, window: int) -> dict[str, float]:
    """Means of the first and last ``window`` values, their difference and its standard error."""
    y = np.asarray(y, float)
    a = y[:window]
    b = y[-window:]
    se = math.sqrt(np.var(a, ddof=1) / a.size + np.var(b, ddof=1) / b.size) if window > 1 else float("nan")
    return {"first_mean": float(np.mean(a)), "last_mean": float(np.mean(b)),
            "last_minus_first": float(np.mean(b) - np.mean(a)), "difference_stderr": se,
            "window": int(window)}


def window_size(revolutions: int) -> int:
    """Revolutions in the first and last windows compared: a quarter of the run, 2 to WINDOW."""
    return int(min(WINDOW, max(2, revolutions // 4)))


def algorithmic_damping(omega_h: float, rho: float) -> float:
    """Damping ratio of generalized-alpha on the undamped linear oscillator ``x'' = -Omega^2 x``.

    Chung-Hulbert parameters for the spectral radius at infinity ``rho`` (those of Exudyn's
    index-3 generalized-alpha): ``alpha_m = (2 rho - 1)/(rho + 1)``, ``alpha_f = rho/(rho + 1)``,
    ``gamma = 1/2 + alpha_f - alpha_m``, ``beta = (gamma + 1/2)^2 / 4``, in the two-acceleration
    form (Arnold and Bruls). The damping ratio of the physical root ``lambda`` of the one-step
    map is ``-ln|lambda| / arg(lambda)``; for small ``Omega h`` it is ``c(rho) (Omega h)^3``.
    """
    am = (2.0 * rho - 1.0) / (rho + 1.0)
    af = rho / (rho + 1.0)
    gamma = 0.5 + af - am
    beta = 0.25 * (gamma + 0.5) ** 2
    w2 = omega_h * omega_h  # step 1, frequency omega_h
    # state (x, v, a, acc): a the algorithmic acceleration, acc the physical one
    lhs = np.array([[0.0, 0.0, 1.0 - am, -(1.0 - af)], [1.0, 0.0, -beta, 0.0],
                    [0.0, 1.0, -gamma, 0.0], [w2, 0.0, 0.0, 1.0]])
    rhs = np.array([[0.0, 0.0, -am, af], [1.0, 1.0, 0.5 - beta, 0.0],
                    [0.0, 1.0, 1.0 - gamma, 0.0], [0.0, 0.0, 0.0, 0.0]])
    lam = np.linalg.eigvals(np.linalg.solve(lhs, rhs))
    root = lam[np.argmin(np.abs(lam - np.exp(1j * omega_h)))]
    return float(-math.log(abs(root)) / abs(np.angle(root)))


def damping_coefficient(rho: float) -> float:
    """``c(rho)`` of the small-step damping ratio ``c (Omega h)^3`` (evaluated at Omega h = 0.02)."""
    return algorithmic_damping(0.02, rho) / 0.02 ** 3


def energy_measures(theta: np.ndarray, energy: np.ndarray, revolutions: int) -> dict[str, Any]:
    """Relative energy at each whole revolution (``relative``), its drift over the run, the loss
    rate per revolution and the energy's range within the last revolution (relative)."""
    done = whole_revolutions(theta) if theta.size > 1 else 0
    done = min(done, revolutions)
    at = at_revolutions(energy, theta, done) if done >= 1 else energy[:1]
    relative = (at - at[0]) / at[0]
    out: dict[str, Any] = {"relative": relative, "completed_revolutions": done,
                           "initial_energy_j": float(energy[0])}
    out["relative_drift"] = float(relative[-1]) if done >= 1 else float("nan")
    half = done // 2
    if done >= 4:  # steady loss rate: line through the second half (the start-up excluded)
        k = np.arange(half, done + 1)
        trend = linear_trend(k, relative[half:])
        out["loss_per_revolution"] = -trend["slope"]
    else:
        out["loss_per_revolution"] = -out["relative_drift"] / done if done >= 1 else float("nan")
    if done >= 1:
        sign = 1.0 if theta[-1] >= theta[0] else -1.0
        turned = sign * (theta - theta[0])
        last = (turned >= 2.0 * math.pi * (done - 1)) & (turned <= 2.0 * math.pi * done)
        out["within_revolution_range"] = float(np.ptp(energy[last]) / abs(at[0]))
    return out
