"""Run a scene with Exudyn and return the common result schema.

Reaction conventions (pinned by ``tests/test_reactions.py``)
------------------------------------------------------------
Exudyn 1.13.6 reports for ``ObjectJointGeneric`` in dynamic runs ``ForceLocal`` = minus the force
that body ``a`` (marker 0) exerts on body ``b``, in the joint frame fixed to body ``a``; and
``TorqueLocal`` with its in-plane components rotated by 90 degrees, the same sign flip, and
its components in the joint frame attached to body ``b`` (marker 1): the moment of body ``a`` on
body ``b`` in the pair frame of body ``b`` is ``(-TL_y, TL_x, -TL_z)``; it is rotated into the
pair frame of body ``a`` with the pair's relative rotation (they differ by the free rotation about
the pair axis, e.g. the whole shaft angle for ``frame_input``).
The drive torque on the input shaft is minus the ``Force`` of the coordinate connector.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import exudyn as exu
import numpy as np

from cardan_exudyn.model.build import ExudynModel, build_model
from cardan_exudyn.model.projection import project_velocities
from cardan_exudyn.model.stepsize import choose_step
from reference.friction import friction_from_columns
from reference.rccc import LoopClosureError
from reference.scene import (
    PAIR_BODIES,
    PAIR_KIND,
    PAIR_NAMES,
    AngleDrive,
    Scene,
    check_steps,
    scene_to_dict,
)
from reference.schema import (
    REACTION_SUFFIXES,
    OptionsError,
    Result,
    Status,
    Summary,
    instantaneous_efficiency,
    mean_values,
    table_columns,
)

ENGINE_NAME = "exudyn"


NODE_TYPES = ("Rxyz", "EP", "RotVecLG")
SENSOR_SCOPES = ("auto", "all")


@dataclass(frozen=True)
class ExudynOptions:
    """Solver settings of the Exudyn engine.

    Attributes
    ----------
    spectral_radius : float
        Generalized-alpha spectral radius at infinity, in [0, 1); lower damps more.
    modified_newton : bool
        Use modified Newton (Jacobian reused) instead of full Newton.
    jacobian_every_step : bool
        With modified Newton: compute the Jacobian once at the start of every step (Exudyn's
        ``modifiedNewtonJacUpdatePerStep``) instead of only when the iteration stalls.
    newton_relative_tolerance, newton_absolute_tolerance : float
        Tolerances of the Newton iteration (relative to the initial residual, and absolute).
    node_type : str
        Rigid-body node of the bodies: ``"Rxyz"`` (Tait-Bryan angles), ``"EP"`` (Euler
        parameters) or ``"RotVecLG"`` (rotation vector, Lie-group integration); see
        :func:`cardan_exudyn.model.build.build_model` for which body gets which.
    sensors : str
        ``"auto"``: record the pair reactions only when the scene asks for the time table (a
        summary-only run does not need them); ``"all"``: always.
    velocity_projection : bool
        Report velocities projected onto the velocity constraints at the computed positions
        (post-processing, :mod:`cardan_exudyn.model.projection`): exact speed ratio for a prescribed
        input; the drive torque, reactions and friction keep the integrator's error.
    """

    spectral_radius: float = 0.6
    modified_newton: bool = False
    jacobian_every_step: bool = False
    newton_relative_tolerance: float = 1e-10
    newton_absolute_tolerance: float = 1e-10
    node_type: str = "Rxyz"
    sensors: str = "auto"
    velocity_projection: bool = False

    def __post_init__(self) -> None:
        if not 0.0 <= self.spectral_radius < 1.0:
            raise OptionsError(f"`spectral_radius` must be in [0, 1), got {self.spectral_radius!r}")
        for name in ("newton_relative_tolerance", "newton_absolute_tolerance"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and 0.0 < value < 1.0):
                raise OptionsError(f"`{name}` must be in (0, 1), got {value!r}")
        if self.node_type not in NODE_TYPES:
            raise OptionsError(f"`node_type` must be one of {list(NODE_TYPES)}, got {self.node_type!r}")
        if self.node_type == "RotVecLG" and self.spectral_radius > 0.8:
            # measured: at 0.9 friction runs end "ok" with the efficiency 0.2 off, at 0.95 the
            # frictionless run fails
            raise OptionsError(f"`spectral_radius` must be <= 0.8 with node_type 'RotVecLG', got "
                             f"{self.spectral_radius!r}")
        if self.sensors not in SENSOR_SCOPES:
            raise OptionsError(f"`sensors` must be one of {list(SENSOR_SCOPES)}, got {self.sensors!r}")

    def to_dict(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}

    def records_reactions(self, scene: Scene) -> bool:
        """Whether the run records the pair-reaction sensors (see ``sensors``)."""
        return self.sensors == "all" or scene.record.timeseries


def engine_version() -> str:
    return exu.config.Version() if hasattr(exu, "config") else exu.GetVersionString()


def end_time(scene: Scene, start: float) -> float:
    """Time at which the input has turned ``scene.revolutions`` revolutions [s]."""
    drive = scene.drive
    target = 2.0 * math.pi * scene.revolutions
    if drive.kind == "speed":
        return start + target / abs(drive.speed)
    if isinstance(drive, AngleDrive):
        return drive.time_to_turn(target)
    return start + drive.time_allowed(target)


def steps_for_span(span: float, dt: float) -> int:
    """Fewest whole steps of at most ``dt`` (to rounding) that cover ``span``.

    Rounding to the nearest count instead would stop short of the span by up to half a step, and
    a span of exactly ``1 + skip`` revolutions would then average less than one revolution.
    """
    return max(1, math.ceil(span / dt - 1e-9))


def simulation_settings(dt: float, t_start: float, t_end: float,
                        options: ExudynOptions) -> Any:
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    n = steps_for_span(t_end - t_start, dt)
    ti.startTime = t_start
    ti.endTime = t_start + n * dt
    ti.numberOfSteps = n
    ti.verboseMode = 0
    ti.adaptiveStep = False
    ti.automaticStepSize = False
    ti.generalizedAlpha.spectralRadius = options.spectral_radius
    ti.newton.useModifiedNewton = options.modified_newton
    ti.newton.modifiedNewtonJacUpdatePerStep = options.jacobian_every_step
    ti.newton.relativeTolerance = options.newton_relative_tolerance
    ti.newton.absoluteTolerance = options.newton_absolute_tolerance
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.5 * dt
    s.show.statistics = False
    s.show.computationTime = False
    return s


@dataclass
class Solved:
    """A finished (or failed) Exudyn solve of a scene: the model with its sensors, the solver's
    counters, the status and reason, the step used and how it was chosen, the solve's wall time."""

    model: ExudynModel
    solver: Any
    status: Status
    reason: str
    dt: float
    dt_reason: str
    wall_time_s: float


