"""The long runs: (a) drift over thousands of revolutions with friction, per node type, and (b)
energy conservation of the free-spinning frictionless joint.

Entry point: :func:`long_runs` (``quick=True``: about 20-30 s). The pieces: what runs
(:mod:`.plan`), the measurements (:mod:`.measures`), the headline figures (:mod:`.summary`), the
files and the report section (:mod:`.report`). This package measures; the verdicts (each
tolerance with its reason) are ``tests/benchmarks/test_longrun.py``; the measured figures and what
they mean are in ``docs/benchmarks.md`` (*Long runs*).

(a) The paper's scene with friction (:data:`.plan.DRIFT_SCENE`, converged coupling) with each
node type of the spider and the output, all at :data:`.plan.DRIFT_STEPS_PER_REVOLUTION`. Per
revolution: the largest violation of the pair constraints at position level (marker distance
[m], axis misalignment [rad]) and at velocity level (constrained relative velocity [m/s] and
angular velocity [rad/s]); the rotation coordinates' health (``| |p| - 1 |`` of Euler
parameters, ``|nu|`` of rotation vectors, orthogonality of every rotation matrix); the input
angle against ``omega t``; the input, output and lost work and the change of mechanical energy
over the revolution, hence each revolution's efficiency and the residual of its energy balance.
The first revolution is a start-up (:data:`.plan.STARTUP_REVOLUTIONS`).

(b) The paper's frictionless joint driven by a torque of 0 (free spinning), no load, gravity on,
from 2000 rpm: the total mechanical energy at each whole input revolution (the same input angle
every time, so the periodic O(h^2) error within a revolution does not enter) relative to its
start, for the default settings, a step ladder and a spectral-radius ladder
(:func:`.plan.energy_plan`), compared with generalized-alpha's numerical damping
``K c(rho) h^3`` (:data:`.plan.DISSIPATION_MODEL`); the reference engine (no time steps) runs the
same scene as the yardstick of an integrator that does not dissipate.

Every step of a run is kept in memory (node-state sensors, the friction log) and post-processed
once with :func:`cardan_exudyn.model.postprocess.postprocess` (the engine's own definitions):
keeping every n-th step would miss the per-step maxima and coarsen the per-revolution work
integrals, and running in chunks would restart the integrator and the friction iteration at
every chunk boundary, changing the very run whose drift is measured.
"""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from benchmarks.longrun.measures import (
    at_revolutions,
    energy_measures,
    pair_violations,
    per_revolution_max,
    revolution_index,
    rotation_health,
    whole_revolutions,
)
from benchmarks.longrun.plan import (
    DRIFT_SCENE,
    DRIFT_STEPS_PER_REVOLUTION,
    ENGINE,
    FULL,
    QUICK,
    REFERENCE,
    LongRunPlan,
    case_label,
    drift_scene,
    energy_plan,
    energy_scene,
)
from benchmarks.longrun.summary import summarise
from cardan_exudyn.engines import run
from cardan_exudyn.model.build import ExudynModel
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.postprocess import body_states, mechanical_energy, postprocess, stored
from cardan_exudyn.model.solve import solve
from reference.engine import ReferenceOptions
from reference.results.means import cumulative
from reference.results.summary import Status
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["simulate", "drift_rows", "drift_run", "energy_case_exudyn", "energy_case_reference",
           "LongRuns", "run_drift", "energy_cases", "run_energy", "long_runs"]

Say = Callable[[str], None]
#: An energy case: label, function, its arguments but the label, engine, spectral radius, steps.
EnergyCase = tuple[str, Callable[..., Any], tuple, str, float, "int | None"]


def simulate(scene: Scene, options: ExudynOptions,
             columns: bool = True) -> tuple[dict[str, Any], ExudynModel, dict[str, np.ndarray]]:
    """Solve ``scene`` with :func:`cardan_exudyn.model.solve.solve` (as the engine's run does),
    keeping the model.

    What differs from :func:`cardan_exudyn.engines.run` is what comes back: the model, whose
    sensors hold every step, and (``columns=True``) the result-schema columns of every step from
    :func:`cardan_exudyn.model.postprocess.postprocess`, with ``model.pair_kinematics`` filled
    (also for a failed run: the steps it completed). No table, no reaction sensors (friction reads
    the reactions itself).
    """
    wall_start = time.perf_counter()
    solved = solve(scene, options, reactions=False)
    model = solved.model
    cols: dict[str, np.ndarray] = {}
    if columns:  # a failed run too: the steps it completed
        try:
            cols = postprocess(model)
        except ValueError:  # nothing usable recorded (as the engine's run): the status says why
            cols = {}
    summary = {"status": solved.status, "reason": solved.reason, "dt": solved.dt,
               "dt_choice": solved.dt_reason, "newton_iterations": int(solved.solver.it.newtonStepsCount),
               "solve_wall_time_s": solved.wall_time_s, "wall_time_s": time.perf_counter() - wall_start}
    if model.friction is not None:
        summary["friction"] = model.friction.diagnostics().to_dict()
    return summary, model, cols


