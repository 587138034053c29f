"""The reference engine: any scene in, the shared result schema out, without time stepping error.

Prescribed input motion (constant speed, angle history) is pure inverse dynamics: every sample
is solved on its own (:func:`reference.engine.dynamics.dynamics_columns`), friction included, so the
time table has no discretisation error at all. A torque-driven scene is one degree of freedom
in minimal coordinates: the input angle and speed are integrated with
:func:`scipy.integrate.solve_ivp` (DOP853, tight tolerances); the acceleration at every instant
comes from the same Newton-Euler system with the drive torque given.

The mean values that matter (input, output and lost work, hence the mean efficiency) are not
taken from the time table but by Gauss-Legendre quadrature over the whole-revolution window, on
panels that break at every kink of the integrand: the edges of each friction sign ramp
(relative surface speed = +- the pair's band, :mod:`reference.physics.bands`) and the knots of an angle
history. Inside a panel the integrand is smooth, so the quadrature converges exponentially; the
mean efficiency is stable to 1e-8 and better as the panels are refined (tested). The
time-averaged instantaneous efficiency is taken from the table like every engine does (it has
poles where the input power crosses zero, so it has no exact value to converge to).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference.engine.crossings import (
    SCAN_PER_REVOLUTION,
    distinct_instants,
    grazing_brackets,
    grazing_candidates,
    sign_change_brackets,
)
from reference.engine.dynamics import (
    dynamics_columns,
    friction_slots,
    ramp_bands,
    ramp_speeds,
)
from reference.engine.gauss import (
    DENSE_NODES,
    DENSE_WIDTH,
    GROSS_SCALE,
    adaptive_gauss,
    initial_panels,
    quadrature_summary,
)
from reference.engine.periodic import period_rows, repeat_period
from reference.physics.bands import sign_bands
from reference.physics.joint_motion import joint_motion
from reference.physics.loop_closure import LoopClosureError
from reference.results.schema import (
    OptionsError,
    Result,
    Status,
    Summary,
    result_table,
    whole_revolution_window,
)
from reference.scene.drives import AngleDrive, SpeedDrive, TorqueDrive
from reference.scene.histories import run_clock
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import check_steps, require_scene

ENGINE_NAME = "reference"
ENGINE_VERSION = "reference-0.2"
EXTRA_COLUMNS = ("input_acceleration", "friction_loop_gain", "self_locking",
                 *(f"{p}_slide" for p in PAIR_NAMES),
                 *(f"power_loss_{p}_{part}" for p in PAIR_NAMES for part in ("rotation", "sliding")))


@dataclass(frozen=True)
class ReferenceOptions:
    """Resolution of the reference engine.

    Attributes
    ----------
    samples_per_revolution : int or None
        Rows of the time table per input revolution; None: the scene's ``numerics.dt`` when set
        (so the rows line up with a fixed-step engine), else 360.
    panels_per_revolution : int
        Initial Gauss-Legendre panels per revolution for the work integrals (more where kinks
        split them; refined adaptively).
    gauss_nodes : int
        Nodes per panel.
    quadrature_rtol : float
        A panel is accepted when its two halves and the whole agree to this fraction of the
        input work (scaled by the panel's share of the window).
    ode_rtol, ode_atol : float
        Tolerances of ``solve_ivp`` for torque-driven scenes (atol applies to the angle [rad]
        and, scaled by the initial speed, to the speed).
    """

    samples_per_revolution: int | None = None
    panels_per_revolution: int = 8
    gauss_nodes: int = 8
    quadrature_rtol: float = 1e-9
    ode_rtol: float = 1e-11
    ode_atol: float = 1e-11

    def __post_init__(self) -> None:
        spr = self.samples_per_revolution
        if spr is not None and (isinstance(spr, bool) or not isinstance(spr, (int, np.integer))
                                or spr < 1):
            raise OptionsError(f"`samples_per_revolution` must be a positive integer, got {spr!r}")
        for name in ("panels_per_revolution", "gauss_nodes"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise OptionsError(f"`{name}` must be a positive integer, got {v!r}")
        for name in ("ode_rtol", "ode_atol", "quadrature_rtol"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and 0.0 < v < 1.0):
                raise OptionsError(f"`{name}` must be in (0, 1), got {v!r}")


class SelfLocking(Exception):
    """Friction has no finite consistent value at some instant (raised inside the integrator)."""

    def __init__(self, t: float, theta: float) -> None:
        super().__init__(t, theta)
        self.t, self.theta = t, theta


@dataclass
class InputMotion:
    """The input's motion over the run: ``state(t)`` gives angle, speed and (prescribed motion)
    acceleration, or None for the acceleration when the dynamics must supply it (torque drive).

    Attributes
    ----------
    t0, t_end : float
        Span [s].
    state : callable
        ``t -> (theta, theta_t, theta_tt | None)``, vectorised.
    torque_in : float or None
        The given drive torque [N m] of a torque-driven scene.
    knots : ndarray
        Instants where the motion is less smooth (angle-history knots) [s].
    status, reason : str
        Why the span ends early, if it does.
    ode_evaluations : int
        Right-hand-side evaluations of the integrator (torque drive).
    periodic : bool
        Every input revolution takes the same time and repeats the first (constant speed and
        constant load).
    """

    t0: float
    t_end: float
    state: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray | None]]
    torque_in: float | None = None
    knots: np.ndarray = field(default_factory=lambda: np.zeros(0))
    status: Status = Status.OK
    reason: str = ""
    ode_evaluations: int = 0
    periodic: bool = False

    def angle(self, t: float) -> float:
        """Input angle [rad] at one instant."""
        return float(np.asarray(self.state(np.array([t]))[0]).ravel()[0])


def _speed_motion(scene: Scene, drive: SpeedDrive) -> InputMotion:
    w = drive.speed
    t_end = 2.0 * math.pi * scene.revolutions / abs(w)
    return InputMotion(0.0, t_end, lambda t: (w * np.asarray(t, float),
                                             np.full(np.shape(t), w),
                                             np.zeros(np.shape(t))), periodic=scene.load.constant)


def _angle_motion(scene: Scene, drive: AngleDrive) -> InputMotion:
    spline = drive.spline()
    t0 = drive.time[0]
    # a history shorter than the span ends first; the means say how many revolutions it holds
    t_end = drive.time_to_turn(2.0 * math.pi * scene.revolutions)
    return InputMotion(t0, float(t_end), lambda t: (spline(t), spline(t, 1), spline(t, 2)),
                       knots=np.asarray(drive.time))


def _torque_motion(scene: Scene, drive: TorqueDrive, options: ReferenceOptions) -> InputMotion:
    from scipy.integrate import solve_ivp  # scipy.integrate takes ~0.5 s to import

    from reference.engine.forward import right_hand_side  # scipy.linalg: imported with scipy.integrate

    target = 2.0 * math.pi * scene.revolutions
    w0 = drive.initial_speed
    t_max = drive.time_allowed(target)  # the span every engine allows
    count = {"n": 0}
    acceleration = right_hand_side(scene, drive.torque)  # microseconds a call (reference.engine.forward)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        count["n"] += 1
        theta, theta_t = float(y[0]), float(y[1])
        theta_tt, locked = acceleration(t, theta, theta_t)
        if locked:
            raise SelfLocking(t, theta)
        return np.array([theta_t, theta_tt])

    def reached(t: float, y: np.ndarray) -> float:  # turned `target` either way, as Exudyn's stop
        return abs(y[0]) - target

    reached.terminal = True
    try:
        sol = solve_ivp(rhs, (0.0, t_max), [0.0, w0], method="DOP853", dense_output=True,
                        events=reached, rtol=options.ode_rtol,
                        atol=[options.ode_atol, options.ode_atol * abs(w0)])
    except SelfLocking as exc:
        return InputMotion(0.0, exc.t, lambda t: (np.nan, np.nan, None), drive.torque,
                           status=Status.SELF_LOCKING,
                           reason=(f"friction self-locks at t = {exc.t:.6g} s, input angle "
                                   f"{math.degrees(exc.theta):.6g} deg: no consistent friction"),
                           ode_evaluations=count["n"])
    if not sol.success:
        return InputMotion(0.0, float(sol.t[-1]), sol.sol, drive.torque,
                           status=Status.INTEGRATION_FAILURE, reason=sol.message,
                           ode_evaluations=count["n"])
    t_end = float(sol.t_events[0][0]) if sol.t_events[0].size else float(sol.t[-1])
    dense = sol.sol

    def state(t):
        y = dense(np.asarray(t, float))
        return y[0], y[1], None

    motion = InputMotion(0.0, t_end, state, drive.torque, ode_evaluations=count["n"])
    if not sol.t_events[0].size:
        motion.status = Status.INCOMPLETE
        motion.reason = (f"torque drive turned {abs(sol.y[0, -1]) / (2 * math.pi):.3g} of "
                         f"{scene.revolutions:g} revolutions in the time allowed")
    return motion


def input_motion(scene: Scene, options: ReferenceOptions) -> InputMotion:
    """The input's motion for the scene's drive (integrating it for a torque drive)."""
    drive = scene.drive
    if isinstance(drive, SpeedDrive):
        return _speed_motion(scene, drive)
    if isinstance(drive, AngleDrive):
        return _angle_motion(scene, drive)
    if isinstance(drive, TorqueDrive):
        return _torque_motion(scene, drive, options)
    raise NotImplementedError(f"the reference engine has no {drive.kind!r} drive")


def columns_at(scene: Scene, motion: InputMotion, t: np.ndarray) -> dict[str, np.ndarray]:
    """Result-schema columns at the instants ``t`` (plus :data:`EXTRA_COLUMNS`)."""
    theta, theta_t, theta_tt = motion.state(t)
    theta = np.broadcast_to(np.asarray(theta, float), np.shape(t))
    theta_t = np.broadcast_to(np.asarray(theta_t, float), np.shape(t))
    load = scene.load.at(np.asarray(t, float))
    cols, _ = dynamics_columns(scene, theta, theta_t, theta_tt=theta_tt, load_torque=load,  # one of the two
                               torque_in=motion.torque_in if theta_tt is None else None)
    return {"t": np.asarray(t, float), **cols}


def table_columns(scene: Scene, motion: InputMotion, t: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`columns_at` on the table's instants ``t`` [s]. Summary only (no table recorded): a
    periodic motion's first period, repeated (:mod:`reference.engine.periodic`); a recorded table is
    evaluated row by row, so that each row's angle is the one its state was computed at."""
    rows = period_rows(t, scene.drive.speed) if motion.periodic and not scene.record.timeseries else None
    if rows is None:
        return columns_at(scene, motion, t)
    return repeat_period(columns_at(scene, motion, t[:rows]), t, scene.drive.speed)


def sign_breakpoints(scene: Scene, motion: InputMotion, t_a: float, t_b: float,
                     per_revolution: int = SCAN_PER_REVOLUTION) -> np.ndarray:
    """Instants in (t_a, t_b) where a friction sign ramp starts or ends [s].

    Each relative surface (or sliding) speed is sampled on a grid, every crossing of its ramp
    edges ``+-band`` (:func:`reference.engine.dynamics.slot_bands`; of 0 for the exact sign) is
    bracketed (:mod:`reference.engine.crossings`: sign changes, and grazing crossings between two
    samples) and refined to rounding.
    """

    slots = friction_slots(scene)
    if not slots or t_b <= t_a:
        return np.zeros(0)

    def speeds(t: np.ndarray) -> np.ndarray:
        theta, theta_t, _ = motion.state(t)
        kin = joint_motion(scene.joint, theta, theta_t, 0.0)  # speeds do not need accelerations
        return ramp_speeds(scene, slots, kin.omega_rel, kin.slide_rel)  # resultant law: slip speeds too

    theta_a, theta_b = motion.angle(t_a), motion.angle(t_b)
    n = max(64, int(per_revolution * abs(theta_b - theta_a) / (2.0 * math.pi)))
    grid = np.linspace(t_a, t_b, n + 1)
    values = speeds(grid)
    bands = ramp_bands(scene, slots)
    brackets, grazing = [], []
    for levels in (-bands, bands):  # twice 0 for the exact sign: duplicates merge below
        brackets += sign_change_brackets(grid, values, levels)
        grazing += [(levels, c) for c in grazing_candidates(grid, values, levels)]
    if grazing:  # every vertex in one evaluation
        at = speeds(np.array([c[0] for _, c in grazing]))
        for row, (levels, c) in enumerate(grazing):
            brackets += grazing_brackets(grid, values, levels, [c], at[row, c[2]:c[2] + 1])
    if not brackets:
        return np.zeros(0)
    a, b, f_a, f_b, j, level = (np.array(v) for v in zip(*brackets, strict=True))
    rows = np.arange(a.size)
    for _ in range(100):  # Illinois regula falsi on all brackets at once
        c = b - f_b * (b - a) / (f_b - f_a)
        f_c = speeds(c)[rows, j] - level
        same = np.sign(f_c) == np.sign(f_b)
        a, f_a = np.where(same, a, b), np.where(same, 0.5 * f_a, f_b)
        b, f_b = c, f_c
        if np.all((np.abs(b - a) <= 1e-15) | (f_b == 0.0)):
            break
    return distinct_instants(b, t_b - t_a)


def _time_at_angle(motion: InputMotion, theta: float, lo: float, hi: float) -> float:
    """Illinois regula falsi as in :func:`sign_breakpoints`: scipy.optimize would cost every
    command that builds a ``mean_input`` scene (``cardan run``) ~0.3 s of imports."""
    a, b = lo, hi
    f_a, f_b = motion.angle(a) - theta, motion.angle(b) - theta
    if f_a == 0.0 or f_b == 0.0 or f_a * f_b > 0:  # at an end within rounding
        return a if f_a == 0.0 else b
    for _ in range(100):
        c = b - f_b * (b - a) / (f_b - f_a)
        f_c = motion.angle(c) - theta
        a, f_a = (a, 0.5 * f_a) if (f_c > 0) == (f_b > 0) else (b, f_b)
        b, f_b = c, f_c
        if f_b == 0.0 or abs(b - a) <= 1e-15 + 4 * np.finfo(float).eps * abs(b):
            break
    return b


WORK_KEYS = ("power_in", "power_out", "power_loss", "self_locking",
             *(f"power_loss_{p}" for p in PAIR_NAMES), *(f"power_loss_{p}_sliding" for p in PAIR_NAMES))
"""The columns :func:`work_quadrature` integrates over time, in this order."""


def window_times(motion: InputMotion, theta: np.ndarray, t: np.ndarray,
                  theta_0: float, theta_1: float) -> tuple[float, float]:
    """Instants [s] at which the input passes ``theta_0`` and ``theta_1`` [rad], each solved
    between the table rows that bracket it."""
    sign = 1.0 if theta[-1] >= theta[0] else -1.0

    def bracket(angle: float) -> tuple[float, float]:
        k = min(max(int(np.searchsorted(sign * theta, sign * angle)), 1), t.size - 1)
        return float(t[k - 1]), float(t[k])

    return (_time_at_angle(motion, theta_0, *bracket(theta_0)),
            _time_at_angle(motion, theta_1, *bracket(theta_1)))


def _integrate_powers(scene: Scene, motion: InputMotion, lo: np.ndarray, hi: np.ndarray,
                      ends: dict[str, np.ndarray], options: ReferenceOptions,
                      nodes: int | None = None) -> tuple[np.ndarray, dict]:
    """:data:`WORK_KEYS` integrated over the panels ``[lo, hi]`` [s] (:func:`adaptive_gauss`,
    ``nodes`` per panel, default ``options.gauss_nodes``)."""
    def integrand(times: np.ndarray) -> np.ndarray:
        cols = columns_at(scene, motion, times)
        return np.stack([np.asarray(cols[k], float) for k in WORK_KEYS], -1)

    # work below a thousandth of the mechanical energy is at the scale's floor (zero input work)
    energy_scale = float(np.max(np.abs(ends["energy_kinetic"])) + np.max(np.abs(ends["energy_potential"])))
    with np.errstate(invalid="ignore"):
        return adaptive_gauss(integrand, lo, hi, nodes or options.gauss_nodes, options.quadrature_rtol,
                              scale_floor=GROSS_SCALE * energy_scale)


def work_means(work: dict[str, float], ends: dict[str, np.ndarray]) -> dict[str, Any]:
    """Summary keys from the works [J] over the window (the means derived from them are
    :func:`reference.results.schema.mean_values`')."""
    out = {"input_work": work["power_in"], "output_work": work["power_out"],
           "loss_work": work["power_loss"]}
    for pair in PAIR_NAMES:
        out[f"loss_work_{pair}"] = work[f"power_loss_{pair}"]
        out[f"loss_work_{pair}_sliding"] = work[f"power_loss_{pair}_sliding"]
    energy = ends["energy_kinetic"] + ends["energy_potential"]
    out["energy_balance_residual"] = float(out["input_work"] - out["output_work"] - out["loss_work"]
                                           - (energy[1] - energy[0]))
    return out


def work_quadrature(scene: Scene, motion: InputMotion, table: dict[str, np.ndarray],
                    options: ReferenceOptions) -> dict:
    """Work integrals over the whole-revolution window by panel Gauss-Legendre quadrature.

    Returns the summary keys ``input_work``, ``output_work``, ``loss_work`` [J],
    ``loss_work_<pair>`` and its axial-friction part ``loss_work_<pair>_sliding`` [J] (zero in
    the ideal joint), ``energy_balance_residual`` (W_in - W_out - W_loss - change of mechanical
    energy [J], zero up to rounding for an exact solution), ``quadrature`` (how it was done) and
    ``self_locking_nodes`` (friction locks at some node); empty when there is no whole revolution.
    """
    theta, t = table["theta_in"], table["t"]
    theta_0, theta_1, n = whole_revolution_window(theta, scene.record.skip_revolutions)
    if n < 1:
        return {}
    t_a, t_b = window_times(motion, theta, t, theta_0, theta_1)
    period = (t_b - t_a) / n
    # at constant speed every revolution repeats the first exactly: integrate one, times n
    repeats = n if motion.periodic else 1
    t_end = t_a + period if motion.periodic else t_b
    kinks = sign_breakpoints(scene, motion, t_a, t_end)
    knots = np.concatenate([motion.knots, scene.load.knots])  # drive and load histories' knots
    knots = knots[(knots > t_a) & (knots < t_end)]
    edges = np.unique(np.concatenate([[t_a, t_end], kinks, knots]))
    lo, hi = initial_panels(edges, width := period / options.panels_per_revolution)
    k_lo, k_hi = initial_panels(np.unique(np.concatenate([[t_a, t_end], knots])), width)
    dense = knots.size and np.median(k_hi - k_lo) < DENSE_WIDTH * width
    nodes = min(options.gauss_nodes, DENSE_NODES) if dense else options.gauss_nodes
    ends = columns_at(scene, motion, np.array([t_a, t_b]))
    values, info = _integrate_powers(scene, motion, lo, hi, ends, options, nodes)
    work = dict(zip(WORK_KEYS, (repeats * values).tolist(), strict=True))
    out = work_means(work, ends)
    out["quadrature"] = quadrature_summary(info, nodes, options.quadrature_rtol, int(kinks.size),
                                           int(knots.size), n // repeats)
    # a locked node makes its panel's values NaN; the self_locking column integrates to > 0
    out["self_locking_nodes"] = bool(work["self_locking"] != 0 or not np.isfinite(out["input_work"]))
    return out


def table_times(scene: Scene, motion: InputMotion, options: ReferenceOptions) -> np.ndarray:
    span = motion.t_end - motion.t0
    if options.samples_per_revolution is None and scene.numerics.dt is not None:
        check_steps(span / scene.numerics.dt,
                    f"{scene.revolutions:g} revolutions at dt = {scene.numerics.dt:.3g} s")
        steps = max(1, math.ceil(span / scene.numerics.dt - 1e-9))  # as the Exudyn engine
    else:
        spr = options.samples_per_revolution or 360
        theta_a, theta_b = motion.angle(motion.t0), motion.angle(motion.t_end)
        check_steps(abs(theta_b - theta_a) / (2.0 * math.pi) * spr,
                    f"{scene.revolutions:g} revolutions at {spr} samples per revolution")
        steps = max(1, round(abs(theta_b - theta_a) / (2.0 * math.pi) * spr))
    return np.linspace(motion.t0, motion.t_end, steps + 1)


def run(scene: Scene, options: ReferenceOptions | None = None) -> Result:
    """Solve ``scene`` with the reference engine.

    Scripts should usually call ``cardan_exudyn.run(scene, engine="reference")``, the same for
    every engine; this is the engine itself, for users without Exudyn.

    Parameters
    ----------
    scene : Scene
        Any scene: constant-speed, angle-history or torque drive, with or without mounting errors.
    options : ReferenceOptions or None
        Resolution; None: the defaults.

    Returns
    -------
    Result
        Time table (the schema's columns plus :data:`EXTRA_COLUMNS`, every
        ``scene.record.every``-th row; None when ``record.timeseries`` is off) and summary: the
        keys of :func:`reference.results.schema.mean_values` taken from :func:`work_quadrature`'s works,
        ``self_locking_samples`` and, when friction locks, status ``self_locking`` with the first
        input angle where it does; status ``unphysical`` when the means are impossible; status
        ``loop_does_not_close`` (no table) when mounting errors keep the loop from closing.
    """
    require_scene(scene)
    if options is not None and not isinstance(options, ReferenceOptions):
        raise OptionsError(f"`options` must be ReferenceOptions or None, got {type(options).__name__}")
    options = options or ReferenceOptions()
    start = time.perf_counter()
    summary = Summary(Status.OK, engine=ENGINE_NAME, engine_version=ENGINE_VERSION,
                      scene=scene_to_dict(scene),
                      options={k: getattr(options, k) for k in options.__dataclass_fields__})
    try:
        clock, origin = run_clock(scene)  # histories from t = 0: the same answer at any start time
        table = _run(clock, options, summary, origin)
    except LoopClosureError as exc:  # mounting errors the loop cannot be assembled with
        summary.fail(Status.LOOP_DOES_NOT_CLOSE, str(exc))
        table = None
    summary.wall_time_s = time.perf_counter() - start
    return Result(table, summary)


def _run(scene: Scene, options: ReferenceOptions, summary: Summary, origin: float = 0.0) -> Any:
    """Fill ``summary``; return the time table (or None), its times ``origin`` [s] later than
    the scene's (:func:`reference.scene.histories.run_clock`)."""
    if scene.drive.kind == "torque":  # the ODE's cost grows with the revolutions: refuse first
        spr = options.samples_per_revolution or 360
        check_steps(scene.revolutions * spr,
                    f"{scene.revolutions:g} revolutions at {spr} samples per revolution")
    if scene.has_friction:
        summary.extras["sign_bands_m_s"] = {p: list(b) for p, b in sign_bands(scene).items()}
    motion = input_motion(scene, options)
    summary.status, summary.reason = Status(motion.status), motion.reason
    if scene.drive.kind == "torque":
        summary.ode_evaluations = motion.ode_evaluations
    if motion.status == Status.SELF_LOCKING:
        return None
    t = table_times(scene, motion, options)
    columns = table_columns(scene, motion, t)
    table_verdict(t, columns, summary, origin)
    if summary.success:  # the means over whole revolutions, from the works
        means_from_works(scene, work_quadrature(scene, motion, columns, options), columns, options, summary)
    columns["t"] = t + origin
    return result_table(columns, scene.record.every, EXTRA_COLUMNS) if scene.record.timeseries else None


def table_verdict(t: np.ndarray, columns: dict[str, np.ndarray], summary: Summary,
                  origin: float = 0.0) -> None:
    """Step, sample count, self-locking samples, loop gain of the table at ``t`` [s] into ``summary``."""
    locked = columns["self_locking"]
    summary.dt, summary.steps = float(t[1] - t[0]), int(t.size - 1)
    summary.extras["self_locking_samples"] = int(np.count_nonzero(locked))
    summary.max_friction_loop_gain = float(np.max(columns["friction_loop_gain"]))
    if np.any(locked) and summary.success:
        first = int(np.argmax(locked))
        summary.fail(Status.SELF_LOCKING, (
            f"friction self-locks at {int(np.count_nonzero(locked))} of {locked.size} samples, "
            f"first at t = {t[first] + origin:.6g} s, input angle "
            f"{math.degrees(columns['theta_in'][first]):.6g} deg (loop gain "
            f"{columns['friction_loop_gain'][first]:.3g}): no consistent friction"))


def means_from_works(scene: Scene, works: dict, columns: dict[str, np.ndarray],
                     options: ReferenceOptions, summary: Summary) -> None:
    """The means over whole revolutions from :func:`work_quadrature`'s ``works`` (consumed)."""
    if works.pop("self_locking_nodes", False):
        # as when it locks at a sample: no means (they were NaN or meaningless)
        summary.fail(Status.SELF_LOCKING,
                     "friction self-locks between the table's samples (at quadrature nodes)")
        return
    diagnostics = {k: works.pop(k) for k in ("quadrature", "energy_balance_residual") if k in works}
    means = summary.whole_revolution_means(columns, scene.record.skip_revolutions, works)
    if means is not None:
        summary.set_means({**means, **diagnostics})
        _efficiency_error(scene, summary, options)


def _efficiency_error(scene: Scene, summary: Summary, options: ReferenceOptions) -> None:
    """The quadrature's error estimate of the mean efficiency into the summary (a first-order
    propagation of the input and lost works' estimates, plus the ODE's ``rtol`` for a torque
    drive), and whether it meets ``numerics.accuracy``."""
    q, w_in, w_loss = summary.extras.get("quadrature"), summary.input_work, summary.loss_work
    if not q or not w_in or w_loss is None or summary.mean_efficiency is None:
        return
    repeats = summary.revolutions / q["revolutions_integrated"] if q.get("revolutions_integrated") else 1
    e_in = repeats * float(q["input_work_error_estimate"])
    e_loss = repeats * float(q["loss_work_error_estimate"])
    estimate = e_loss / abs(w_in) + abs(w_loss) * e_in / w_in ** 2
    if scene.drive.kind == "torque":
        estimate += options.ode_rtol * abs(summary.mean_efficiency)
    summary.efficiency_error_estimate = estimate
    summary.accuracy_met = bool(estimate <= scene.numerics.accuracy)