def solve(scene: Scene, options: ExudynOptions, reactions: bool,
          tweak: Callable[[ExudynModel, Any], None] | None = None) -> Solved:
    """Build the model of ``scene`` and integrate it: the step choice, solver settings, friction
    set-up and stop function of every Exudyn run (:func:`run`, the long runs, the benchmark).

    ``tweak(model, settings)``, when given, is called once the model and its simulation settings
    are made and before the solver starts (the benchmark's skip audit adds or removes one thing).

    Raises :class:`LoopClosureError` when the mounting errors cannot be assembled.
    """
    wall_start = time.perf_counter()
    dt, dt_reason = choose_step(scene, options.node_type)
    model = build_model(scene, reactions=reactions, node_type=options.node_type)
    t_end = end_time(scene, model.start_time)
    span = t_end - model.start_time
    check_steps(span / dt, f"{scene.revolutions:g} revolutions at dt = {dt:.3g} s")
    dt = span / steps_for_span(span, dt)  # whole steps end exactly at the span's end
    settings = simulation_settings(dt, model.start_time, t_end, options)
    target = 2.0 * math.pi * scene.revolutions
    friction = model.friction
    if friction is not None:
        friction.configure(settings)
    _set_pre_step(model, target if scene.drive.kind == "torque" else None)
    if tweak is not None:
        tweak(model, settings)
    solver = exu.MainSolverImplicitSecondOrder()
    status, reason = Status.OK, ""
    try:
        if friction is None:
            ok = solver.SolveSystem(model.mbs, settings)
        else:
            solver.InitializeSolver(model.mbs, settings)
            friction.initialise(solver, settings)
            ok = friction.status != Status.OK or solver.SolveSteps(model.mbs, settings)
            solver.FinalizeSolver(model.mbs, settings)
        if not ok:
            status, reason = Status.INTEGRATION_FAILURE, solver.GetErrorString() or "solver failed"
    except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
        status, reason = Status.INTEGRATION_FAILURE, str(exc).strip().splitlines()[0][:300]
    if friction is not None and friction.status != Status.OK:
        status, reason = friction.status, friction.reason
    return Solved(model, solver, status, reason, dt, dt_reason, time.perf_counter() - wall_start)