def _work_rows(cols: dict[str, np.ndarray], theta: np.ndarray, revs: int) -> dict[str, np.ndarray]:
    """Per revolution: input, output and lost work, change of mechanical energy, the residual of
    the energy balance [J] and the efficiency."""
    t = cols["t"]
    works = {key: np.diff(at_revolutions(cumulative(cols[key], t), theta, revs))
             for key in ("power_in", "power_out", "power_loss")}
    energy = np.diff(at_revolutions(cols["energy_kinetic"] + cols["energy_potential"], theta, revs))
    rows = {"input_work_j": works["power_in"], "output_work_j": works["power_out"],
            "loss_work_j": works["power_loss"], "energy_change_j": energy,
            "balance_residual_j": works["power_in"] - works["power_out"] - works["power_loss"] - energy}
    with np.errstate(divide="ignore", invalid="ignore"):
        rows["efficiency"] = 1.0 - works["power_loss"] / works["power_in"]
    return rows


def drift_rows(model: ExudynModel, cols: dict[str, np.ndarray], node_type: str,
               dt: float) -> pd.DataFrame:
    """One row per revolution: constraint violations, rotation coordinates, input angle and time
    grid, work, efficiency."""
    t = cols["t"]
    theta = cols["theta_in"]
    n = len(t)
    revs = whole_revolutions(theta)
    index = revolution_index(theta, revs)
    # a failed run's rows after its last whole revolution are left out of the maxima
    inside = np.abs(theta - theta[0]) <= 2.0 * math.pi * (revs + 1e-6)
    index = np.where(inside, index, 0)
    rows: dict[str, Any] = {"node_type": node_type, "revolution": np.arange(1, revs + 1),
                            "t_end_s": at_revolutions(t, theta, revs)[1:]}
    for key, values in pair_violations(model.pair_kinematics).items():
        rows[key] = per_revolution_max(values, index, revs)
    kinds = {name: rotation.name for name, rotation in model.rotations.items()}
    for key, values in rotation_health(kinds, body_states(model), n).items():
        rows[key] = per_revolution_max(values, index, revs)
    drive = model.scene.drive
    if drive.kind == "speed":
        error = theta - theta[0] - drive.speed * (t - t[0])
        rows["input_angle_error_rad"] = at_revolutions(error, theta, revs)[1:]
    # Exudyn's step times against i dt (would show an accumulated rounding of t; measured zero)
    rows["time_grid_error_s"] = per_revolution_max(np.abs(t - t[0] - dt * np.arange(n)), index, revs)
    rows.update(_work_rows(cols, theta, revs))
    return pd.DataFrame(rows)


