"""Means over whole input revolutions: the window, its integrals (trapezoid except across friction's
sign jumps, :mod:`reference.results.quadrature`) and the summary's mean values in the direction the
power flows (the paper's eq. (18) assumes the input is the source).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from reference.results.power_flow import PowerFlow, classify_works, likely_cause, sign_changes, source_power
from reference.results.quadrature import jump_breaks, segment_integrals
from reference.scene.joint import PAIR_NAMES

__all__ = ["after_revolutions", "whole_revolution_window", "cumulative", "window_integral",
           "window_duration", "mean_values", "flow_means", "window_rows", "pair_loss_works",
           "flow_time_average"]


def after_revolutions(theta_in: np.ndarray, skip_revolutions: float) -> np.ndarray:
    """Mask of the rows past ``skip_revolutions`` [-] input revolutions (either sense) of ``theta_in`` [rad].
    """
    theta = np.asarray(theta_in, float)
    return np.abs(theta - theta[0]) >= 2.0 * math.pi * skip_revolutions


def whole_revolution_window(theta_in: np.ndarray, skip_revolutions: float) -> tuple[float, float, int]:
    """``(theta_0, theta_1, n)``: the input-angle window [rad] of ``n`` whole revolutions after
    ``skip_revolutions`` of the monotonic ``theta_in`` [rad] (``n = 0`` when less than one remains).
    """
    sign = 1.0 if theta_in[-1] >= theta_in[0] else -1.0
    theta_0 = theta_in[0] + sign * 2.0 * math.pi * skip_revolutions
    travelled = sign * (theta_in[-1] - theta_0)
    # tolerate rounding at the end of a span chosen as a whole number of revolutions
    n = int(math.floor(travelled / (2.0 * math.pi) + 1e-9))
    return theta_0, theta_0 + sign * 2.0 * math.pi * n, max(n, 0)


def cumulative(y: np.ndarray, t: np.ndarray, breaks: Sequence[tuple[int, int, float]] = ()) -> np.ndarray:
    """Running integral of ``y dt`` over time ``t`` [s], 0 at the first row: trapezoidal except across
    the friction jumps ``breaks`` (:func:`reference.results.quadrature.jump_breaks`).
    """
    out = np.zeros(np.shape(t), float)
    out[1:] = np.cumsum(segment_integrals(y, t, breaks))
    return out


def window_integral(y: np.ndarray, t: np.ndarray, theta: np.ndarray,
                    theta_0: float, theta_1: float,
                    breaks: Sequence[tuple[int, int, float]] = ()) -> float:
    """Integral of ``y dt`` between the instants the monotonic ``theta`` [rad] passes ``theta_0`` and
    ``theta_1`` (interpolated linearly in ``theta``), across the friction jumps ``breaks``.
    """
    cum = cumulative(np.asarray(y, float), np.asarray(t, float), breaks)
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th = -th
        theta_0 = -theta_0
        theta_1 = -theta_1
    return float(np.interp(theta_1, th, cum) - np.interp(theta_0, th, cum))


def window_duration(t: np.ndarray, theta: np.ndarray, theta_0: float, theta_1: float) -> float:
    """Time [s] between the instants the monotonic ``theta`` [rad] passes ``theta_0`` and ``theta_1``."""
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th = -th
        theta_0 = -theta_0
        theta_1 = -theta_1
    return float(np.interp(theta_1, th, t) - np.interp(theta_0, th, t))


def mean_values(columns: Mapping[str, np.ndarray], skip_revolutions: float,
                works: Mapping[str, float] | None = None) -> dict[str, Any]:
    """Mean values over whole input revolutions, in the direction the power flows.

    ``mean_efficiency`` is one minus lost over supplied work, ``mean_instantaneous_efficiency`` the time
    average of eq. (18), ``work_ratio`` received over supplied work (the rig's definition; it differs
    from ``mean_efficiency`` by the change of mechanical energy).

    Parameters
    ----------
    columns : mapping
        The schema's columns (at least time, input angle, powers, efficiency and energies).
    skip_revolutions : float
        Input revolutions left out at the start [-].
    works : mapping, optional
        ``input_work``, ``output_work``, ``loss_work`` [J] (and ``loss_work_<pair>``, ...) of the window
        from a better quadrature than the table's trapezoid; every mean is taken from them.

    Returns
    -------
    dict
        The summary keys (:data:`reference.results.summary.MEAN_KEYS`, ``FLOW_KEYS``,
        ``loss_work_<pair>``), ``warnings`` and ``unphysical`` (empty when the means are possible);
        ``revolutions`` 0 and ``mean_status`` when there is no whole revolution.
    """
    t = columns["t"]
    theta = columns["theta_in"]
    if np.any(np.diff(theta) * np.sign(theta[-1] - theta[0]) < 0):
        return {"revolutions": 0, "mean_status": "input angle is not monotonic"}
    theta_0, theta_1, n = whole_revolution_window(theta, skip_revolutions)
    if n < 1:
        return {"revolutions": 0, "mean_status": "less than one whole revolution after skipping"}

    breaks = jump_breaks(columns)  # friction's sign jumps: each side integrated on its own

    def integral(y: np.ndarray) -> float:
        return window_integral(y, t, theta, theta_0, theta_1, breaks)

    duration = window_duration(t, theta, theta_0, theta_1)
    out: dict[str, Any] = {
        "revolutions": n,
        "window_start_s": window_duration(t, theta, theta[0], theta_0) + float(t[0]),
        "window_duration_s": duration,
        "input_work": integral(columns["power_in"]),
        "output_work": integral(columns["power_out"]),
        "loss_work": integral(columns["power_loss"]),
        **pair_loss_works(columns, integral),
        **(works or {}),
    }
    out.update(mean_torque_in=out["input_work"] / (theta_1 - theta_0),
               mean_speed_in=(theta_1 - theta_0) / duration)
    out.update(flow_means(columns, out, integral, duration, window_rows(theta, theta_0, theta_1)))
    return out


def flow_means(columns: Mapping[str, np.ndarray], works: Mapping[str, float], integral: Any,
               duration: float, inside: np.ndarray) -> dict[str, Any]:
    """The means that depend on the power flow's direction, from the window's ``works`` [J],
    ``integral(y)``, ``duration`` [s] and rows ``inside``: efficiency, work ratio, time average, flow,
    reversals, ``warnings`` and ``unphysical``.
    """
    w_in = works["input_work"]
    w_out = works["output_work"]
    w_loss = works["loss_work"]
    energy = np.asarray(columns["energy_kinetic"]) + np.asarray(columns["energy_potential"])
    scale = integral(np.abs(columns["power_in"]) + np.abs(columns["power_out"])
                     + np.abs(columns["power_loss"])) + float(np.max(np.abs(energy[inside])))
    verdict = classify_works(w_in, w_out, w_loss, scale)
    flow = None if verdict.power_flow is None else verdict.power_flow.value
    average, reversals, note = flow_time_average(columns, flow, inside, integral, duration)
    out = {"mean_efficiency": verdict.mean_efficiency, "work_ratio": verdict.work_ratio,
           "mean_instantaneous_efficiency": average, "power_flow": flow, "power_reversals": reversals,
           "warnings": [m for m in (verdict.note, note) if m], "unphysical": ""}
    if verdict.problem and np.isfinite(verdict.excess_work):
        # dE over the window (the integral of its rate: good enough for the diagnosis)
        change = float(integral(np.gradient(energy, np.asarray(columns["t"], float))))
        cause = likely_cause(verdict.excess_work, change, w_in - w_out - w_loss - change)
        out["unphysical"] = f"{verdict.problem}: {cause}"
    elif verdict.problem:
        out["unphysical"] = verdict.problem
    return out


def window_rows(theta: np.ndarray, theta_0: float, theta_1: float) -> np.ndarray:
    """Mask of the rows between ``theta_0`` and ``theta_1`` [rad] plus the row bracketing each end."""
    sign = 1.0 if theta_1 >= theta_0 else -1.0
    th = sign * np.asarray(theta, float)
    lo = sign * theta_0
    hi = sign * theta_1
    first = max(int(np.searchsorted(th, lo, side="right")) - 1, 0)
    last = min(int(np.searchsorted(th, hi, side="left")), th.size - 1)
    mask = np.zeros(th.size, bool)
    mask[first:last + 1] = True
    return mask


def pair_loss_works(columns: Mapping[str, np.ndarray], integral: Any) -> dict[str, float]:
    """Each pair's ``loss_work_<pair>`` and axial-friction part ``loss_work_<pair>_sliding`` [J]."""
    out = {}
    for p in PAIR_NAMES:
        key = f"power_loss_{p}"
        if key in columns:
            out[f"loss_work_{p}"] = integral(columns[key])
        if f"{p}_friction_force" in columns and f"{p}_slide_rel" in columns:  # axial friction's part
            sliding = -np.asarray(columns[f"{p}_friction_force"]) * np.asarray(columns[f"{p}_slide_rel"])
            out[f"loss_work_{p}_sliding"] = integral(sliding)
    return out