def run(scene: Scene, options: ExudynOptions | None = None) -> Result:
    """Simulate ``scene`` with Exudyn and return its time table and summary."""
    options = options or ExudynOptions()
    wall_start = time.perf_counter()
    summary = Summary(Status.OK, engine=ENGINE_NAME, engine_version=engine_version(),
                      scene=scene_to_dict(scene),
                      options={**options.to_dict(), "integrator": "generalized-alpha index 3"})
    try:
        solved = solve(scene, options, reactions=options.records_reactions(scene))
    except LoopClosureError as exc:  # mounting errors the loop cannot be assembled with
        summary.fail(Status.LOOP_DOES_NOT_CLOSE, str(exc))
        summary.wall_time_s = time.perf_counter() - wall_start
        return Result(None, summary)
    model, solver = solved.model, solved.solver
    summary.status, summary.reason = Status(solved.status), solved.reason
    summary.dt, summary.dt_choice = solved.dt, solved.dt_reason
    summary.steps = int(solver.it.currentStepIndex)
    summary.newton_iterations = int(solver.it.newtonStepsCount)
    summary.jacobian_evaluations = int(solver.it.newtonJacobiCount)
    summary.wall_time_s = time.perf_counter() - wall_start
    if model.friction is not None:
        friction = model.friction.summary()
        summary.extras["friction"] = friction
        summary.max_friction_loop_gain = friction["loop_gain_estimate_max"]
    try:
        columns = postprocess(model, project=options.velocity_projection)
    except ValueError as exc:  # no data recorded, e.g. a failure in the first step
        if summary.success:
            summary.fail(Status.INTEGRATION_FAILURE, f"no usable output: {exc}")
        return Result(None, summary)
    _check_columns(scene, model, columns, summary, options)
    table = None
    if scene.record.timeseries:
        import pandas as pd

        every = scene.record.every
        table = pd.DataFrame({c: columns[c][::every] for c in table_columns()})
    return Result(table, summary)


def _check_columns(scene: Scene, model: ExudynModel, columns: dict[str, np.ndarray],
                   summary: Summary, options: ExudynOptions) -> None:
    """Constraint violations, finiteness, the torque drive's turn, and the means into ``summary``."""
    violation = constraint_violation(model.pair_kinematics)
    summary.max_constraint_violation_m = violation["max_constraint_violation_m"]
    summary.max_constraint_violation_rad = violation["max_constraint_violation_rad"]
    if options.velocity_projection:
        summary.extras["max_velocity_correction"] = model.velocity_correction
    unrecorded = set() if f"{PAIR_NAMES[0]}_force" in model.sensors else {
        f"{p}_{c}" for p in PAIR_NAMES for c in REACTION_SUFFIXES}
    bad = _first_non_finite({k: v for k, v in columns.items() if k not in unrecorded})
    if bad and summary.success:
        summary.fail(Status.DIVERGED, f"non-finite values in `{bad}`")
    target = 2.0 * math.pi * scene.revolutions
    if scene.drive.kind == "torque" and summary.success:
        turned = abs(columns["theta_in"][-1] - columns["theta_in"][0])
        if turned + 1e-6 < target:
            summary.fail(Status.INCOMPLETE, f"torque drive turned {turned / (2 * math.pi):.3g} of "
                                            f"{scene.revolutions:g} revolutions in the time allowed")
    if summary.success:
        means = mean_values(columns, scene.record.skip_revolutions)
        if means.get("revolutions", 0) < 1:
            summary.fail(Status.NO_WHOLE_REVOLUTION, means.get("mean_status", ""))
        else:
            summary.set_means(means)