def drift_run(node_type: str, revolutions: int) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One long run with friction: the per-revolution rows (of the revolutions completed, also
    when the run fails) and what the run cost."""
    summary, model, cols = simulate(drift_scene(revolutions), ExudynOptions(node_type=node_type))
    info: dict[str, Any] = {"node_type": node_type, "status": summary["status"],
                            "reason": summary["reason"], "dt": summary["dt"],
                            "steps_per_revolution": DRIFT_STEPS_PER_REVOLUTION,
                            "requested_revolutions": revolutions,
                            "solve_wall_time_s": summary["solve_wall_time_s"],
                            "wall_time_s": summary["wall_time_s"]}
    if len(cols.get("t", ())) < 2:
        info["completed_revolutions"] = 0
        return pd.DataFrame(), info
    rows = drift_rows(model, cols, node_type, summary["dt"])
    steps = len(cols["t"]) - 1
    turned = abs(cols["theta_in"][-1] - cols["theta_in"][0]) / (2.0 * math.pi)
    coordinate = stored(model, "input_q")[:, 4]  # the input's angle coordinate, as the solver had it
    info.update(steps=steps, completed_revolutions=len(rows), ended_at_revolution=turned,
                ended_at_s=float(cols["t"][-1]), input_turns_removed=model.input_turns.count,
                input_coordinate_max_abs_rad=float(np.abs(coordinate).max()),
                newton_iterations_per_step=summary["newton_iterations"] / steps,
                friction_evaluations_per_step=summary["friction"]["mean_iterations_per_step"],
                unconverged_friction_steps=summary["friction"]["unconverged_steps"])
    return rows, info


def energy_case_exudyn(shaft_angle_deg: float, revolutions: int, steps_per_revolution: int | None,
                       rho: float, label: str) -> tuple[dict[str, Any], np.ndarray]:
    """One free-spinning Exudyn run: case description and relative energy per revolution."""
    scene = energy_scene(shaft_angle_deg, revolutions, steps_per_revolution)
    summary, model, _ = simulate(scene, ExudynOptions(spectral_radius=rho), columns=False)
    states = body_states(model)
    n = min(len(s["t"]) for s in states.values())
    info = {"case": label, "engine": ENGINE, "shaft_angle_deg": shaft_angle_deg,
            "spectral_radius": rho, "status": summary["status"], "reason": summary["reason"],
            "dt": summary["dt"], "dt_choice": summary["dt_choice"],
            "wall_time_s": summary["wall_time_s"]}
    if n < 2:
        info.update(completed_revolutions=0, relative_drift=float("nan"))
        return info, np.zeros(0)
    kinetic, potential = mechanical_energy(model, states, n)
    theta = states["input"]["psi"][:n, 0]
    measures = energy_measures(theta, kinetic + potential, revolutions)
    relative = measures.pop("relative")
    info.update(measures)
    info["steps"] = n - 1
    info["steps_per_revolution"] = (n - 1) / max(abs(theta[-1] - theta[0]) / (2 * math.pi), 1e-300)
    info["nominal_steps_per_revolution"] = (steps_per_revolution if steps_per_revolution
                                            else round(2 * math.pi / scene.drive.initial_speed
                                                       / summary["dt"]))
    if info["status"] == Status.OK and measures["completed_revolutions"] < revolutions:
        info.update(status=Status.INCOMPLETE,
                    reason=f"{measures['completed_revolutions']} of {revolutions} revolutions")
    return info, relative


def energy_case_reference(shaft_angle_deg: float, revolutions: int,
                          label: str) -> tuple[dict[str, Any], np.ndarray]:
    """The same free-spinning scene with the reference engine (DOP853 on the input angle)."""
    scene = replace(energy_scene(shaft_angle_deg, revolutions), **{"record.timeseries": True})
    start = time.perf_counter()
    result = run(scene, REFERENCE, ReferenceOptions(samples_per_revolution=64))
    s = result.summary
    info = {"case": label, "engine": REFERENCE, "shaft_angle_deg": shaft_angle_deg,
            "spectral_radius": float("nan"), "status": s.status, "reason": s.reason,
            "wall_time_s": time.perf_counter() - start, "ode_evaluations": s.ode_evaluations,
            "steps_per_revolution": float("nan"), "nominal_steps_per_revolution": float("nan")}
    if result.table is None or len(result.table) < 2:
        info.update(completed_revolutions=0, relative_drift=float("nan"))
        return info, np.zeros(0)
    t = result.table
    measures = energy_measures(t["theta_in"].to_numpy(),
                               (t["energy_kinetic"] + t["energy_potential"]).to_numpy(), revolutions)
    relative = measures.pop("relative")
    info.update(measures)
    return info, relative


def _isolated(call: Callable[..., tuple[dict[str, Any], np.ndarray]], args: tuple, label: str,
              engine_name: str, angle: float, rho: float) -> tuple[dict[str, Any], np.ndarray]:
    """``call(*args)``, or a case that records the exception."""
    try:
        return call(*args)
    except Exception as exc:  # the study goes on past a broken case, whose record says why
        return ({"case": label, "engine": engine_name, "shaft_angle_deg": angle,
                 "spectral_radius": rho, "status": "error",
                 "reason": f"{type(exc).__name__}: {exc}", "completed_revolutions": 0,
                 "relative_drift": float("nan"), "wall_time_s": float("nan")}, np.zeros(0))


@dataclass
class LongRuns:
    """Per-revolution drift rows (a), relative energy per revolution (b), and the summary."""

    drift: pd.DataFrame
    energy: pd.DataFrame
    summary: dict[str, Any] = field(default_factory=dict)

    def errors(self) -> list[tuple[str, str]]:
        """(run, reason) of every drift run and energy case that raised in the harness."""
        runs = [(f"drift {name}", info["reason"]) for name, info in self.summary["drift"].items()
                if info["status"] == "error"]
        return runs + [(c["case"], c["reason"]) for c in self.summary["energy"]["cases"]
                       if c["status"] == "error"]

    def status_line(self) -> str:
        """The statuses in a line: each drift run's, and how many energy cases ended ok."""
        drift = ", ".join(f"{name} {info['status']}" for name, info in self.summary["drift"].items())
        cases = self.summary["energy"]["cases"]
        ok = sum(c["status"] == Status.OK for c in cases)
        return f"drift {drift}; energy {ok} of {len(cases)} cases ok"


