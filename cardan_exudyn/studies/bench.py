"""``cardan bench``: work-precision runs of every engine on a small fixed set of scenes.

For each scene of :data:`SCENES` (frictionless and with the paper's friction, 10 and 35 deg, at
2000 rpm) and each engine configuration (:func:`configurations`: Exudyn's step size, Newton
settings, node type, friction coupling and velocity projection; the reference engine's sampling
and quadrature tolerance; MuJoCo with its recommended settings and a shorter constraint time
constant, frictionless scenes only) the bench records

- the errors against the reference engine, which is exact for prescribed motion
  (:func:`run_errors`): largest error of ``omega_out / omega_in`` against Hooke's law, largest
  drive-torque error over the whole run and after the first revolution (the generalized-alpha
  start-up transient is in the first), the mean-efficiency error (friction scenes; without
  friction every engine reports exactly 1) and the mean-input-torque error;
- the median wall time of ``repeats`` runs of the engine's ``run`` (model build, solve and the
  result table: what a caller pays), per simulated second; the repeats run in rounds over all
  configurations, so that a change in the machine's load hits every configuration alike;
- the cost counters the engine reports (steps, Newton iterations, Jacobians, friction
  evaluations per step).

Then it evaluates the targets of :data:`TARGETS` side by side from the same run
(:func:`evaluate_targets`), times the paper's eleven scenes with both engines
(:func:`paper_scenes_timing`) and measures what each "skip" of the Exudyn build saves
(:func:`skip_audit`). Results go to a folder (atomically): ``bench.csv`` and ``audit.csv`` opening
with an environment header, ``targets.csv``, ``bench.json``, ``report.md`` and the log-log
work-precision plot ``work_precision.png``.
"""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from dataclasses import replace as dc_replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.model.solve import ExudynOptions
from cardan_exudyn.io import atomic_directory, dumps
from reference.engine import ReferenceOptions, columns_at, input_motion
from reference.engine import run as reference_run
from reference.kinematics import speed_ratio
from reference.paper import named_scene, paper_cases, paper_scene
from reference.scene import Scene, replace

# the fixed scene set: key -> named scene (all at 2000 rpm, the paper's masses, load and gravity)
SCENES = {
    "frictionless-10deg": "paper-10deg-frictionless",
    "frictionless-35deg": "paper-35deg-frictionless",
    "friction-10deg": "paper-10deg",
    "friction-35deg": "paper-35deg",
}

SPEED_RATIO_TARGET = 2e-5      # equal-accuracy level of the kinematic target [-]
EFFICIENCY_TARGET = 1e-4       # mean-efficiency accuracy of the friction targets [-]
FRICTION_COST_TARGET = 1.5     # friction run / frictionless run at the same step
PAPER_EXUDYN_TARGET_S = 10.0   # the eleven paper scenes with Exudyn [s]
PAPER_REFERENCE_TARGET_S = 0.5  # ... with the reference engine [s]
TARGETS = {
    "kinematics": f"frictionless: Exudyn's wall time per simulated second <= MuJoCo's best at a "
                  f"speed-ratio error <= {SPEED_RATIO_TARGET:g}",
    "friction_cost": f"friction: mean efficiency within {EFFICIENCY_TARGET:g} of the reference at "
                     f"<= {FRICTION_COST_TARGET:g} x the frictionless run's cost at the same step",
    "paper_exudyn": f"the eleven paper scenes within {EFFICIENCY_TARGET:g} in < "
                    f"{PAPER_EXUDYN_TARGET_S:g} s with Exudyn",
    "paper_reference": f"the eleven paper scenes within {EFFICIENCY_TARGET:g} in < "
                       f"{PAPER_REFERENCE_TARGET_S:g} s with the reference engine",
}

# Exudyn settings compared. "tuned": modified Newton with one Jacobian per step and a relative
# Newton tolerance of 1e-8 (the speed-ratio and efficiency errors do not change: the bench shows
# it); "default": the engine's defaults (full Newton, 1e-10).
EXUDYN_DEFAULT = ExudynOptions()
EXUDYN_TUNED = ExudynOptions(modified_newton=True, jacobian_every_step=True,
                             newton_relative_tolerance=1e-8)
# the paper scenes' run (summary only) and the default of `cardan bench --paper`
PAPER_EXUDYN_STEPS = 800
PAPER_REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=36, quadrature_rtol=1e-6)

FULL_LADDER = {"exudyn": (25, 50, 100, 200, 400, 800, 1600), "mujoco": (20, 25, 30, 40, 60, 100, 200),
               "reference": (36, 360)}
QUICK_LADDER = {"exudyn": (50, 200, 800), "mujoco": (25, 60), "reference": (36,)}


