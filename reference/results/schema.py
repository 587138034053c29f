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

The summary's means are those of the direction power flows over the window
(:mod:`reference.results.power_flow`): ``power_flow`` says which; the paper's eq. (18) and its time average
assume the input is the source.

Per pair, ``<pair>_fx, _fy, _fz`` [N] and ``<pair>_mx, _my, _mz`` [N m]: the force and moment that
body ``a`` of the pair exerts on body ``b`` (see :data:`reference.scene.joint.PAIR_BODIES`), about the
pair's origin (on the axis, moving with body ``b`` when a pair with mounting errors slides), in
the pair frame (z along the pair axis) attached to body ``a``. The constraint
part excludes the applied friction; friction appears in ``<pair>_friction_torque`` [N m] and
``<pair>_friction_force`` [N] (on body b, about / along the pair axis), with the relative motion
``<pair>_omega_rel`` [rad/s] and ``<pair>_slide_rel`` [m/s] of b with respect to a.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from enum import Enum
from typing import Any

import numpy as np

from reference.results.power_flow import PowerFlow, classify_works, likely_cause, sign_changes, source_power
from reference.results.quadrature import jump_breaks, segment_integrals
from reference.scene.joint import PAIR_NAMES

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


SCHEMA_VERSION = 3
"""Version of the summary written to disk (``summary.json``, sweep records): 2 adds
``schema_version`` and writes every common key (``null`` where a run has no value); 3 adds
``power_flow``, ``power_reversals``, ``warnings``, ``efficiency_error_estimate`` and
``accuracy_met``, takes the efficiencies in the direction the
power flows, and never writes one outside [0, 1] with status ``ok`` (status ``unphysical``).
:meth:`Summary.from_dict` reads 1 and 2 and applies version 3's rules to their works."""


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
    UNPHYSICAL = "unphysical"  # means no physical run can have (an efficiency outside [0, 1])

    def __str__(self) -> str:
        return self.value


class OptionsError(ValueError):
    """An engine's options are out of range or of the wrong type (the message names the option)."""


MEAN_KEYS = ("revolutions", "window_start_s", "window_duration_s", "input_work", "output_work",
             "loss_work", "mean_efficiency", "mean_instantaneous_efficiency", "work_ratio",
             "mean_torque_in", "mean_speed_in")