def run_drift(plan: LongRunPlan, say: Say) -> tuple[pd.DataFrame, list[dict[str, Any]]]:
    """(a) The drift runs with friction, one per node type: per-revolution rows and run infos."""
    frames = []
    runs = []
    for node_type in plan.node_types:
        say(f"drift: {node_type} nodes, {plan.drift_revolutions} revolutions of {DRIFT_SCENE} with friction")
        try:
            rows, info = drift_run(node_type, plan.drift_revolutions)
        except Exception as exc:  # the study goes on past a broken run, whose record says why
            rows = pd.DataFrame()
            info = {"node_type": node_type, "status": "error",
                    "reason": f"{type(exc).__name__}: {exc}", "wall_time_s": float("nan")}
        frames.append(rows)
        runs.append(info)
        gc.collect()  # the run's model (a reference cycle with its friction) holds ~1 GB
        say(f"drift: {node_type} {info['status']} in {info['wall_time_s']:.1f} s")
    return (pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()), runs


def _energy_frame(info: dict[str, Any], relative: np.ndarray, steps: int | None) -> pd.DataFrame:
    return pd.DataFrame({
        "case": info["case"], "engine": info["engine"], "shaft_angle_deg": info["shaft_angle_deg"],
        "steps_per_revolution": info.get("nominal_steps_per_revolution", steps),
        "spectral_radius": info["spectral_radius"], "revolution": np.arange(relative.size),
        "relative_energy_deviation": relative})


def energy_cases(plan: LongRunPlan, angle: float) -> list[EnergyCase]:
    """The energy cases at one shaft angle [deg]: Exudyn's (:func:`.plan.energy_plan`)
    and the reference engine's."""
    cases = [(case_label(ENGINE, angle, steps, rho), energy_case_exudyn,
              (angle, plan.energy_revolutions, steps, rho), ENGINE, rho, steps)
             for steps, rho in energy_plan(plan, angle)]
    cases.append((case_label(REFERENCE, angle), energy_case_reference,
                  (angle, plan.reference_revolutions), REFERENCE, float("nan"), None))
    return cases


def run_energy(plan: LongRunPlan, say: Say) -> tuple[pd.DataFrame, list[dict[str, Any]]]:
    """(b) The free-spinning runs: relative energy per revolution and one info per case."""
    infos = []
    frames = []
    for angle in plan.energy_angles:
        for label, call, args, engine_name, rho, steps in energy_cases(plan, angle):
            revolutions = args[1]
            say(f"energy: {label}, {revolutions} revolutions")
            info, relative = _isolated(call, (*args, label), label, engine_name, angle, rho)
            infos.append(info)
            frames.append(_energy_frame(info, relative, steps))
            say(f"energy: {label}: {info['status']}, drift {info['relative_drift']:.3g} "
                f"in {info['wall_time_s']:.1f} s")
    return (pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()), infos


def long_runs(quick: bool = False, progress: Say | None = None,
              plan: LongRunPlan | None = None) -> LongRuns:
    """Run the long-run study: (a) drift with friction per node type, (b) energy conservation.

    Parameters
    ----------
    quick : bool
        The :data:`~.plan.QUICK` variant (20 revolutions with friction for Rxyz and EP,
        20 free-spinning revolutions at 35 deg with a short ladder, the reference engine for 2)
        instead of :data:`~.plan.FULL`; the first/last windows shrink to a quarter of the run.
    progress : callable, optional
        Called with a line of text as each run starts and ends.
    plan : LongRunPlan, optional
        Another variant (overrides ``quick``).

    Returns
    -------
    LongRuns
        The per-revolution drift rows, the relative energy per revolution of every energy case,
        and the summary (:func:`.summary.summarise`).
    """
    plan = plan or (QUICK if quick else FULL)
    say = progress or (lambda text: None)
    started = time.perf_counter()
    drift, runs = run_drift(plan, say)
    drift_wall = time.perf_counter() - started
    energy, cases = run_energy(plan, say)
    walls = {"drift": drift_wall, "energy": time.perf_counter() - started - drift_wall,
             "total": time.perf_counter() - started}
    return LongRuns(drift=drift, energy=energy, summary=summarise(drift, runs, cases, plan, walls))