class BenchError(ValueError):
    """Bad bench input (unknown scene key, engine, bad repeats)."""


@dataclass(frozen=True)
class Config:
    """One engine configuration at one resolution.

    ``steps``: steps (Exudyn, MuJoCo) or table samples (reference) per input revolution.
    """

    engine: str
    label: str
    steps: int
    options: Any = None
    coupling: str | None = None

    def scene(self, base: Scene) -> Scene:
        period = 2.0 * math.pi / base.drive.max_speed()
        changes: dict[str, Any] = {}
        if self.engine != "reference":
            changes["numerics.dt"] = period / self.steps
        if self.coupling is not None:
            changes["friction.coupling"] = self.coupling
        return replace(base, **changes) if changes else base

    def run(self, scene: Scene):
        if self.engine == "exudyn":
            from cardan_exudyn.model.solve import run

            return run(scene, self.options)
        if self.engine == "mujoco":
            from cardan_exudyn.mujoco_engine import run

            return run(scene, self.options)
        options = dc_replace(self.options or ReferenceOptions(), samples_per_revolution=self.steps)
        return reference_run(scene, options)

    def describe(self) -> dict[str, Any]:
        opts = self.options
        if hasattr(opts, "to_dict"):
            opts = opts.to_dict()
        elif opts is not None:
            opts = {k: getattr(opts, k) for k in opts.__dataclass_fields__}
        return {"engine": self.engine, "config": self.label, "steps_per_revolution": self.steps,
                "coupling": self.coupling, "options": opts}


def _mujoco_available() -> bool:
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def _node_types() -> tuple[str, ...]:
    """Node types of the spider and output (the Rxyz default first)."""
    from cardan_exudyn.model.solve import NODE_TYPES

    return NODE_TYPES


def exudyn_settings(friction: bool, quick: bool) -> list[tuple[str, ExudynOptions, str | None]]:
    """``(label, options, coupling)`` of the Exudyn configurations for a scene kind."""
    out = [("exudyn default", EXUDYN_DEFAULT, None), ("exudyn tuned", EXUDYN_TUNED, None)]
    if friction:
        out.append(("exudyn tuned lagged", EXUDYN_TUNED, "lagged"))
    else:
        out.append(("exudyn tuned + projection", dc_replace(EXUDYN_TUNED, velocity_projection=True),
                    None))
    if not quick:
        for node in _node_types()[1:]:
            out.append((f"exudyn tuned {node}", dc_replace(EXUDYN_TUNED, node_type=node), None))
    return out


def configurations(scene_key: str, quick: bool = False,
                   engines: Iterable[str] = ("exudyn", "mujoco", "reference")) -> list[Config]:
    """Every configuration benchmarked on ``scene_key``."""
    engines = set(engines)
    ladder = QUICK_LADDER if quick else FULL_LADDER
    friction = scene_key.startswith("friction-")
    out: list[Config] = []
    if "exudyn" in engines:
        for label, options, coupling in exudyn_settings(friction, quick):
            steps = ladder["exudyn"]
            if quick and label != "exudyn tuned":
                steps = steps[:2]
            out += [Config("exudyn", label, n, options, coupling) for n in steps]
    if "mujoco" in engines and not friction and _mujoco_available():
        from cardan_exudyn.mujoco_engine import MujocoOptions

        for tc in ((10.0,) if quick else (10.0, 20.0)):
            label = f"mujoco RK4 tc {tc:g} dt" + (" (recommended)" if tc == 20.0 else "")
            out += [Config("mujoco", label, n, MujocoOptions(timeconst_steps=tc))
                    for n in ladder["mujoco"]]
    if "reference" in engines:
        for rtol in ((1e-6,) if quick else (1e-9, 1e-6, 1e-4)):
            out += [Config("reference", f"reference rtol {rtol:g}", n,
                           ReferenceOptions(quadrature_rtol=rtol)) for n in ladder["reference"]]
    return out


@dataclass
class Yardstick:
    """The reference engine's exact answer for one scene."""

    scene: Scene
    motion: Any
    summary: dict[str, Any]


def yardstick(scene: Scene) -> Yardstick:
    """Reference run at its default (tightest) settings."""
    options = ReferenceOptions()
    result = reference_run(replace(scene, **{"record.timeseries": False}), options)
    if not result.ok:
        raise BenchError(f"the reference engine cannot solve {scene.name!r}: {result.summary['reason']}")
    return Yardstick(scene, input_motion(scene, options), result.summary)


