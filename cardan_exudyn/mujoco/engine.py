"""The MuJoCo engine (optional: ``pip install mujoco``) for the frictionless Cardan joint.

MuJoCo's friction loss is a constant-magnitude joint friction; it cannot express the paper's
friction forces proportional to the pair reactions (eqs. (1)-(5)), so this engine refuses scenes
with friction. Importing this module needs MuJoCo; :mod:`cardan_exudyn.engines` imports it on
first use, so a missing MuJoCo makes only this engine unavailable.

The model (``docs/mujoco.md``): three hinges through the joint centre O; one ``connect`` at the
output bearing closes the loop; a prescribed input follows a heavy ``drive_reference`` hinge
through a joint equality whose force is the drive torque. MuJoCo's supports are not the schema's
RCCC, so its pair forces and frame-pair reactions are NaN; the spider-pair moments, the same in
both, are filled. Defaults: the settings study of :mod:`cardan_exudyn.studies.mujoco_settings.compute`.

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": Section 3 (RCCC model, pair frames) and eq. (18).
MuJoCo documentation, "Computation" (soft constraints: impedance ``d``, reference acceleration
``a_ref = -b J v - k r``) and "Modeling / Solver parameters" (``solref``, ``solimp``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from typing import Any

import mujoco
import numpy as np

from reference.physics.kinematics import body_motions, pair_frames_in_body_a, rot_z
from reference.results.columns import instantaneous_efficiency
from reference.results.result import Result, result_table
from reference.results.summary import OptionsError, Status, Summary
from reference.scene import AngleDrive, Scene, SpeedDrive, TorqueDrive, scene_to_dict
from reference.scene.joint import PAIR_BODIES, PAIR_NAMES
from reference.scene.validation import refuse_steps_per_revolution

ENGINE_NAME = "mujoco"
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast", "discrete")
# MuJoCo's own solref and solimp: the contact override's when not given, and the study's
MUJOCO_DEFAULT_SOLREF = (0.02, 1.0)
MUJOCO_DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
# Impedance at MuJoCo's cap mjMAXIMP = 0.9999 (larger values are clamped to it).
STIFF_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
BODY_IDS = {"input": 1, "spider": 2, "output": 3}
# A loop that opens by more than this is no Cardan joint any more: the run is flagged [rad].
VIOLATION_LIMIT_RAD = 1e-2
# Pairs whose moments (mx, my, mz) are filled; see the module docstring.
_FILLED_REACTIONS = ("input_spider", "spider_output")
# Per-step shapes of the recorded mjData fields (:meth:`_Record.take` says what each holds).
RECORD_SHAPES = {"t": (), "q": (3,), "qd": (3,), "reference": (), "xmat": (3, 3, 3), "cvel": (3, 6),
                 "centre": (3,), "sites": (2, 3), "cfrc_int": (3, 6), "torque_in": ()}


def _floats(name: str, value: Any) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise OptionsError(f"`{name}` must be a sequence of numbers, got {value!r}") from None


def _solref(name: str, value: Any) -> tuple[float, ...]:
    ref = _floats(name, value)
    if len(ref) != 2 or not (min(ref) > 0.0 or (ref[0] < 0.0 and ref[1] <= 0.0)):
        raise OptionsError(f"`{name}` must be (timeconst > 0, dampratio > 0) or "
                           f"(-stiffness < 0, -damping <= 0), got {value!r}")
    return ref


def _solimp(name: str, value: Any) -> tuple[float, ...]:
    imp = _floats(name, value)
    if len(imp) != 5 or not (0.0 < imp[0] < 1.0 and 0.0 < imp[1] < 1.0):
        raise OptionsError(f"`{name}` must be 5 numbers with 0 < d0, dwidth < 1, got {value!r}")
    return imp


@dataclass(frozen=True)
class MujocoOptions:
    """Solver settings of the MuJoCo engine; the defaults are the recommended ones.

    Attributes
    ----------
    integrator : str
        One of :data:`INTEGRATORS` (MuJoCo's ``option/integrator``).
    timestep : float or None
        Time step [s]; None takes ``scene.numerics.dt`` or, if that is None too, the step that
        meets ``scene.numerics.accuracy`` (:func:`choose_timestep`).
    timeconst_steps : float
        Constraint time constant in time steps: ``solref = (timeconst_steps * dt, dampratio)``
        when ``solref`` is None [-].
    dampratio : float
        Damping ratio of the constraint stabilisation when ``solref`` is None [-].
    solref : tuple of 2 float or None
        Explicit ``solref`` of every equality: ``(timeconst [s], dampratio [-])`` or the direct
        form ``(-stiffness [1/s^2], -damping [1/s])``.
    solimp : tuple of 5 float
        ``solimp`` of every equality: ``(d0, dwidth, width [m or rad], midpoint, power)``.
    refsafe : bool
        MuJoCo's ``refsafe`` flag: the time constant is raised to at least ``2 dt``.
    iterations : int
        Maximum constraint-solver iterations [-].
    tolerance : float
        Constraint-solver tolerance [-].
    noslip_iterations : int
        Noslip post-processing iterations [-] (acts on friction rows only; there are none).
    o_solref, o_solimp : tuple or None
        When either is given, MuJoCo's contact override is enabled with these ``o_solref`` /
        ``o_solimp`` (MuJoCo's defaults for the one not given). The override acts on contacts
        only, and there are none: the study shows that it leaves the equalities alone.
    reference_inertia : float
        Inertia of the drive-reference body about its axis [kg m^2]: the drive torque changes its
        speed by ``torque * dt / reference_inertia`` within a step before it is reset.
    """

    integrator: str = "RK4"
    timestep: float | None = None
    timeconst_steps: float = 20.0
    dampratio: float = 1.0
    solref: tuple | None = None
    solimp: tuple = STIFF_SOLIMP
    refsafe: bool = True
    iterations: int = 100
    tolerance: float = 1e-8
    noslip_iterations: int = 0
    o_solref: tuple | None = None
    o_solimp: tuple | None = None
    reference_inertia: float = 1e6

    def __post_init__(self) -> None:
        if self.integrator not in INTEGRATORS:
            raise OptionsError(f"`integrator` must be one of {list(INTEGRATORS)}, got {self.integrator!r}")
        for name in ("timeconst_steps", "dampratio", "reference_inertia"):
            if not getattr(self, name) > 0.0:
                raise OptionsError(f"`{name}` must be positive, got {getattr(self, name)!r}")
        if self.timestep is not None and not self.timestep > 0.0:
            raise OptionsError(f"`timestep` must be positive or None, got {self.timestep!r}")
        for name, check in (("solref", _solref), ("o_solref", _solref), ("o_solimp", _solimp)):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, check(name, getattr(self, name)))
        object.__setattr__(self, "solimp", _solimp("solimp", self.solimp))
        for name in ("iterations", "noslip_iterations"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < (name == "iterations"):
                raise OptionsError(f"`{name}` must be a non-negative integer (iterations >= 1), "
                                   f"got {value!r}")
        if not self.tolerance >= 0.0:
            raise OptionsError(f"`tolerance` must be >= 0, got {self.tolerance!r}")

    def solref_for(self, dt: float) -> tuple[float, float]:
        """The ``solref`` used at time step ``dt`` [s]."""
        return self.solref if self.solref is not None else (self.timeconst_steps * dt, self.dampratio)


ERROR_CONSTANT_SPEED = 1.5e-4  # C_H of speed_ratio_error_model [-]
ERROR_CONSTANT_GRAVITY = 1e-4  # C_G of speed_ratio_error_model [1/m]
MIN_STEPS_PER_REVOLUTION = 100
SECONDS_PER_STEP = 1e-4  # one RK4 step on one core [s]: measured 40-81 us (docs/mujoco.md, "Cost")


def engine_version() -> str:
    return mujoco.__version__


def speed_ratio_error_model(scene: Scene, options: MujocoOptions, steps: int) -> float:
    """Predicted largest speed-ratio error [-] of a run with ``steps`` steps per revolution.

    Valid for the recommended settings (RK4, ``solref`` from ``timeconst_steps``): the largest
    error of ``omega_out / omega_in`` is about ``C_H tan(b)^2 / cos(b)^2 h^1.5 + C_G |g| tc /
    omega``, with ``h = omega dt`` the input angle per step [rad] and ``tc`` the constraint time
    constant [s]. The first term is the integration error at speed (the paper scenes at 10-75 deg,
    2000 rpm: ``C_H`` bounds the measured values by 1.2-8x), the second the drift that the
    impedance cap lets gravity cause within one time constant (the rig scene, 6 rad/s: the
    measured values are half of it). Measured by the settings study, see ``docs/mujoco.md``.
    """
    beta = scene.joint.geometry.shaft_angle
    omega = scene.drive.max_speed()
    h = 2.0 * math.pi / steps
    timeconst = options.timeconst_steps * h / omega
    gravity = float(np.linalg.norm(scene.gravity))
    return (ERROR_CONSTANT_SPEED * (math.tan(beta) / math.cos(beta)) ** 2 * h**1.5
            + ERROR_CONSTANT_GRAVITY * gravity * timeconst / omega)


def choose_timestep(scene: Scene, options: MujocoOptions) -> tuple[float, str]:
    """Time step [s] and a sentence saying how it was chosen.

    Without a given step, the fewest whole steps per revolution (at the drive's highest speed),
    at least :data:`MIN_STEPS_PER_REVOLUTION`, whose :func:`speed_ratio_error_model` meets
    ``scene.numerics.accuracy`` (beyond ``MAX_STEPS_PER_REVOLUTION``, 2e6, refused, never capped).

    Raises
    ------
    OptionsError
        When no step is given and the settings are not the ones the error model was measured
        with (another integrator or an explicit ``solref``).
    SceneError
        The accuracy needs more steps than allowed (the predicted steps and run time, one line).
    """
    if options.timestep is not None:
        return options.timestep, "given (engine settings)"
    if scene.numerics.dt is not None:
        return scene.numerics.dt, "given (scene)"
    if options.integrator != "RK4" or options.solref is not None:
        raise OptionsError("the automatic time step is measured for RK4 with `solref` from "
                           f"`timeconst_steps` only; give `timestep` for integrator "
                           f"{options.integrator!r} and solref {options.solref!r}")
    accuracy = scene.numerics.accuracy
    low, high = MIN_STEPS_PER_REVOLUTION, MIN_STEPS_PER_REVOLUTION
    while speed_ratio_error_model(scene, options, high) > accuracy and high < 2**60:  # falls with h
        low, high = high, 2 * high
    while high - low > 1:  # the smallest count in (low, high] that meets the accuracy
        middle = (low + high) // 2
        meets = speed_ratio_error_model(scene, options, middle) <= accuracy
        low, high = (low, middle) if meets else (middle, high)
    target = f"a speed-ratio error of {accuracy:g} at {math.degrees(scene.joint.geometry.shaft_angle):g} deg"
    refuse_steps_per_revolution(high, scene.revolutions * (4.0 if scene.drive.kind == "torque" else 1.0),
                                SECONDS_PER_STEP, target)
    why = f"auto: {high} steps per input revolution for {target} at most (error model of docs/mujoco.md)"
    return 2.0 * math.pi / scene.drive.max_speed() / high, why


def _numbers(values: Iterable[float]) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(np.asarray(values, dtype=float)))


def _inertial(scene: Scene, name: str) -> str:
    mass, com, j = getattr(scene.joint, name).canonical()
    full = [j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]]
    return f'<inertial pos="{_numbers(com)}" mass="{mass!r}" fullinertia="{_numbers(full)}"/>'


def mjcf(scene: Scene, options: MujocoOptions, dt: float) -> str:
    """The MJCF model of ``scene`` (see the module docstring) with time step ``dt`` [s]."""
    geo = scene.joint.geometry
    half = 0.5 * geo.shaft_angle
    solref = f'solref="{_numbers(options.solref_for(dt))}" solimp="{_numbers(options.solimp)}"'
    prescribed = not isinstance(scene.drive, TorqueDrive)
    i_ref = options.reference_inertia
    reference_body = (
        f'<body name="drive_reference"><joint name="drive_reference" axis="1 0 0"/>'
        f'<inertial pos="0 0 0" mass="1" diaginertia="{i_ref!r} {i_ref!r} {i_ref!r}"/></body>'
        if prescribed else "")
    drive = (f'<joint name="drive" joint1="input" joint2="drive_reference" polycoef="0 1 0 0 0" '
             f'{solref}/>' if prescribed else "")
    override = options.o_solref is not None or options.o_solimp is not None
    o_solref = options.o_solref if options.o_solref is not None else MUJOCO_DEFAULT_SOLREF
    o_solimp = options.o_solimp if options.o_solimp is not None else MUJOCO_DEFAULT_SOLIMP
    return f"""<mujoco model="cardan">
  <option timestep="{dt!r}" integrator="{options.integrator}" gravity="{_numbers(scene.gravity)}"
          solver="Newton" jacobian="dense" iterations="{options.iterations}"
          tolerance="{options.tolerance!r}" noslip_iterations="{options.noslip_iterations}"
          o_solref="{_numbers(o_solref)}" o_solimp="{_numbers(o_solimp)}">
    <flag refsafe="{'enable' if options.refsafe else 'disable'}" autoreset="disable"
          override="{'enable' if override else 'disable'}"/>
  </option>
  <worldbody>
    <site name="bearing_ground" pos="{_numbers(geo.output_bearing * geo.output_axis())}"/>
    <body name="input">
      <joint name="input" axis="1 0 0"/>
      {_inertial(scene, "input")}
      <body name="spider">
        <joint name="spider" axis="0 1 0"/>
        {_inertial(scene, "spider")}
        <body name="output" quat="{math.cos(half)!r} 0 0 {math.sin(half)!r}">
          <joint name="output" axis="0 0 1"/>
          {_inertial(scene, "output")}
          <site name="bearing_output" pos="{geo.output_bearing!r} 0 0"/>
        </body>
      </body>
    </body>
    {reference_body}
  </worldbody>
  <equality>
    <connect name="closure" site1="bearing_output" site2="bearing_ground" {solref}/>
    {drive}
  </equality>
</mujoco>
"""


def joint_state(scene: Scene, theta: float, theta_t: float) -> tuple[np.ndarray, np.ndarray]:
    """Assembled angles [rad] and rates [rad/s] of the input, spider and output hinges.

    From the closed-form kinematics: the spider angle about the input yoke, and the output
    hinge angle ``phi`` defined by ``R_output = R_spider Rz(beta) Rz(phi)``; the rates are the
    relative angular velocities projected on the hinge axes.
    """
    beta = scene.joint.geometry.shaft_angle
    m = body_motions(np.array(theta), np.array(theta_t), np.array(0.0), beta)
    r_input, r_spider, r_output = (m[b].rotation for b in ("input", "spider", "output"))
    spider_relative = r_input.T @ r_spider
    output_relative = rot_z(np.array(-beta)) @ r_spider.T @ r_output
    gamma = math.atan2(spider_relative[0, 2], spider_relative[0, 0])
    phi = math.atan2(output_relative[1, 0], output_relative[0, 0])
    gamma_t = float((m["spider"].omega - m["input"].omega) @ r_input[:, 1])
    phi_t = float((m["output"].omega - m["spider"].omega) @ r_spider[:, 2])
    return np.array([theta, gamma, phi]), np.array([theta_t, gamma_t, phi_t])


@dataclass(frozen=True)
class DrivePlan:
    """How the input is driven.

    Attributes
    ----------
    start, span : float
        Start time and longest simulated time [s].
    motion : callable or None
        ``t -> (angle [rad], speed [rad/s], acceleration [rad/s^2])`` of a prescribed input;
        None for the torque drive.
    theta0, omega0 : float
        Input angle [rad] and speed [rad/s] at ``start``.
    turn : float
        Input rotation [rad] after which the run stops (the scene's revolutions).
    """

    start: float
    span: float
    motion: Callable[[float], tuple[float, float, float]] | None
    theta0: float
    omega0: float
    turn: float


def drive_plan(scene: Scene) -> DrivePlan:
    """The :class:`DrivePlan` of the scene's drive (speed, angle history or torque)."""
    drive = scene.drive
    turn = 2.0 * math.pi * scene.revolutions
    if isinstance(drive, SpeedDrive):
        w = drive.speed
        return DrivePlan(0.0, turn / abs(w), lambda t: (w * t, w, 0.0), 0.0, w, turn)
    if isinstance(drive, AngleDrive):
        spline = drive.spline()
        rates = (spline, spline.derivative(), spline.derivative(2))
        end = drive.time_to_turn(turn)
        start = drive.time[0]
        return DrivePlan(start, end - start, lambda s: tuple(float(f(s)) for f in rates),
                         float(spline(start)), float(rates[1](start)), turn)
    if isinstance(drive, TorqueDrive):
        # as the Exudyn engine: four times the time at the initial speed, stopped at `turn`
        return DrivePlan(0.0, drive.time_allowed(turn), None, 0.0, drive.initial_speed, turn)
    raise NotImplementedError(f"the MuJoCo engine cannot run a {type(drive).__name__}")


class _Record:
    """Per-step copies of the mjData fields the result table is computed from (arrays of
    :data:`RECORD_SHAPES`, one row per step)."""


    def __init__(self, n: int) -> None:
        for name, shape in RECORD_SHAPES.items():
            setattr(self, name, np.zeros((n, *shape)))
        self.size = 0

    def take(self, d: Any, drive_row: int | None, torque: float) -> None:
        """Append the state of ``d`` (after ``mj_forward`` and ``mj_rnePostConstraint``)."""
        k, bodies = self.size, slice(1, 4)
        self.t[k] = d.time
        self.q[k], self.qd[k] = d.qpos[:3], d.qvel[:3]
        self.reference[k] = d.qpos[3] if drive_row is not None else np.nan
        self.xmat[k] = d.xmat[bodies].reshape(3, 3, 3)
        self.cvel[k] = d.cvel[bodies]
        self.centre[k] = d.subtree_com[BODY_IDS["input"]]
        self.sites[k] = d.site_xpos[:2]
        self.cfrc_int[k] = d.cfrc_int[bodies]
        self.torque_in[k] = d.efc_force[drive_row] if drive_row is not None else torque
        self.size += 1

    def trimmed(self) -> _Record:
        for name, value in vars(self).items():
            if isinstance(value, np.ndarray):
                setattr(self, name, value[:self.size])
        return self


def _integrate(m: Any, d: Any) -> None:
    """Advance one step from an mjData on which ``mj_forward`` has just run."""
    integrator = m.opt.integrator
    if integrator == mujoco.mjtIntegrator.mjINT_RK4:
        mujoco.mj_RungeKutta(m, d, 4)
    elif integrator == mujoco.mjtIntegrator.mjINT_EULER:
        mujoco.mj_Euler(m, d)
    elif integrator in (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST):
        mujoco.mj_implicit(m, d)
    else:  # "discrete" has no separate integration call: mj_step repeats the forward pass
        mujoco.mj_step(m, d)


def simulate(scene: Scene, options: MujocoOptions, dt: float) -> tuple[_Record, Status, str]:
    """Run the MuJoCo model of ``scene``; per-step records, status and reason.

    Every step runs ``mj_forward`` and ``mj_rnePostConstraint`` at the current state, records,
    and integrates, so that every record (state, drive torque, reactions) belongs to one instant.
    """
    plan = drive_plan(scene)
    m = mujoco.MjModel.from_xml_string(mjcf(scene, options, dt))
    d = mujoco.MjData(m)
    q0, qd0 = joint_state(scene, plan.theta0, plan.omega0)
    d.qpos[:3], d.qvel[:3] = q0, qd0
    a2 = scene.joint.geometry.output_axis()
    d.xfrc_applied[BODY_IDS["output"], 3:] = -scene.load.torque * a2
    torque = scene.drive.torque if isinstance(scene.drive, TorqueDrive) else 0.0
    d.qfrc_applied[0] = torque
    # The run ends once the input itself has turned `revolutions`. A prescribed input lags its
    # reference (by a fraction of a step with the recommended settings, by 0.06 rad with
    # MuJoCo's default solref/solimp), so it may take up to 1 % more steps than the span.
    steps = max(1, math.ceil(plan.span / dt - 1e-9))
    if plan.motion is not None:
        steps += math.ceil(0.01 * steps)
    record = _Record(steps + 1)
    drive_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, "drive")
    drive_row = None
    status, reason = Status.OK, ""
    for k in range(steps + 1):
        d.time = plan.start + k * dt
        if plan.motion is not None:
            angle, speed, acceleration = plan.motion(d.time)
            d.qpos[3], d.qvel[3] = angle, speed
            d.qfrc_applied[3] = options.reference_inertia * acceleration
        mujoco.mj_forward(m, d)
        mujoco.mj_rnePostConstraint(m, d)
        if plan.motion is not None and drive_row is None:  # equality rows keep their place
            drive_row = int(np.flatnonzero((d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
                                           & (d.efc_id == drive_id))[0])
        record.take(d, drive_row, torque)
        if not math.isfinite(d.qvel @ d.qvel + d.qacc @ d.qacc):
            status, reason = Status.DIVERGED, f"non-finite state at t = {d.time:.6g} s (step {k})"
            break
        if abs(d.qpos[0] - plan.theta0) >= plan.turn - 1e-12 or k == steps:
            break
        _integrate(m, d)
    turned = abs(d.qpos[0] - plan.theta0)
    if status == Status.OK and turned < plan.turn - 1e-9:
        status = Status.INCOMPLETE
        reason = (f"the input turned {turned / (2 * math.pi):.6g} of {scene.revolutions:g} "
                  "revolutions in the time allowed")
    return record.trimmed(), status, reason


def _point_velocity(cvel: np.ndarray, centre: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Velocity [m/s] of a body point from MuJoCo's com-based velocity ``[omega, v(centre)]``."""
    return cvel[:, 3:] + np.cross(cvel[:, :3], point - centre)


def _body_motion(record: _Record) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Rotation matrices (columns: canonical axes) and angular velocities [rad/s], ground included."""
    n = record.t.size
    rot = {"ground": np.broadcast_to(np.eye(3), (n, 3, 3))}
    omega = {"ground": np.zeros((n, 3))}
    for name, i in BODY_IDS.items():
        rot[name], omega[name] = record.xmat[:, i - 1], record.cvel[:, i - 1, :3]
    return rot, omega


def mechanical_energy(scene: Scene, record: _Record) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy of the three bodies [J] (potential zero at O)."""
    rot, omega = _body_motion(record)
    kinetic, potential = np.zeros(record.t.size), np.zeros(record.t.size)
    for name, i in BODY_IDS.items():
        mass, com, inertia = getattr(scene.joint, name).canonical()
        r = rot[name] @ com
        v = _point_velocity(record.cvel[:, i - 1], record.centre, r)
        j_omega = np.einsum("nij,jk,nlk,nl->ni", rot[name], inertia, rot[name], omega[name])
        kinetic += 0.5 * mass * np.sum(v * v, 1) + 0.5 * np.sum(omega[name] * j_omega, 1)
        potential -= mass * (r @ np.asarray(scene.gravity))
    return kinetic, potential


def pair_columns(scene: Scene, record: _Record) -> dict[str, np.ndarray]:
    """Relative motion, zero friction and the reactions of each pair (NaN where not filled)."""
    n = record.t.size
    geo = scene.joint.geometry
    rot, omega = _body_motion(record)
    points = {"frame_input": np.broadcast_to([-geo.input_bearing, 0.0, 0.0], (n, 3)),
              "input_spider": np.zeros((n, 3)), "spider_output": np.zeros((n, 3)),
              "output_frame": record.sites[:, 1]}
    local = pair_frames_in_body_a()
    cols = {}
    for pair in PAIR_NAMES:
        a, b = PAIR_BODIES[pair]
        frame = rot[a] @ local[pair]
        velocity = {body: np.zeros((n, 3)) if body == "ground" else
                    _point_velocity(record.cvel[:, BODY_IDS[body] - 1], record.centre, points[pair])
                    for body in (a, b)}
        cols[f"{pair}_omega_rel"] = np.sum((omega[b] - omega[a]) * frame[:, :, 2], 1)
        cols[f"{pair}_slide_rel"] = np.sum((velocity[b] - velocity[a]) * frame[:, :, 2], 1)
        cols.update({key: np.zeros(n) for key in (f"power_loss_{pair}", f"{pair}_friction_torque",
                                                  f"{pair}_friction_force")})
        cols.update({f"{pair}_{c}": np.full(n, np.nan) for c in ("fx", "fy", "fz", "mx", "my", "mz")})
        if pair in _FILLED_REACTIONS:  # the wrench a exerts on b, moved to the pair origin
            wrench = record.cfrc_int[:, BODY_IDS[b] - 1]
            moment = wrench[:, :3] + np.cross(record.centre - points[pair], wrench[:, 3:])
            local_moment = np.einsum("nji,nj->ni", frame, moment)
            cols.update({f"{pair}_{c}": local_moment[:, i] for i, c in enumerate(("mx", "my", "mz"))})
    return cols


def columns(scene: Scene, record: _Record) -> dict[str, np.ndarray]:
    """Result-schema columns from the records (see the module docstring for the reactions)."""
    n = record.t.size
    geo = scene.joint.geometry
    y_out = record.xmat[:, BODY_IDS["output"] - 1, :, 1]
    y_ref = np.array([-math.sin(geo.shaft_angle), math.cos(geo.shaft_angle), 0.0])
    cols = {"t": record.t, "theta_in": record.q[:, 0], "omega_in": record.qd[:, 0],
            "theta_out": np.unwrap(np.arctan2(y_out[:, 2], y_out @ y_ref)),
            "omega_out": record.cvel[:, BODY_IDS["output"] - 1, :3] @ geo.output_axis(),
            "torque_in": record.torque_in, "torque_out": np.full(n, scene.load.torque)}
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * cols["omega_out"]
    cols["power_loss"] = np.zeros(n)
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], cols["power_loss"])
    cols["energy_kinetic"], cols["energy_potential"] = mechanical_energy(scene, record)
    cols.update(pair_columns(scene, record))
    return cols


def constraint_violation(scene: Scene, record: _Record) -> dict[str, float]:
    """Largest loop-closure and drive violations over the run.

    ``max_constraint_violation_m``: distance of the output's bearing point from its place on the
    ground [m]; ``max_constraint_violation_rad``: misalignment of the output axis from ``a2``
    [rad]; ``max_drive_error_rad``: input angle minus prescribed angle [rad] (NaN for a torque
    drive).
    """
    drift = np.linalg.norm(record.sites[:, 1] - record.sites[:, 0], axis=1)
    axis = record.xmat[:, BODY_IDS["output"] - 1, :, 0]
    tilt = np.linalg.norm(np.cross(axis, scene.joint.geometry.output_axis()), axis=1)
    lag = np.abs(record.q[:, 0] - record.reference)
    return {"max_constraint_violation_m": float(np.max(drift)),
            "max_constraint_violation_rad": float(np.max(tilt)),
            "max_drive_error_rad": float(np.max(lag)) if np.all(np.isfinite(lag)) else float("nan")}


def run(scene: Scene, options: MujocoOptions | None = None) -> Result:
    """Simulate the frictionless ``scene`` with MuJoCo and return its time table and summary.

    Parameters
    ----------
    scene : Scene
        A scene with every friction coefficient zero.
    options : MujocoOptions, optional
        Solver settings; the defaults are the recommended ones (``docs/mujoco.md``).

    Returns
    -------
    Result
        The columns of :func:`reference.results.columns.table_columns` (pair forces and frame-pair
        reactions NaN, see the module docstring) and the summary with the mean values.

    Raises
    ------
    NotImplementedError
        For scenes with friction: MuJoCo has no friction proportional to the reactions.
    SceneError
        ``numerics.accuracy`` needs more steps than allowed (:func:`choose_timestep`).
    """
    if scene.has_friction:
        raise NotImplementedError(
            "MuJoCo cannot model the paper's friction (eqs. (1)-(5): friction forces "
            "proportional to the pair reactions); its frictionloss is a constant joint friction. "
            "Use the exudyn engine or a '-frictionless' scene")
    if scene.numerics.richardson:
        raise NotImplementedError("`numerics.richardson` is not implemented for MuJoCo (its RK4 with "
                                  "soft constraints has no O(h^2) error to extrapolate)")
    if not scene.load.constant:
        raise NotImplementedError("the MuJoCo engine takes a constant load torque only; a load "
                                  "history (measured brake torque) runs on exudyn or reference")
    options = options or MujocoOptions()
    start = time.perf_counter()
    dt, why = choose_timestep(scene, options)
    record, status, reason = simulate(scene, options, dt)
    cols = columns(scene, record)
    summary = Summary(status, reason, engine=ENGINE_NAME, engine_version=engine_version(),
                      scene=scene_to_dict(scene), dt=dt, dt_choice=why, steps=int(record.t.size - 1),
                      options={**asdict(options), "solref": list(options.solref_for(dt))})
    violation = constraint_violation(scene, record)
    summary.max_constraint_violation_m = violation["max_constraint_violation_m"]
    summary.max_constraint_violation_rad = violation["max_constraint_violation_rad"]
    summary.extras["max_drive_error_rad"] = violation["max_drive_error_rad"]
    if summary.success and summary.max_constraint_violation_rad > VIOLATION_LIMIT_RAD:
        # before the means: a loop that does not hold explains whatever they would say
        summary.fail(Status.CONSTRAINT_VIOLATED, (
            f"the output axis left its bearing by up to "
            f"{summary.max_constraint_violation_rad:.3g} rad (limit {VIOLATION_LIMIT_RAD:g}):"
            " the loop closure is too soft for this time step and these settings"))
    elif summary.success:
        means = summary.whole_revolution_means(cols, scene.record.skip_revolutions)
        if means is not None:
            summary.set_means(means)
    table = result_table(cols, scene.record.every) if scene.record.timeseries else None
    summary.wall_time_s = time.perf_counter() - start
    return Result(table, summary)
