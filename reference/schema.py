"""The result schema shared by every engine: one time table and one summary.

Table columns (SI units)
------------------------
``t`` [s]; ``theta_in``, ``theta_out`` [rad] (unwrapped, output measured about its own axis from
its yoke position at input angle 0); ``omega_in``, ``omega_out`` [rad/s];
``torque_in`` [N m], torque the drive applies to the input shaft about its axis;
``torque_out`` [N m], torque the output shaft applies to the load about the output axis
(the resisting torque); ``power_in = torque_in * omega_in``, ``power_out = torque_out * omega_out``
[W]; ``power_loss_<pair>`` [W] and their sum ``power_loss``; ``efficiency`` [-], the
instantaneous efficiency of eq. (18), ``1 - power_loss / power_in`` (NaN where power_in is 0);
``energy_kinetic``, ``energy_potential`` [J], mechanical energy of the three bodies (potential
energy zero at the joint centre).

Per pair, ``<pair>_fx, _fy, _fz`` [N] and ``<pair>_mx, _my, _mz`` [N m]: the force and moment that
body ``a`` of the pair exerts on body ``b`` (see :data:`reference.scene.PAIR_BODIES`), about the
pair's origin (on the axis, moving with body ``b`` when a pair with mounting errors slides), in
the pair frame (z along the pair axis) attached to body ``a``. The constraint
part excludes the applied friction; friction appears in ``<pair>_friction_torque`` [N m] and
``<pair>_friction_force`` [N] (on body b, about / along the pair axis), with the relative motion
``<pair>_omega_rel`` [rad/s] and ``<pair>_slide_rel`` [m/s] of b with respect to a.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference.scene import PAIR_NAMES

KINEMATIC_COLUMNS = ("t", "theta_in", "theta_out", "omega_in", "omega_out")
POWER_COLUMNS = ("torque_in", "torque_out", "power_in", "power_out", "power_loss", "efficiency",
                 "energy_kinetic", "energy_potential")
REACTION_SUFFIXES = ("fx", "fy", "fz", "mx", "my", "mz")
PAIR_SUFFIXES = REACTION_SUFFIXES + ("friction_torque", "friction_force", "omega_rel", "slide_rel")


def pair_columns(pair: str) -> list[str]:
    return [f"{pair}_{s}" for s in PAIR_SUFFIXES]


def table_columns() -> list[str]:
    """All columns of the time table, in order."""
    cols = list(KINEMATIC_COLUMNS) + list(POWER_COLUMNS)
    cols += [f"power_loss_{p}" for p in PAIR_NAMES]
    for p in PAIR_NAMES:
        cols += pair_columns(p)
    return cols


STATUS_OK = "ok"
STATUS_NO_CLOSURE = "loop_does_not_close"  # mounting errors the loop cannot be assembled with


@dataclass
class Result:
    """What every engine returns: a time table (or None) and a summary dictionary."""

    table: Any  # pandas.DataFrame or None
    summary: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.summary.get("status") == STATUS_OK


def whole_revolution_window(theta_in: np.ndarray, skip_revolutions: float) -> tuple[float, float, int]:
    """Input-angle window [theta_0, theta_1] spanning whole revolutions after the skipped ones.

    Returns ``(theta_0, theta_1, n)`` with ``theta_1 = theta_0 + 2 pi n`` in the direction of
    motion; ``n`` is 0 when less than one whole revolution is available.
    """
    sign = 1.0 if theta_in[-1] >= theta_in[0] else -1.0
    theta_0 = theta_in[0] + sign * 2.0 * math.pi * skip_revolutions
    travelled = sign * (theta_in[-1] - theta_0)
    # tolerate rounding at the end of a span chosen as a whole number of revolutions
    n = int(math.floor(travelled / (2.0 * math.pi) + 1e-9))
    return theta_0, theta_0 + sign * 2.0 * math.pi * n, max(n, 0)


def _cumulative(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    out = np.zeros_like(t)
    out[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))
    return out


def window_integral(y: np.ndarray, t: np.ndarray, theta: np.ndarray,
                    theta_0: float, theta_1: float) -> float:
    """Trapezoidal integral of y dt between the instants where theta passes theta_0 and theta_1.

    ``theta`` must be monotonic; the ends are interpolated linearly in theta.
    """
    cum = _cumulative(np.asarray(y, float), np.asarray(t, float))
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th, cum, theta_0, theta_1 = -th, cum, -theta_0, -theta_1
    return float(np.interp(theta_1, th, cum) - np.interp(theta_0, th, cum))


def window_duration(t: np.ndarray, theta: np.ndarray, theta_0: float, theta_1: float) -> float:
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th, theta_0, theta_1 = -th, -theta_0, -theta_1
    return float(np.interp(theta_1, th, t) - np.interp(theta_0, th, t))


def mean_values(columns: dict[str, np.ndarray], skip_revolutions: float) -> dict[str, Any]:
    """Mean values over whole input revolutions.

    ``mean_efficiency`` is one minus lost energy over input energy; ``mean_instantaneous_efficiency``
    the time average of eq. (18) over the same window; ``work_ratio`` is output work over input
    work (the rig's definition; it differs from ``mean_efficiency`` by the change of mechanical
    energy and, without friction, measures it).
    """
    t = columns["t"]
    theta = columns["theta_in"]
    if np.any(np.diff(theta) * np.sign(theta[-1] - theta[0]) < 0):
        return {"revolutions": 0, "mean_status": "input angle is not monotonic"}
    theta_0, theta_1, n = whole_revolution_window(theta, skip_revolutions)
    if n < 1:
        return {"revolutions": 0, "mean_status": "less than one whole revolution after skipping"}
    w_in = window_integral(columns["power_in"], t, theta, theta_0, theta_1)
    w_out = window_integral(columns["power_out"], t, theta, theta_0, theta_1)
    w_loss = window_integral(columns["power_loss"], t, theta, theta_0, theta_1)
    duration = window_duration(t, theta, theta_0, theta_1)
    eta = columns["efficiency"]
    finite = np.isfinite(eta)
    mean_eta_inst = (window_integral(np.where(finite, eta, 0.0), t, theta, theta_0, theta_1)
                     / duration) if np.all(finite) else float("nan")
    out = {
        "revolutions": n,
        "window_start_s": window_duration(t, theta, theta[0], theta_0) + float(t[0]),
        "window_duration_s": duration,
        "input_work": w_in,
        "output_work": w_out,
        "loss_work": w_loss,
        "mean_efficiency": 1.0 - w_loss / w_in if w_in != 0 else float("nan"),
        "mean_instantaneous_efficiency": mean_eta_inst,
        "work_ratio": w_out / w_in if w_in != 0 else float("nan"),
        "mean_torque_in": w_in / (theta_1 - theta_0),
        "mean_speed_in": (theta_1 - theta_0) / duration,
    }
    for p in PAIR_NAMES:
        key = f"power_loss_{p}"
        if key in columns:
            out[f"loss_work_{p}"] = window_integral(columns[key], t, theta, theta_0, theta_1)
        if f"{p}_friction_force" in columns and f"{p}_slide_rel" in columns:  # axial friction's part
            sliding = -np.asarray(columns[f"{p}_friction_force"]) * np.asarray(columns[f"{p}_slide_rel"])
            out[f"loss_work_{p}_sliding"] = window_integral(sliding, t, theta, theta_0, theta_1)
    return out


def instantaneous_efficiency(power_in: np.ndarray, power_loss: np.ndarray) -> np.ndarray:
    """Eq. (18): ``1 - P_loss / P_in``, NaN where ``P_in`` is exactly zero."""
    p_in = np.asarray(power_in, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(p_in != 0.0, 1.0 - np.asarray(power_loss, float) / p_in, np.nan)