def run_errors(scene: Scene, result, yard: Yardstick) -> dict[str, float]:
    """Error measures of one run against the reference (NaN when the run has no table/means).

    ``speed_ratio_error``: max ``|omega_out/omega_in - Hooke(theta_in)|``;
    ``torque_in_error``: max ``|torque_in - reference|`` over the reference's largest
    ``|torque_in|`` over all rows, ``torque_in_error_steady`` the same after the first input
    revolution; ``mean_efficiency_error``: ``|eta - eta_ref|`` (friction scenes);
    ``mean_torque_in_error``: relative error of the mean input torque.
    """
    keys = ("speed_ratio_error", "torque_in_error", "torque_in_error_steady",
            "mean_efficiency_error", "mean_torque_in_error")
    out = dict.fromkeys(keys, float("nan"))
    s, table = result.summary, result.table
    if s.get("status") != "ok" or table is None:
        return out
    t = table["t"].to_numpy()
    theta = table["theta_in"].to_numpy()
    ratio = table["omega_out"].to_numpy() / table["omega_in"].to_numpy()
    hooke = speed_ratio(theta, scene.joint.geometry.shaft_angle)
    out["speed_ratio_error"] = float(np.max(np.abs(ratio - hooke)))
    ref = columns_at(scene, yard.motion, t)["torque_in"]
    scale = float(np.max(np.abs(ref)))
    diff = np.abs(table["torque_in"].to_numpy() - ref) / scale
    out["torque_in_error"] = float(np.max(diff))
    steady = np.abs(theta - theta[0]) >= 2.0 * math.pi - 1e-9
    if np.any(steady):
        out["torque_in_error_steady"] = float(np.max(diff[steady]))
    if scene.has_friction:
        out["mean_efficiency_error"] = abs(s["mean_efficiency"] - yard.summary["mean_efficiency"])
    ref_mean = yard.summary["mean_torque_in"]
    out["mean_torque_in_error"] = abs(s["mean_torque_in"] - ref_mean) / abs(ref_mean)
    return out


def cost_counters(summary: dict[str, Any]) -> dict[str, Any]:
    """The engine's own cost counters, flattened."""
    out = {k: summary.get(k) for k in ("steps", "newton_iterations", "jacobian_evaluations")}
    friction = summary.get("friction") or {}
    out["friction_evaluations_per_step"] = friction.get("mean_iterations_per_step")
    quad = summary.get("quadrature") or {}
    out["quadrature_panels"] = quad.get("panels") if isinstance(quad, dict) else None
    return out


def _progress(enabled: bool) -> Callable[[str], None]:
    def say(text: str) -> None:
        if enabled:
            print(text, file=sys.stderr, flush=True)
    return say


def _simulated_time(scene: Scene) -> float:
    return 2.0 * math.pi * scene.revolutions / scene.drive.max_speed()


def work_precision(scene_keys: Iterable[str], quick: bool, repeats: int,
                   engines: Iterable[str] = ("exudyn", "mujoco", "reference"),
                   progress: bool = False) -> pd.DataFrame:
    """Run every configuration of every scene ``repeats`` times (in rounds); one row per config."""
    say = _progress(progress)
    jobs = []
    for key in scene_keys:
        base = named_scene(SCENES[key])
        yard = yardstick(base)
        for config in configurations(key, quick, engines):
            jobs.append((key, config, config.scene(base), yard))
    times: dict[int, list[float]] = {i: [] for i in range(len(jobs))}
    first: dict[int, dict[str, Any]] = {}
    total = len(jobs) * repeats
    done = 0
    start = time.perf_counter()
    for round_ in range(repeats):
        for i, (key, config, scene, yard) in enumerate(jobs):
            t0 = time.perf_counter()
            try:
                result = config.run(scene)
                error = ""
            except Exception as exc:  # a configuration that cannot run is a row, not a crash
                result, error = None, f"{type(exc).__name__}: {exc}"
            wall = time.perf_counter() - t0
            done += 1
            if result is not None and result.ok:
                times[i].append(wall)
            if round_ == 0:
                record = {"scene": key, **config.describe()}
                if result is None:
                    record.update(status="error", reason=error[:300])
                else:
                    record.update(status=result.summary.get("status"),
                                  reason=str(result.summary.get("reason", ""))[:300],
                                  mean_efficiency=result.summary.get("mean_efficiency"),
                                  **run_errors(scene, result, yard), **cost_counters(result.summary))
                record["simulated_s"] = _simulated_time(scene)
                first[i] = record
            say(f"[{done}/{total} {time.perf_counter() - start:6.1f} s] {key:20s} {config.label:28s} "
                f"n={config.steps:<5d} {wall:7.3f} s {first[i]['status']}")
    rows = []
    for i in range(len(jobs)):
        record = first[i]
        wall = float(np.median(times[i])) if times[i] else float("nan")
        record.update(wall_s=wall, wall_per_simulated_s=wall / record["simulated_s"],
                      runs_timed=len(times[i]))
        rows.append(record)
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------- targets
def _best(rows: pd.DataFrame, error: str, level: float) -> pd.Series | None:
    ok = rows[(rows["status"] == "ok") & (rows[error] <= level) & rows["wall_per_simulated_s"].notna()]
    if ok.empty:
        return None
    return ok.loc[ok["wall_per_simulated_s"].idxmin()]