def _set_pre_step(model: ExudynModel, target: float | None) -> None:
    """Stop the run after ``target`` radians (torque drive) or when friction self-locks."""
    node = model.nodes["input"]
    friction = model.friction
    if target is None and friction is None:
        return
    start = {}

    def pre_step(mbs_, t):
        if friction is not None and friction.status != Status.OK:
            return False
        if target is None:
            return True
        angle = mbs_.GetNodeOutput(node, exu.OutputVariableType.Coordinates)[3]
        start.setdefault("angle", angle)
        return abs(angle - start["angle"]) < target - 1e-12

    model.user_functions.append(pre_step)
    model.mbs.SetPreStepUserFunction(pre_step)


def _first_non_finite(columns: dict[str, np.ndarray]) -> str | None:
    for key, values in columns.items():
        if key != "efficiency" and not np.all(np.isfinite(values)):
            return key
    return None


def _stored(model: ExudynModel, key: str) -> np.ndarray:
    data = np.asarray(model.mbs.GetSensorStoredData(model.sensors[key]))
    if data.ndim != 2:  # nothing recorded, e.g. a failure in the first step
        raise ValueError(f"sensor `{key}` recorded no data")
    return data


def body_states(model: ExudynModel) -> dict[str, dict[str, np.ndarray]]:
    """Per body: time, CoM position, velocity, rotation matrices (node axes) and angular velocity.

    ``psi`` holds the node's total rotation coordinates (reference included): the Rxyz angles
    for the input (every node type; the first is the shaft angle), else those of
    ``model.rotations[name]``.
    """
    states = {}
    for name in model.nodes:
        q = _stored(model, f"{name}_q")
        q_t = _stored(model, f"{name}_q_t")
        n = min(len(q), len(q_t))
        q, q_t = q[:n], q_t[:n]
        rot = model.rotations[name]
        end = 4 + rot.size
        p = q[:, 4:end] if rot.zero_reference else q[:, 4:end] + np.asarray(rot.reference)
        a, omega = rot.frame(p, q_t[:, 4:end])
        states[name] = {
            "t": q[:, 0],
            "r": model.com_reference[name] + q[:, 1:4],
            "v": q_t[:, 1:4],
            "A": a,
            "omega": omega,
            "psi": p,
        }
    return states


def _ground_state(n: int) -> dict[str, np.ndarray]:
    return {"r": np.zeros((n, 3)), "v": np.zeros((n, 3)),
            "A": np.broadcast_to(np.eye(3), (n, 3, 3)), "omega": np.zeros((n, 3))}


def _pair_kinematics(model: ExudynModel, states: dict, n: int) -> dict[str, dict[str, np.ndarray]]:
    """Pair axes, marker points and their velocities (global) for both bodies of each pair."""
    out = {}
    for name in PAIR_NAMES:
        body_a, body_b = PAIR_BODIES[name]
        l_a, l_b = model.marker_local[name]
        frame = model.pair_frames[name]
        sa = _ground_state(n) if body_a == "ground" else states[body_a]
        sb = _ground_state(n) if body_b == "ground" else states[body_b]
        pa = sa["r"][:n] + sa["A"][:n] @ l_a
        pb = sb["r"][:n] + sb["A"][:n] @ l_b
        va = sa["v"][:n] + np.cross(sa["omega"][:n], pa - sa["r"][:n])
        vb = sb["v"][:n] + np.cross(sb["omega"][:n], pb - sb["r"][:n])
        out[name] = {
            "frame_a": sa["A"][:n] @ frame,
            "frame_b": sb["A"][:n] @ frame,
            "pa": pa, "pb": pb, "va": va, "vb": vb,
            "omega_a": sa["omega"][:n], "omega_b": sb["omega"][:n],
        }
    return out


