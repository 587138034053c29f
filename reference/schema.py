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
body ``a`` of the pair exerts on body ``b`` (see :data:`reference.joint.PAIR_BODIES`), about the
pair's origin (on the axis, moving with body ``b`` when a pair with mounting errors slides), in
the pair frame (z along the pair axis) attached to body ``a``. The constraint
part excludes the applied friction; friction appears in ``<pair>_friction_torque`` [N m] and
``<pair>_friction_force`` [N] (on body b, about / along the pair axis), with the relative motion
``<pair>_omega_rel`` [rad/s] and ``<pair>_slide_rel`` [m/s] of b with respect to a.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from enum import Enum
from typing import Any

import numpy as np

from reference.joint import PAIR_NAMES

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


SCHEMA_VERSION = 2
"""Version of the summary written to disk (``summary.json``, sweep records): 2 adds
``schema_version`` and writes every common key (``null`` where a run has no value)."""


class Status(str, Enum):
    """How a run ended. Only :attr:`OK` carries mean values; every other status has a ``reason``.

    A ``str`` enum: ``Status.OK == "ok"`` and JSON writes the plain value.
    """

    OK = "ok"
    SELF_LOCKING = "self_locking"  # friction has no consistent value (loop gain >= 1)
    INTEGRATION_FAILURE = "integration_failure"  # the solver stopped (Newton, step size)
    DIVERGED = "diverged"  # the solver finished but produced non-finite values
    INCOMPLETE = "incomplete"  # a torque drive did not turn the asked revolutions in time
    NO_WHOLE_REVOLUTION = "no_whole_revolution"  # nothing to average over after the skip
    LOOP_DOES_NOT_CLOSE = "loop_does_not_close"  # mounting errors the loop cannot assemble with
    CONSTRAINT_VIOLATED = "constraint_violated"  # a soft constraint (MuJoCo) left its tolerance

    def __str__(self) -> str:
        return self.value


class OptionsError(ValueError):
    """An engine's options are out of range or of the wrong type (the message names the option)."""


MEAN_KEYS = ("revolutions", "window_start_s", "window_duration_s", "input_work", "output_work",
             "loss_work", "mean_efficiency", "mean_instantaneous_efficiency", "work_ratio",
             "mean_torque_in", "mean_speed_in")