def _describe_row(row: pd.Series | None) -> str:
    if row is None:
        return "none reaches the level"
    return f"{row['config']}, {int(row['steps_per_revolution'])} steps/rev"


def evaluate_targets(rows: pd.DataFrame, paper: dict[str, Any] | None) -> list[dict[str, Any]]:
    """The targets of :data:`TARGETS` with their measured ratios, from one bench run."""
    out = []
    for key in SCENES:
        scene_rows = rows[rows["scene"] == key]
        if scene_rows.empty:
            continue
        if key.startswith("frictionless-"):
            mj = _best(scene_rows[scene_rows["engine"] == "mujoco"], "speed_ratio_error", SPEED_RATIO_TARGET)
            ex_all = scene_rows[scene_rows["engine"] == "exudyn"]
            projected = ex_all["config"].str.contains("projection")
            for variant, sel in (("integrator velocities", ex_all[~projected]),
                                 ("velocity projection", ex_all[projected])):
                if sel.empty:
                    continue
                ex = _best(sel, "speed_ratio_error", SPEED_RATIO_TARGET)
                ratio = (ex["wall_per_simulated_s"] / mj["wall_per_simulated_s"]
                         if ex is not None and mj is not None else float("nan"))
                out.append({"target": "kinematics", "scene": key, "variant": variant,
                            "exudyn": _describe_row(ex), "other": "MuJoCo: " + _describe_row(mj),
                            "measured": ratio, "limit": 1.0,
                            "met": bool(np.isfinite(ratio) and ratio <= 1.0),
                            "detail": _kinematics_detail(ex, mj)})
        else:
            angle = key.split("-")[1]
            free = rows[rows["scene"] == f"frictionless-{angle}"]
            ex_all = scene_rows[scene_rows["engine"] == "exudyn"]
            for label in ex_all["config"].unique():
                sel = ex_all[ex_all["config"] == label]
                best = _best(sel, "mean_efficiency_error", EFFICIENCY_TARGET)
                ratio = float("nan")
                detail = "no step size on the ladder reaches the accuracy"
                if best is not None:
                    twin_label = label.replace(" lagged", "")
                    twin = free[(free["config"] == twin_label)
                                & (free["steps_per_revolution"] == best["steps_per_revolution"])]
                    if not twin.empty:
                        ratio = best["wall_per_simulated_s"] / twin.iloc[0]["wall_per_simulated_s"]
                        detail = (f"efficiency error {best['mean_efficiency_error']:.2g}; "
                                  f"{best['wall_per_simulated_s']:.3g} vs frictionless "
                                  f"{twin.iloc[0]['wall_per_simulated_s']:.3g} s per simulated s; "
                                  f"friction evaluations per step "
                                  f"{_num(best, 'friction_evaluations_per_step')}")
                    else:
                        detail = "no frictionless run at the same step to compare with"
                out.append({"target": "friction_cost", "scene": key, "variant": label,
                            "exudyn": _describe_row(best), "other": "", "measured": ratio,
                            "limit": FRICTION_COST_TARGET,
                            "met": bool(np.isfinite(ratio) and ratio <= FRICTION_COST_TARGET),
                            "detail": detail})
    if paper:
        for engine, limit, name in (("exudyn", PAPER_EXUDYN_TARGET_S, "paper_exudyn"),
                                    ("reference", PAPER_REFERENCE_TARGET_S, "paper_reference")):
            part = paper[engine]
            met = (part["wall_s"] < limit and part["max_error"] <= EFFICIENCY_TARGET
                   and part["failed"] == 0)
            out.append({"target": name, "scene": "paper's eleven", "variant": part["config"],
                        "exudyn": "", "other": "", "measured": part["wall_s"], "limit": limit,
                        "met": bool(met),
                        "detail": (f"largest mean-efficiency error {part['max_error']:.2g} "
                                   f"(limit {EFFICIENCY_TARGET:g}); {part['failed']} runs not ok; "
                                   f"median of {part['repeats']}")})
    return out


def _kinematics_detail(ex: pd.Series | None, mj: pd.Series | None) -> str:
    return (f"wall per simulated second Exudyn {_num(ex, 'wall_per_simulated_s')} s, MuJoCo "
            f"{_num(mj, 'wall_per_simulated_s')} s; speed-ratio error {_num(ex, 'speed_ratio_error')} "
            f"vs {_num(mj, 'speed_ratio_error')}; drive-torque error after rev. 1 "
            f"{_num(ex, 'torque_in_error_steady')} vs {_num(mj, 'torque_in_error_steady')}")