def postprocess(model: ExudynModel, project: bool = False) -> dict[str, np.ndarray]:
    """Columns of the result schema from the recorded sensors.

    ``project``: replace the recorded velocities by their projection onto the velocity
    constraints (:mod:`cardan_exudyn.model.projection`); the largest correction is left in
    ``model.velocity_correction``.
    """
    scene = model.scene
    states = body_states(model)
    n = min(len(s["t"]) for s in states.values())
    t = states["input"]["t"][:n]
    if n < 2:
        raise ValueError("fewer than two recorded steps")
    if project:
        states = _projected_states(model, states, n)
    cols: dict[str, np.ndarray] = {"t": t}
    cols["theta_in"] = states["input"]["psi"][:n, 0]
    cols["omega_in"] = states["input"]["omega"][:n, 0]
    kin = _pair_kinematics(model, states, n)
    # the output turns about the output_frame axis (fixed in the ground); its angle is minus the
    # pair's relative rotation (ground relative to output), zero in the reference configuration
    out = kin["output_frame"]
    cols["theta_out"] = -_relative_angle(out)
    cols["omega_out"] = states["output"]["omega"][:n] @ model.pair_frames["output_frame"][:, 2]
    if scene.drive.kind == "torque":
        cols["torque_in"] = np.full(n, scene.drive.torque)
    else:
        cols["torque_in"] = -_stored(model, "drive_force")[:n, 1]
    cols["torque_out"] = scene.load.at(t)
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * cols["omega_out"]

    for name in PAIR_NAMES:
        if f"{name}_force" in model.sensors:
            force = _stored(model, f"{name}_force")[:n, 1:4]
            torque = _stored(model, f"{name}_torque")[:n, 1:4]
        else:  # reactions not recorded (summary-only run)
            force = torque = np.full((n, 3), np.nan)
        k = kin[name]
        fx, fy, fz = (-force).T
        # TorqueLocal: 90-degree in-plane swap, sign flip, and components in the frame of body b
        m_b = np.stack([-torque[:, 1], torque[:, 0], -torque[:, 2]], axis=1)
        relative = np.einsum("nji,njk->nik", k["frame_a"], k["frame_b"])  # frame_a^T frame_b
        mx, my, mz = np.einsum("nij,nj->ni", relative, m_b).T
        omega_rel, slide_rel = relative_speeds(t, k, cylindrical=PAIR_KIND[name] == "cylindrical")
        for suffix, values in zip(("fx", "fy", "fz", "mx", "my", "mz", "omega_rel", "slide_rel"),
                                  (fx, fy, fz, mx, my, mz, omega_rel, slide_rel), strict=True):
            cols[f"{name}_{suffix}"] = values
    if model.friction is not None:
        applied = model.friction.columns(t)
    elif scene.has_friction:  # uncoupled: the law evaluated on the frictionless reactions
        law = friction_from_columns(scene, cols)
        applied = {f"{p}_{kind}": law[p][j] for p in PAIR_NAMES
                   for j, kind in enumerate(("friction_torque", "friction_force"))}
    else:
        applied = {f"{p}_{k}": np.zeros(n) for p in PAIR_NAMES
                   for k in ("friction_torque", "friction_force")}
    loss_total = np.zeros(n)
    for name in PAIR_NAMES:
        friction_torque = applied[f"{name}_friction_torque"]
        friction_force = applied[f"{name}_friction_force"]
        loss = -(friction_torque * cols[f"{name}_omega_rel"] + friction_force * cols[f"{name}_slide_rel"])
        loss_total += loss
        cols[f"{name}_friction_torque"] = friction_torque
        cols[f"{name}_friction_force"] = friction_force
        cols[f"power_loss_{name}"] = loss
    cols["power_loss"] = loss_total
    cols["energy_kinetic"], cols["energy_potential"] = mechanical_energy(model, states, n)
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], loss_total)
    model.pair_kinematics = kin
    return cols


def _projected_states(model: ExudynModel, states: dict, n: int) -> dict:
    """``states`` with velocities projected onto the joint's velocity constraints."""
    drive = model.scene.drive
    if isinstance(drive, AngleDrive):
        spline = drive.spline()

        def input_speed(t):
            return spline(t, 1)
    elif drive.kind == "speed":
        def input_speed(t):
            return np.full(np.shape(t), drive.speed)
    else:
        input_speed = None
    trimmed = {name: {k: v[:n] for k, v in s.items()} for name, s in states.items()}
    projected = project_velocities(trimmed, _pair_kinematics(model, trimmed, n), model.mass,
                                   model.inertia, model.pair_frames["frame_input"][:, 2], input_speed)
    model.velocity_correction = projected.pop("max_velocity_correction")
    return projected