@dataclass
class Summary:
    """What every engine reports about a run, with the same fields for every engine.

    Modelled on scipy's ``OdeResult``: the outcome (:attr:`status`, :attr:`reason`), the solution's
    mean values over whole input revolutions (``None`` unless the status is ``ok``; definitions
    in :func:`mean_values`), the cost counters next to them (``None`` where an engine has no
    such counter), and engine-specific diagnostics in :attr:`extras` (Exudyn's ``friction``,
    the reference's ``quadrature``, ...).

    Attributes
    ----------
    status : Status
    reason : str
        Why the run did not end ``ok`` (empty when it did).
    engine, engine_version : str
    scene, options : dict
        The scene as :func:`reference.scene.scene_to_dict` gives it, and the engine's options.
    wall_time_s : float
        Wall time of the whole run [s].
    dt : float or None
        Time step [s] (the reference engine: the table's sample spacing).
    dt_choice : str or None
        How the step was chosen.
    steps, newton_iterations, jacobian_evaluations, ode_evaluations : int or None
        Cost counters: time steps, Newton iterations and Jacobian evaluations (Exudyn), right-hand
        side evaluations of an ODE (the reference engine's torque-driven scenes).
    max_constraint_violation_m, max_constraint_violation_rad : float or None
        Largest violation of the pair constraints over the run [m], [rad].
    max_friction_loop_gain : float or None
        Largest gain of the friction feedback loop (>= 1: no consistent friction).
    revolutions : int
        Whole input revolutions averaged over.
    window_start_s, window_duration_s : float or None
        The averaging window [s].
    input_work, output_work, loss_work : float or None
        Works over the window [J].
    mean_efficiency : float or None
        One minus lost over input work, the headline number.
    mean_instantaneous_efficiency : float or None
        Time average of eq. (18) over the window.
    work_ratio : float or None
        Output over input work.
    mean_torque_in : float or None
        Input work over input angle [N m].
    mean_speed_in : float or None
        Input angle over time [rad/s].
    pair_loss_work : dict[str, float]
        Loss work per pair [J] (``loss_work_<pair>`` on disk).
    pair_sliding_loss_work : dict[str, float]
        Its part from axial friction [J] (``loss_work_<pair>_sliding`` on disk).
    extras : dict
        Engine-specific diagnostics, written at the top level of the JSON.
    """

    status: Status
    reason: str = ""
    engine: str = ""
    engine_version: str = ""
    scene: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = math.nan
    dt: float | None = None
    dt_choice: str | None = None
    steps: int | None = None
    newton_iterations: int | None = None
    jacobian_evaluations: int | None = None
    ode_evaluations: int | None = None
    max_constraint_violation_m: float | None = None
    max_constraint_violation_rad: float | None = None
    max_friction_loop_gain: float | None = None
    revolutions: int = 0
    window_start_s: float | None = None
    window_duration_s: float | None = None
    input_work: float | None = None
    output_work: float | None = None
    loss_work: float | None = None
    mean_efficiency: float | None = None
    mean_instantaneous_efficiency: float | None = None
    work_ratio: float | None = None
    mean_torque_in: float | None = None
    mean_speed_in: float | None = None
    pair_loss_work: dict[str, float] = field(default_factory=dict)
    pair_sliding_loss_work: dict[str, float] = field(default_factory=dict)
    extras: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.status = Status(self.status)

    @property
    def success(self) -> bool:
        """True when the run ended ``ok`` (its means are defined)."""
        return self.status is Status.OK

    def set_means(self, means: Mapping[str, Any]) -> None:
        """Take the keys of :func:`mean_values` (or the same keys from another integration)."""
        for key, value in means.items():
            if key in MEAN_KEYS:
                setattr(self, key, value)
            elif key.startswith("loss_work_") and key.endswith("_sliding"):
                self.pair_sliding_loss_work[key[len("loss_work_"):-len("_sliding")]] = value
            elif key.startswith("loss_work_"):
                self.pair_loss_work[key[len("loss_work_"):]] = value
            else:
                self.extras[key] = value

    def whole_revolution_means(self, columns: Mapping[str, np.ndarray],
                               skip_revolutions: float) -> dict[str, Any] | None:
        """:func:`mean_values` of ``columns``; None, with status ``no_whole_revolution`` and the
        reason, when there is no whole revolution to average over (every engine's rule)."""
        means = mean_values(columns, skip_revolutions)
        if means["revolutions"] < 1:
            self.fail(Status.NO_WHOLE_REVOLUTION, means["mean_status"])
            return None
        return means

    def clear_means(self) -> None:
        """Forget the means (a run that turned out not ``ok`` after averaging)."""
        for key in MEAN_KEYS:
            setattr(self, key, 0 if key == "revolutions" else None)
        self.pair_loss_work.clear()
        self.pair_sliding_loss_work.clear()

    def fail(self, status: Status | str, reason: str) -> None:
        """End the run with ``status`` and ``reason`` and forget its means."""
        self.status, self.reason = Status(status), reason
        self.clear_means()

    def to_dict(self) -> dict[str, Any]:
        """The JSON shape written to disk: flat keys, ``schema_version`` first."""
        out: dict[str, Any] = {"schema_version": SCHEMA_VERSION}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "status":
                out["status"] = value.value
            elif f.name == "pair_loss_work":
                out.update({f"loss_work_{p}": v for p, v in value.items()})
            elif f.name == "pair_sliding_loss_work":
                out.update({f"loss_work_{p}_sliding": v for p, v in value.items()})
            elif f.name == "extras":
                out.update(value)
            else:
                out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Summary:
        """Inverse of :meth:`to_dict` (also reads version-1 summaries, which had no version)."""
        names = {f.name for f in fields(cls)} - {"pair_loss_work", "pair_sliding_loss_work", "extras"}
        summary = cls(status=Status(data["status"]))
        for key, value in data.items():
            if key == "schema_version":
                continue
            if key in names:
                setattr(summary, key, value)
            else:
                summary.set_means({key: value})
        summary.status = Status(summary.status)
        return summary


@dataclass
class Result:
    """What every engine returns: a time table (or None) and a :class:`Summary`.

    Attributes
    ----------
    table : pandas.DataFrame or None
        The columns of :func:`table_columns` (and engine extras), every ``record.every``-th row;
        None when the scene does not record the time series or the run failed.
    summary : Summary
    """

    table: Any  # pandas.DataFrame or None
    summary: Summary

    @property
    def status(self) -> Status:
        return self.summary.status

    @property
    def success(self) -> bool:
        """True when the run ended ``ok``."""
        return self.summary.success

    @property
    def message(self) -> str:
        """Why the run did not end ``ok`` (empty when it did)."""
        return self.summary.reason

    @property
    def mean_efficiency(self) -> float | None:
        """One minus lost over input work over whole revolutions (None unless ``ok``)."""
        return self.summary.mean_efficiency



def result_table(columns: Mapping[str, np.ndarray], every: int, extra: tuple[str, ...] = ()) -> Any:
    """The time table of a result: the schema's columns (and an engine's ``extra`` ones), every
    ``every``-th row, as a pandas DataFrame."""
    import pandas as pd  # pandas takes ~0.5 s to import; only a recorded table needs it

    return pd.DataFrame({c: columns[c][::every] for c in table_columns() + list(extra)})


def after_revolutions(theta_in: np.ndarray, skip_revolutions: float) -> np.ndarray:
    """Mask of the rows after the first ``skip_revolutions`` of the input angle (either sense)."""
    theta = np.asarray(theta_in, float)
    return np.abs(theta - theta[0]) >= 2.0 * math.pi * skip_revolutions


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


def cumulative(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Trapezoidal integral of ``y dt`` from the first row to each row."""
    out = np.zeros_like(t)
    out[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))
    return out


def window_integral(y: np.ndarray, t: np.ndarray, theta: np.ndarray,
                    theta_0: float, theta_1: float) -> float:
    """Trapezoidal integral of y dt between the instants where theta passes theta_0 and theta_1.

    ``theta`` must be monotonic; the ends are interpolated linearly in theta.
    """
    cum = cumulative(np.asarray(y, float), np.asarray(t, float))
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