def _num(row: pd.Series | None, key: str) -> str:
    if row is None or key not in row or row[key] is None or not np.isfinite(row[key]):
        return "-"
    return f"{row[key]:.3g}"


# ------------------------------------------------------------------------- paper's eleven
def paper_scenes(parameters: str = "plain") -> list[Scene]:
    """The paper's eleven scenes with friction (Table 2 and the speed study), summary only."""
    return [replace(paper_scene(c["shaft_angle_deg"], c["speed_rpm"], parameters=parameters),
                    **{"record.timeseries": False}) for c in paper_cases()]


def paper_scenes_timing(repeats: int = 3, exudyn_steps: int = PAPER_EXUDYN_STEPS,
                        exudyn_options: ExudynOptions = EXUDYN_TUNED,
                        reference_options: ReferenceOptions = PAPER_REFERENCE_OPTIONS,
                        progress: bool = False) -> dict[str, Any]:
    """Wall time of the eleven scenes, one after the other in this process, per engine.

    Exudyn runs at ``exudyn_steps`` per revolution with ``exudyn_options``; the reference with
    ``reference_options``. Errors are against the reference at its default (tight) settings.
    """
    say = _progress(progress)
    scenes = paper_scenes()
    exact = [yardstick(s).summary["mean_efficiency"] for s in scenes]
    from cardan_exudyn.model.solve import run as exudyn_run

    def exudyn_one(scene: Scene):
        period = 2.0 * math.pi / scene.drive.max_speed()
        return exudyn_run(replace(scene, **{"numerics.dt": period / exudyn_steps}), exudyn_options)

    runners = {"exudyn": exudyn_one, "reference": lambda s: reference_run(s, reference_options)}
    out: dict[str, Any] = {}
    walls: dict[str, list[float]] = {k: [] for k in runners}
    last: dict[str, list] = {}
    for round_ in range(repeats):
        for engine, runner in runners.items():
            t0 = time.perf_counter()
            results = [runner(s) for s in scenes]
            walls[engine].append(time.perf_counter() - t0)
            last[engine] = results
            say(f"paper scenes round {round_ + 1}/{repeats} {engine}: {walls[engine][-1]:.2f} s")
    for engine, results in last.items():
        errors = [abs(r.summary["mean_efficiency"] - e) if r.ok else float("nan")
                  for r, e in zip(results, exact, strict=True)]
        finite = [e for e in errors if np.isfinite(e)]
        out[engine] = {
            "config": (f"tuned, {exudyn_steps} steps/rev" if engine == "exudyn"
                       else f"samples {reference_options.samples_per_revolution}/rev, quadrature "
                            f"rtol {reference_options.quadrature_rtol:g}"),
            "wall_s": float(np.median(walls[engine])), "walls_s": walls[engine],
            "max_error": max(finite) if finite else float("nan"), "errors": errors,
            "failed": sum(not r.ok for r in results), "repeats": repeats,
            "scenes": [s.name for s in scenes],
        }
    return out


# ------------------------------------------------------------------------------ skip audit
def _solve_only(scene: Scene, options: ExudynOptions,
                tweak: Callable[[Any, Any], None] | None = None) -> float:
    """Wall time of build + solve (no post-processing), with ``tweak(model, settings)``."""
    import exudyn as exu

    from cardan_exudyn.model.solve import end_time, simulation_settings
    from cardan_exudyn.model.build import build_model
    from cardan_exudyn.model.stepsize import choose_step

    t0 = time.perf_counter()
    model = build_model(scene, reactions=options.records_reactions(scene),
                        node_type=options.node_type)
    dt, _ = choose_step(scene)
    settings = simulation_settings(dt, model.start_time, end_time(scene, model.start_time), options)
    if tweak is not None:
        tweak(model, settings)
    solver = exu.MainSolverImplicitSecondOrder()
    if not solver.SolveSystem(model.mbs, settings):
        raise RuntimeError(f"audit run failed: {solver.GetErrorString()}")
    return time.perf_counter() - t0


def _pre_step(model, settings) -> None:
    def no_op(mbs, t):
        return True

    model.user_functions.append(no_op)
    model.mbs.SetPreStepUserFunction(no_op)


def _solution_file(folder: str) -> Callable[[Any, Any], None]:
    def tweak(model, settings) -> None:
        settings.solution.file.write = True
        settings.solution.file.name = os.path.join(folder, "solution.txt")
        settings.solution.file.writePeriod = 0.0
    return tweak