def flow_time_average(columns: Mapping[str, np.ndarray], flow: str | None, inside: np.ndarray,
                      integral: Any, duration: float) -> tuple[float | None, int | None, str]:
    """``(average, reversals, note)``: time average of eq. (18), ``1 - P_loss / P_src`` with
    ``P_src = P_in`` or ``-P_out`` by ``flow``, over the rows ``inside``.

    Defined only when ``P_src > 0`` at every row (it has poles where ``P_src`` changes sign) and
    reported only in [0, 1]; else ``average`` is None and ``note`` says why.
    """
    if flow is None:
        return None, None, ""
    p_src = source_power(flow, columns["power_in"], columns["power_out"])[inside]
    reversals = sign_changes(p_src)
    if flow == PowerFlow.NONE:
        return None, reversals, "the time average of eq. (18) is undefined: no shaft takes net work"
    if not np.all(p_src > 0.0):
        what = (f"changes sign {reversals} times within the window (power flows back for part of "
                "the time)" if reversals else "reaches zero within the window")
        return None, reversals, f"the source power {what}: the time average of eq. (18) is undefined"
    src = source_power(flow, columns["power_in"], columns["power_out"])
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = np.where(src != 0.0, 1.0 - np.asarray(columns["power_loss"], float) / src, 0.0)
    average = integral(eta) / duration
    if not 0.0 <= average <= 1.0:
        return None, reversals, (f"the time average of eq. (18), {average:.6g}, is outside [0, 1]: "
                                 "not reported")
    return average, reversals, ""