def _relative_angle(k: dict[str, np.ndarray]) -> np.ndarray:
    """Rotation of body b's pair frame relative to body a's about the pair axis [rad], unwrapped."""
    rel = np.einsum("nji,njk->nik", k["frame_a"], k["frame_b"])
    return np.unwrap(np.arctan2(rel[:, 1, 0], rel[:, 0, 0]))


def relative_speeds(t: np.ndarray, k: dict[str, np.ndarray],
                    cylindrical: bool) -> tuple[np.ndarray, np.ndarray]:
    """Relative angular and sliding speed of body b w.r.t. body a of a pair.

    Index-3 integration keeps positions on the constraint manifold to the Newton tolerance but
    leaves O(h^2) residuals in the velocity constraints (sliding speeds of ~1e-3 m/s in pairs
    that cannot slide). The relative speeds are therefore the second-order backward difference
    (BDF2, BDF1 for the first step) of the pair's relative coordinates: the rotation angle of
    b's pair frame about the axis and the axial offset of b's pair point. The initial row uses the
    (consistent) initial velocities. The friction law uses the same definition in the step loop.
    """
    axis = k["frame_a"][:, :, 2]
    angle = _relative_angle(k)
    velocity_level = [np.einsum("ij,ij->i", k["omega_b"] - k["omega_a"], axis)]
    coords = [angle]
    if cylindrical:
        coords.append(np.einsum("ij,ij->i", k["pb"] - k["pa"], axis))
        velocity_level.append(np.einsum("ij,ij->i", k["vb"] - k["va"], axis))
    speeds = []
    for c, v in zip(coords, velocity_level, strict=True):
        out = np.empty_like(c)
        out[0] = v[0]
        if len(c) > 1:
            out[1] = (c[1] - c[0]) / (t[1] - t[0])
        if len(c) > 2:
            h1, h2 = np.diff(t)[1:], np.diff(t)[:-1]
            w = h1 / h2
            d1, d2 = c[2:] - c[1:-1], c[1:-1] - c[:-2]
            out[2:] = ((1.0 + 2.0 * w) / (1.0 + w) * d1 - w * w / (1.0 + w) * d2) / h1
        speeds.append(out)
    if not cylindrical:
        speeds.append(np.zeros_like(angle))
    return speeds[0], speeds[1]


def mechanical_energy(model: ExudynModel, states: dict, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and gravitational potential energy of the three bodies [J]."""
    kinetic = np.zeros(n)
    potential = np.zeros(n)
    g = np.asarray(model.scene.gravity)
    for name, s in states.items():
        m, j_body = model.mass[name], model.inertia[name]
        w_body = np.einsum("nji,nj->ni", s["A"][:n], s["omega"][:n])  # A^T omega
        kinetic += 0.5 * m * np.einsum("ni,ni->n", s["v"][:n], s["v"][:n])
        kinetic += 0.5 * np.einsum("ni,ij,nj->n", w_body, j_body, w_body)
        potential -= m * (s["r"][:n] @ g)
    return kinetic, potential


def constraint_violation(pair_kinematics: dict[str, dict[str, np.ndarray]]) -> dict[str, float]:
    """Largest violation of the pair constraints over the run.

    Position [m]: distance of the two marker points (revolute) or of marker b from the axis of
    marker a (cylindrical). Angle [rad]: misalignment of the two pair axes, and for the revolute
    the twist is free so only the axis counts.
    """
    pos, ang = 0.0, 0.0
    for name, k in pair_kinematics.items():
        d = k["pb"] - k["pa"]
        za, zb = k["frame_a"][:, :, 2], k["frame_b"][:, :, 2]
        if PAIR_KIND[name] == "cylindrical":
            d = d - np.einsum("ij,ij->i", d, za)[:, None] * za
        pos = max(pos, float(np.max(np.linalg.norm(d, axis=1))))
        ang = max(ang, float(np.max(np.linalg.norm(np.cross(za, zb), axis=1))))
    return {"max_constraint_violation_m": pos, "max_constraint_violation_rad": ang}