def _as_angle_history(scene: Scene) -> Scene:
    """The same constant speed as an angle history (a Python offset function every evaluation)."""
    w = scene.drive.speed
    span = _simulated_time(scene) * 1.5
    t = np.linspace(0.0, span, 8)
    return replace(scene, drive={"kind": "angle", "time": t.tolist(), "angle": (w * t).tolist()})


def _fast_module_time(scene_name: str, steps: int, revolutions: float, runs: int,
                      fast: bool) -> float:
    """Median wall of ``runs`` in-process runs in a child Python with or without the fast module."""
    code = (
        "import sys, time, math, statistics\n"
        f"sys.exudynFast = {fast!r}\n"
        "import contextlib, io\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    import exudyn\n"
        "from cardan_exudyn.model.solve import run\n"
        "from cardan_exudyn.studies.bench import EXUDYN_TUNED\n"
        "from reference.paper import named_scene\n"
        "from reference.scene import replace\n"
        f"s = named_scene({scene_name!r})\n"
        f"s = replace(s, **{{'numerics.dt': 2*math.pi/s.drive.speed/{steps}, "
        f"'record.timeseries': False, 'revolutions': {revolutions!r}}})\n"
        "run(s, EXUDYN_TUNED)\n"
        "w = []\n"
        f"for _ in range({runs}):\n"
        "    t0 = time.perf_counter(); r = run(s, EXUDYN_TUNED); w.append(time.perf_counter() - t0)\n"
        "    assert r.ok, r.summary['reason']\n"
        "print(statistics.median(w))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "EXUDYN_MODULE"}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
    return float(proc.stdout.strip().splitlines()[-1])


def skip_audit(repeats: int = 5, steps: int = 200, revolutions: float = 10.0,
               progress: bool = False, fast_module: bool = True) -> pd.DataFrame:
    """What each thing the Exudyn build leaves out (or each solver choice) saves, measured.

    Each item is a pair of runs that differ only in that item, on the frictionless 10 deg scene
    at ``steps`` per revolution for ``revolutions`` (summary only unless the item is the table;
    long enough that the run, not the timer, is measured); the pairs run in
    rounds, ``repeats`` times, and the medians give ``with / without`` (how much slower the run
    is with the item) and the share of the run the removal saves.
    """
    say = _progress(progress)
    base = named_scene(SCENES["frictionless-10deg"])
    period = 2.0 * math.pi / base.drive.speed
    base = replace(base, **{"numerics.dt": period / steps, "record.timeseries": False,
                            "revolutions": revolutions})
    tuned = EXUDYN_TUNED
    from cardan_exudyn.model.solve import run as exudyn_run

    folder = tempfile.mkdtemp(prefix="cardan-audit-")

    def full(scene, options):
        return lambda: _timed_run(exudyn_run, scene, options)

    items = [
        ("pair-reaction sensors (summary only)", "8 stored sensors the summary does not use",
         full(base, tuned), full(base, dc_replace(tuned, sensors="all"))),
        ("result table and its post-processing", "columns and DataFrame when only the summary is asked",
         full(base, dc_replace(tuned, sensors="all")),
         full(replace(base, **{"record.timeseries": True}), dc_replace(tuned, sensors="all"))),
        ("gravity loads when g = 0", "3 mass-proportional loads of zero effect",
         full(replace(base, gravity=(0.0, 0.0, 0.0)), tuned),
         full(replace(base, gravity=(0.0, 0.0, -1e-300)), tuned)),
        ("Python drive function", "constant speed as a velocity-level connector instead of an "
         "angle history evaluated in Python", full(base, tuned), full(_as_angle_history(base), tuned)),
        ("Python pre-step function", "a no-op pre-step user function (needed only with friction "
         "or a torque drive)", lambda: _solve_only(base, tuned),
         lambda: _solve_only(base, tuned, _pre_step)),
        ("solution file", "Exudyn's default coordinates file, every step",
         lambda: _solve_only(base, tuned), lambda: _solve_only(base, tuned, _solution_file(folder))),
        ("full Newton (Jacobian every iteration)", "modified Newton, one Jacobian per step",
         full(base, tuned), full(base, dc_replace(tuned, modified_newton=False,
                                                   jacobian_every_step=False))),
        ("Newton tolerance 1e-10", "relative tolerance 1e-8",
         full(base, tuned), full(base, dc_replace(tuned, newton_relative_tolerance=1e-10))),
    ]
    walls = {i: ([], []) for i in range(len(items))}
    for round_ in range(repeats):
        for i, (_, _, without, with_) in enumerate(items):
            walls[i][0].append(without())
            walls[i][1].append(with_())
        say(f"skip audit round {round_ + 1}/{repeats}")
    rows = []
    for i, (name, what, _, _) in enumerate(items):
        w0, w1 = float(np.median(walls[i][0])), float(np.median(walls[i][1]))
        rows.append({"item": name, "removal": what, "without_s": w0, "with_s": w1,
                     "with_over_without": w1 / w0, "saved_share": 1.0 - w0 / w1})
    if fast_module:
        say("skip audit: Exudyn's fast module (child processes)")
        regular, fast = [], []
        try:
            for _ in range(2):
                regular.append(_fast_module_time(SCENES["frictionless-10deg"], steps, revolutions,
                                                 repeats, False))
                fast.append(_fast_module_time(SCENES["frictionless-10deg"], steps, revolutions,
                                              repeats, True))
            w0, w1 = float(np.median(fast)), float(np.median(regular))
            rows.append({"item": "range checks (regular module)",
                         "removal": "Exudyn's fast module exudynCPPfast (no range checks, AVX2)",
                         "without_s": w0, "with_s": w1, "with_over_without": w1 / w0,
                         "saved_share": 1.0 - w0 / w1})
        except (RuntimeError, subprocess.SubprocessError, ValueError) as exc:
            rows.append({"item": "range checks (regular module)", "removal": f"not measured: {exc}",
                         "without_s": float("nan"), "with_s": float("nan"),
                         "with_over_without": float("nan"), "saved_share": float("nan")})
    with contextlib.suppress(OSError):
        for name in os.listdir(folder):
            os.remove(os.path.join(folder, name))
        os.rmdir(folder)
    table = pd.DataFrame(rows)
    table.insert(0, "scene", f"{base.name}, {steps} steps/rev, summary only")
    return table


def _timed_run(run: Callable, scene: Scene, options: ExudynOptions) -> float:
    t0 = time.perf_counter()
    result = run(scene, options)
    wall = time.perf_counter() - t0
    if not result.ok:
        raise RuntimeError(f"audit run failed: {result.summary['reason']}")
    return wall


# ------------------------------------------------------------------------------ environment
def environment() -> dict[str, Any]:
    """Versions, CPU, date and commit (the header of every results file)."""
    from cardan_exudyn.sweep.runner import environment as sweep_environment

    return sweep_environment()


def _header(env: dict[str, Any]) -> str:
    lines = [f"# cardan bench, {env['date']}", f"# commit {env['commit']}",
             f"# cpu {env['cpu']} ({env['cpu_count']} logical), {env['platform']}",
             f"# python {env['python']}, " + ", ".join(f"{k} {v}" for k, v in env["packages"].items())]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------- output
@dataclass
class BenchResult:
    rows: pd.DataFrame
    targets: list[dict[str, Any]]
    paper: dict[str, Any] | None
    audit: pd.DataFrame | None
    environment: dict[str, Any]
    settings: dict[str, Any] = field(default_factory=dict)
    wall_s: float = 0.0

    def summary(self) -> dict[str, Any]:
        """What ``--json`` prints: environment, targets, paper timing, audit, best per scene."""
        best = []
        for (scene, config), sel in self.rows.groupby(["scene", "config"], sort=False):
            ok = sel[sel["status"] == "ok"]
            best.append({"scene": scene, "config": config, "runs": len(sel), "ok": len(ok),
                         "fastest_wall_per_simulated_s": float(ok["wall_per_simulated_s"].min())
                         if not ok.empty else None})
        return {"environment": self.environment, "settings": self.settings, "wall_s": self.wall_s,
                "targets": self.targets, "paper_scenes": self.paper,
                "audit": None if self.audit is None else self.audit.to_dict(orient="records"),
                "configurations": best}


def run_bench(quick: bool = False, repeats: int | None = None, scenes: Iterable[str] | None = None,
              engines: Iterable[str] = ("exudyn", "mujoco", "reference"), audit: bool = True,
              paper: bool = True, progress: bool = False) -> BenchResult:
    """The whole bench (see the module docstring)."""
    keys = list(scenes) if scenes is not None else list(SCENES)
    unknown = [k for k in keys if k not in SCENES]
    if unknown:
        raise BenchError(f"`--scenes` must be among {list(SCENES)}, got {unknown}")
    engines = list(engines)
    bad = [e for e in engines if e not in ("exudyn", "mujoco", "reference")]
    if bad:
        raise BenchError(f"`--engines` must be among exudyn, mujoco, reference, got {bad}")
    repeats = repeats if repeats is not None else (1 if quick else 3)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise BenchError(f"`--repeats` must be a positive integer, got {repeats!r}")
    start = time.perf_counter()
    env = environment()
    rows = work_precision(keys, quick, repeats, engines, progress)
    paper_result = None
    if paper and "exudyn" in engines and "reference" in engines:
        paper_result = paper_scenes_timing(repeats=repeats, progress=progress)
    audit_table = None
    if audit and "exudyn" in engines:
        audit_table = skip_audit(repeats=3 if quick else 7, progress=progress,
                                 fast_module=not quick)
    targets = evaluate_targets(rows, paper_result)
    return BenchResult(rows, targets, paper_result, audit_table, env,
                       {"quick": quick, "repeats": repeats, "scenes": keys, "engines": engines},
                       time.perf_counter() - start)


def write_bench(result: BenchResult, out: str | os.PathLike) -> Path:
    """The results folder, atomically."""
    from cardan_exudyn.report import plots

    header = _header(result.environment)
    with atomic_directory(out) as tmp:
        rows = result.rows.drop(columns=["options"])
        (tmp / "bench.csv").write_text(header + rows.to_csv(index=False, float_format="%.6g"),
                                       encoding="utf-8")
        pd.DataFrame(result.targets).to_csv(tmp / "targets.csv", index=False, float_format="%.4g")
        if result.audit is not None:
            (tmp / "audit.csv").write_text(header + result.audit.to_csv(index=False, float_format="%.4g"),
                                           encoding="utf-8")
        data = {**result.summary(), "rows": result.rows.to_dict(orient="records")}
        (tmp / "bench.json").write_text(dumps(data) + "\n", encoding="utf-8")
        fig = plots.work_precision(result.rows, SPEED_RATIO_TARGET, EFFICIENCY_TARGET)
        fig.savefig(tmp / "work_precision.png", dpi=120)
        plots.close(fig)
        (tmp / "report.md").write_text(report_markdown(result), encoding="utf-8")
    return Path(out)


def _md_table(df: pd.DataFrame, columns: list[str], fmt: dict[str, str] | None = None) -> str:
    fmt = fmt or {}
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for _, r in df.iterrows():
        cells = []
        for c in columns:
            v = r.get(c)
            if isinstance(v, (float, np.floating)):
                cells.append("-" if not np.isfinite(v) else format(v, fmt.get(c, ".3g")))
            elif v is None:
                cells.append("-")
            else:
                cells.append(str(v))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def report_markdown(result: BenchResult) -> str:
    env = result.environment
    out = [f"# cardan bench{' (quick)' if result.settings.get('quick') else ''}\n",
           f"{env['date']}, commit `{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical "
           f"CPUs), Python {env['python']}, "
           + ", ".join(f"{k} {v}" for k, v in env["packages"].items() if v) + ".\n",
           f"Median of {result.settings.get('repeats')} runs per configuration, run in rounds; "
           f"whole bench {result.wall_s:.0f} s. Wall time is the engine's `run` call (build, solve, "
           "result table) per simulated second. Errors against the reference engine (exact for "
           "prescribed motion). Machines here are shared: compare ratios within this run, not "
           "absolute times across runs.\n",
           "## Targets\n"]
    if result.targets:
        t = pd.DataFrame(result.targets)
        t["met"] = t["met"].map({True: "yes", False: "**no**"})
        out.append(_md_table(t, ["target", "scene", "variant", "measured", "limit", "met", "exudyn",
                                 "other", "detail"]))
    out.append("\nTargets: " + "; ".join(f"**{k}**: {v}" for k, v in TARGETS.items()) + ".\n")
    if result.paper:
        out.append("\n## The paper's eleven scenes (summary only, one after the other)\n")
        for engine, part in result.paper.items():
            out.append(f"- {engine} ({part['config']}): {part['wall_s']:.2f} s (median of "
                       f"{part['repeats']}; all: {', '.join(f'{w:.2f}' for w in part['walls_s'])}), "
                       f"largest mean-efficiency error {part['max_error']:.2g}, not ok: {part['failed']}\n")
    if result.audit is not None:
        out.append("\n## What each skip saves (Exudyn)\n")
        out.append(_md_table(result.audit, ["item", "removal", "without_s", "with_s",
                                            "with_over_without", "saved_share"],
                             {"without_s": ".4f", "with_s": ".4f", "with_over_without": ".2f",
                              "saved_share": ".0%"}))
        out.append(f"\nScene: {result.audit['scene'].iloc[0]}.\n")
    out.append("\n## Work-precision table\n")
    out.append(_md_table(result.rows, ["scene", "config", "steps_per_revolution", "status",
                                       "wall_per_simulated_s", "speed_ratio_error",
                                       "torque_in_error", "torque_in_error_steady",
                                       "mean_efficiency_error", "mean_torque_in_error",
                                       "newton_iterations", "friction_evaluations_per_step"],
                         {"steps_per_revolution": "d"}))
    out.append("\n![work-precision](work_precision.png)\n")
    return "".join(out)