FLOW_KEYS = ("power_flow", "power_reversals")
"""Keys of the power flow over the window (:mod:`reference.results.power_flow`), set and cleared with the means."""


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
        The scene as :func:`reference.scene.mapping.scene_to_dict` gives it, and the engine's options.
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
    efficiency_error_estimate : float or None
        The run's a-posteriori estimate of the absolute error of ``mean_efficiency`` [-] (Exudyn:
        Richardson from a companion run at a coarser step; reference: its quadrature's error
        estimate); None where an engine gives none or the run did not end ``ok``.
    accuracy_met : bool or None
        Whether that estimate is within the scene's ``numerics.accuracy`` (None without an
        estimate); ``cardan run`` exits 5 when it is False (``docs/accuracy.md``).
    revolutions : int
        Whole input revolutions averaged over.
    window_start_s, window_duration_s : float or None
        The averaging window [s].
    input_work, output_work, loss_work : float or None
        Works over the window [J].
    mean_efficiency : float or None
        One minus lost over supplied work, the headline number, in [0, 1]: over the input work
        when power flows from the input to the output (the paper's), over the work the output
        supplies (``-output_work``) when it flows the other way, 0 when no shaft takes net work,
        None (with a warning) when no work is transmitted or lost.
    mean_instantaneous_efficiency : float or None
        Time average of eq. (18) over the window, in [0, 1], for the direction of ``power_flow``
        (``-power_out`` the source power when it is ``output_to_input``); None, with a warning,
        where it is not defined: the source power changes sign within the window, or the average
        falls outside [0, 1].
    work_ratio : float or None
        Received over supplied work: output over input work when power flows from the input.
    mean_torque_in : float or None
        Input work over input angle [N m].
    mean_speed_in : float or None
        Input angle over time [rad/s].
    power_flow : str or None
        ``input_to_output``, ``output_to_input`` or ``none`` (no shaft takes net work), from the
        signs of the window's works (:class:`reference.results.power_flow.PowerFlow`).
    power_reversals : int or None
        How often the source power changes sign within the window (table rows).
    pair_loss_work : dict[str, float]
        Loss work per pair [J] (``loss_work_<pair>`` on disk).
    pair_sliding_loss_work : dict[str, float]
        Its part from axial friction [J] (``loss_work_<pair>_sliding`` on disk).
    warnings : list of str
        What a reader of the means must know (power flowing backwards, an undefined mean).
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
    efficiency_error_estimate: float | None = None
    accuracy_met: bool | None = None
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
    power_flow: str | None = None
    power_reversals: int | None = None
    pair_loss_work: dict[str, float] = field(default_factory=dict)
    pair_sliding_loss_work: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
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
            if key in MEAN_KEYS or key in FLOW_KEYS:
                setattr(self, key, value)
            elif key == "warnings":
                self.warn(*value)
            elif key.startswith("loss_work_") and key.endswith("_sliding"):
                self.pair_sliding_loss_work[key[len("loss_work_"):-len("_sliding")]] = value
            elif key.startswith("loss_work_"):
                self.pair_loss_work[key[len("loss_work_"):]] = value
            else:
                self.extras[key] = value

    def whole_revolution_means(self, columns: Mapping[str, np.ndarray], skip_revolutions: float,
                               works: Mapping[str, float] | None = None) -> dict[str, Any] | None:
        """:func:`mean_values` of ``columns`` (``works``: see there); None, with the status and
        reason, when there is no whole revolution to average over (``no_whole_revolution``) or
        the means are impossible (``unphysical``): every engine's rules. Its warnings are added
        to :attr:`warnings` either way."""
        means = mean_values(columns, skip_revolutions, works)
        if means["revolutions"] < 1:
            self.fail(Status.NO_WHOLE_REVOLUTION, means["mean_status"])
            return None
        self.warn(*means.pop("warnings"))
        problem = means.pop("unphysical")
        if problem:
            self.fail(Status.UNPHYSICAL, problem)
            return None
        return means

    def warn(self, *messages: str) -> None:
        """Add ``messages`` to :attr:`warnings` (each once)."""
        self.warnings.extend(m for m in dict.fromkeys(messages) if m not in self.warnings)

    def clear_means(self) -> None:
        """Forget the means (a run that turned out not ``ok`` after averaging)."""
        for key in MEAN_KEYS + FLOW_KEYS:
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
        """Inverse of :meth:`to_dict`; also reads versions 1 (no version key) and 2, whose
        efficiencies it takes again from their works by version 3's rules (:meth:`upgrade`)."""
        names = {f.name for f in fields(cls)} - {"pair_loss_work", "pair_sliding_loss_work", "extras"}
        summary = cls(status=Status(data["status"]))
        for key, value in data.items():
            if key == "schema_version":
                continue
            if key in names:
                setattr(summary, key, list(value) if key == "warnings" else value)
            else:
                summary.set_means({key: value})
        summary.status = Status(summary.status)
        if data.get("schema_version", 1) < 3:
            summary.upgrade()
        return summary

    def upgrade(self) -> None:
        """Version 3's rules on a version 1 or 2 summary that is ``ok`` and has its three works:
        the power flow and the efficiencies of its direction; ``unphysical`` where they are out
        of [0, 1]. The time average of eq. (18) is kept only where it is in [0, 1] (the table
        that would say whether the source power changed sign is not in a summary)."""
        works = (self.input_work, self.output_work, self.loss_work)
        if not self.success or any(w is None for w in works):
            return
        verdict = classify_works(*works)
        if verdict.problem:
            self.fail(Status.UNPHYSICAL, verdict.problem)
            return
        self.power_flow = None if verdict.power_flow is None else verdict.power_flow.value
        self.mean_efficiency, self.work_ratio = verdict.mean_efficiency, verdict.work_ratio
        self.warn(*[verdict.note] if verdict.note else [])
        eta = self.mean_instantaneous_efficiency
        if eta is not None and not (verdict.power_flow == PowerFlow.INPUT_TO_OUTPUT and 0.0 <= eta <= 1.0):
            self.mean_instantaneous_efficiency = None
            self.warn(f"the time average of eq. (18) read from a version-2 summary ({eta:.6g}) "
                      "is not reported: it may span a reversal of the power flow")


class DeferredTable:
    """The columns of a time table, turned into a pandas DataFrame only when someone reads it.

    Why: importing pandas costs about 0.4 s, ten times a short run's solve; a run whose table
    nobody writes or returns should not pay it.
    """

    def __init__(self, columns: Mapping[str, np.ndarray], every: int, names: list[str]) -> None:
        self._columns = {c: columns[c][::every] for c in names}

    def build(self) -> Any:
        """The table as a pandas DataFrame, every ``every``-th row."""
        import pandas as pd  # import cost: see the class docstring

        return pd.DataFrame(self._columns)


class Result:
    """What every engine returns: a time table (or None) and a :class:`Summary`.

    Parameters
    ----------
    table : pandas.DataFrame, DeferredTable or None
        The columns of :func:`table_columns` (and engine extras), every ``record.every``-th row;
        None when the scene does not record the time series or the run failed. A
        :class:`DeferredTable` is built on first access of :attr:`table`.
    summary : Summary
    """

    __slots__ = ("_table", "summary")

    def __init__(self, table: Any, summary: Summary) -> None:
        self._table = table
        self.summary = summary

    def __repr__(self) -> str:
        return f"Result(status={self.summary.status.value!r}, table={self.has_table})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Result):
            return NotImplemented
        return self.summary == other.summary and self.table is other.table

    @property
    def table(self) -> Any:
        """The time table (pandas.DataFrame) or None."""
        if isinstance(self._table, DeferredTable):
            self._table = self._table.build()
        return self._table

    @table.setter
    def table(self, value: Any) -> None:
        self._table = value

    @property
    def has_table(self) -> bool:
        """True when the run recorded a time table (without building it)."""
        return self._table is not None

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
    ``every``-th row, built as a pandas DataFrame when first read (:class:`DeferredTable`)."""
    return DeferredTable(columns, every, table_columns() + list(extra))


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


def cumulative(y: np.ndarray, t: np.ndarray, breaks: Sequence[tuple[int, int, float]] = ()) -> np.ndarray:
    """Integral of ``y dt`` from the first row to each row: trapezoidal, except across the
    friction jumps ``breaks`` (:func:`reference.results.quadrature.jump_breaks`)."""
    out = np.zeros(np.shape(t), float)
    out[1:] = np.cumsum(segment_integrals(y, t, breaks))
    return out


def window_integral(y: np.ndarray, t: np.ndarray, theta: np.ndarray,
                    theta_0: float, theta_1: float,
                    breaks: Sequence[tuple[int, int, float]] = ()) -> float:
    """Integral of y dt between the instants where theta passes theta_0 and theta_1
    (:func:`cumulative`, with the friction jumps ``breaks``).

    ``theta`` must be monotonic; the ends are interpolated linearly in theta.
    """
    cum = cumulative(np.asarray(y, float), np.asarray(t, float), breaks)
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th, cum, theta_0, theta_1 = -th, cum, -theta_0, -theta_1
    return float(np.interp(theta_1, th, cum) - np.interp(theta_0, th, cum))


def window_duration(t: np.ndarray, theta: np.ndarray, theta_0: float, theta_1: float) -> float:
    th = np.asarray(theta, float)
    if th[-1] < th[0]:
        th, theta_0, theta_1 = -th, -theta_0, -theta_1
    return float(np.interp(theta_1, th, t) - np.interp(theta_0, th, t))


def mean_values(columns: Mapping[str, np.ndarray], skip_revolutions: float,
                works: Mapping[str, float] | None = None) -> dict[str, Any]:
    """Mean values over whole input revolutions, in the direction the power flows.

    ``power_flow`` comes from the signs of the works (:func:`reference.results.power_flow.classify_works`);
    ``mean_efficiency`` is one minus lost over supplied work; ``mean_instantaneous_efficiency`` the
    time average of eq. (18) over the same window for that direction (:func:`flow_time_average`);
    ``work_ratio`` is received over supplied work (the rig's definition; it differs from
    ``mean_efficiency`` by the change of mechanical energy and, without friction, measures it).

    Parameters
    ----------
    columns : mapping
        The schema's columns (at least time, input angle, powers, efficiency and energies).
    skip_revolutions : float
        Input revolutions left out at the start [-].
    works : mapping, optional
        ``input_work``, ``output_work``, ``loss_work`` [J] (and ``loss_work_<pair>``, ...) of the
        window from a better integration than the table's trapezoid (the reference engine's
        quadrature): they replace the table's, and every mean is taken from them.

    Returns
    -------
    dict
        The summary keys (:data:`MEAN_KEYS`, :data:`FLOW_KEYS`, ``loss_work_<pair>``), ``warnings``
        (list of str) and ``unphysical`` (why the means are impossible; empty when they are not);
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
    """The means that depend on the direction of the power flow (:func:`mean_values`), from the
    window's ``works`` [J], ``integral(y)`` (of ``y dt`` over the window), its ``duration`` [s]
    and the mask of its rows ``inside``."""
    w_in, w_out, w_loss = works["input_work"], works["output_work"], works["loss_work"]
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
    """Mask of the rows whose values enter the window's integrals: those between ``theta_0`` and
    ``theta_1`` and the row on either side that brackets an end (``theta`` monotonic)."""
    sign = 1.0 if theta_1 >= theta_0 else -1.0
    th, lo, hi = sign * np.asarray(theta, float), sign * theta_0, sign * theta_1
    first = max(int(np.searchsorted(th, lo, side="right")) - 1, 0)
    last = min(int(np.searchsorted(th, hi, side="left")), th.size - 1)
    mask = np.zeros(th.size, bool)
    mask[first:last + 1] = True
    return mask


def pair_loss_works(columns: Mapping[str, np.ndarray], integral: Any) -> dict[str, float]:
    """``loss_work_<pair>`` and its axial-friction part ``loss_work_<pair>_sliding`` [J] of the
    pairs whose columns are there, with ``integral(y)`` the window's integral of ``y dt``."""
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
    """Time average of eq. (18) over the window for the direction ``flow``, the sign changes of
    the source power at the rows ``inside`` the window, and why the average is not reported.

    Eq. (18) is ``1 - P_loss / P_src`` with the source power ``P_src`` = ``P_in``, or ``-P_out``
    when the power flows from the output to the input. The average is defined only when
    ``P_src > 0`` at every row of the window (it has poles where ``P_src`` changes sign) and is
    reported only in [0, 1]; otherwise it is None and the note says why.
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


def instantaneous_efficiency(power_in: np.ndarray, power_loss: np.ndarray) -> np.ndarray:
    """Eq. (18): ``1 - P_loss / P_in``, NaN where ``P_in`` is exactly zero."""
    p_in = np.asarray(power_in, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(p_in != 0.0, 1.0 - np.asarray(power_loss, float) / p_in, np.nan)
