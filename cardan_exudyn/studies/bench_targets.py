"""The speed targets of ``cardan bench`` (:data:`TARGETS`), evaluated side by side from one bench
run (:func:`evaluate_targets`), and the timing of the paper's eleven scenes with Exudyn and the
reference engine (:func:`paper_scenes_timing`).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn import engines
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.report.format import number
from cardan_exudyn.studies.bench_configs import EXUDYN_TUNED, SCENES, Progress, quiet
from cardan_exudyn.studies.bench_ladders import yardstick
from reference.engine import ReferenceOptions
from reference.paper import paper_cases, paper_scene
from reference.scene import Scene, replace
from reference.schema import Result, Status

__all__ = ["SPEED_RATIO_TARGET", "EFFICIENCY_TARGET", "FRICTION_COST_TARGET",
           "PAPER_EXUDYN_TARGET_S", "PAPER_REFERENCE_TARGET_S", "TARGETS", "PAPER_EXUDYN_STEPS",
           "PAPER_REFERENCE_OPTIONS", "evaluate_targets", "paper_scenes", "paper_scenes_timing"]

SPEED_RATIO_TARGET = 2e-5      # equal-accuracy level of the kinematic target [-]
EFFICIENCY_TARGET = 1e-4       # mean-efficiency accuracy of the friction targets [-]
FRICTION_COST_TARGET = 1.5     # friction run / frictionless run at the same step [-]
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
# the paper scenes' run (summary only) and the default of `cardan bench --paper`
PAPER_EXUDYN_STEPS = 800
PAPER_REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=36, quadrature_rtol=1e-6)


def select(rows: pd.DataFrame, **values: Any) -> pd.DataFrame:
    """The rows whose columns equal ``values`` (``select(rows, engine="mujoco")``)."""
    mask = np.ones(len(rows), dtype=bool)
    for column, value in values.items():
        mask &= (rows[column] == value).to_numpy()
    return rows[mask]


def best(rows: pd.DataFrame, error: str, level: float) -> pd.Series | None:
    """The ok row with the least wall time per simulated second whose ``error`` is <= ``level``."""
    ok = rows[(rows["status"] == Status.OK) & (rows[error] <= level) & rows["wall_per_simulated_s"].notna()]
    if ok.empty:
        return None
    return ok.loc[ok["wall_per_simulated_s"].idxmin()]


def describe_row(row: pd.Series | None) -> str:
    """``"<config>, <n> steps/rev"``, or that no run reaches the level."""
    if row is None:
        return "none reaches the level"
    return f"{row['config']}, {int(row['steps_per_revolution'])} steps/rev"


def value(row: pd.Series | None, key: str) -> Any:
    """``row[key]``, None when there is no row or no such column."""
    return None if row is None else row.get(key)


def kinematics_detail(ex: pd.Series | None, mj: pd.Series | None) -> str:
    """Wall times and errors of the two runs a kinematic target compares."""
    def both(key: str) -> tuple[str, str]:
        return number(value(ex, key), ".3g"), number(value(mj, key), ".3g")

    walls, ratios, torques = (both("wall_per_simulated_s"), both("speed_ratio_error"),
                              both("torque_in_error_steady"))
    return (f"wall per simulated second Exudyn {walls[0]} s, MuJoCo {walls[1]} s; speed-ratio "
            f"error {ratios[0]} vs {ratios[1]}; drive-torque error after rev. 1 {torques[0]} vs "
            f"{torques[1]}")


def kinematics_targets(key: str, scene_rows: pd.DataFrame) -> list[dict[str, Any]]:
    """Exudyn's cheapest run at the speed-ratio level over MuJoCo's, with the integrator's
    velocities and with the velocity projection."""
    mj = best(select(scene_rows, engine="mujoco"), "speed_ratio_error", SPEED_RATIO_TARGET)
    exudyn = select(scene_rows, engine="exudyn")
    projected = exudyn["config"].str.contains("projection")
    out = []
    for variant, sel in (("integrator velocities", exudyn[~projected]),
                         ("velocity projection", exudyn[projected])):
        if sel.empty:
            continue
        ex = best(sel, "speed_ratio_error", SPEED_RATIO_TARGET)
        ratio = (ex["wall_per_simulated_s"] / mj["wall_per_simulated_s"]
                 if ex is not None and mj is not None else float("nan"))
        out.append({"target": "kinematics", "scene": key, "variant": variant,
                    "exudyn": describe_row(ex), "other": "MuJoCo: " + describe_row(mj),
                    "measured": ratio, "limit": 1.0, "met": bool(np.isfinite(ratio) and ratio <= 1.0),
                    "detail": kinematics_detail(ex, mj)})
    return out


def friction_cost(label: str, sel: pd.DataFrame, free: pd.DataFrame) -> tuple[pd.Series | None,
                                                                              float, str]:
    """The cheapest run of one configuration at the efficiency level, its cost over the same
    configuration's frictionless run at the same step, and a sentence on both."""
    row = best(sel, "mean_efficiency_error", EFFICIENCY_TARGET)
    if row is None:
        return None, float("nan"), "no step size on the ladder reaches the accuracy"
    twin = select(free, config=label.replace(" lagged", ""),
                  steps_per_revolution=row["steps_per_revolution"])
    if twin.empty:
        return row, float("nan"), "no frictionless run at the same step to compare with"
    twin_wall = twin.iloc[0]["wall_per_simulated_s"]
    detail = (f"efficiency error {row['mean_efficiency_error']:.2g}; "
              f"{row['wall_per_simulated_s']:.3g} vs frictionless {twin_wall:.3g} s per simulated "
              f"s; friction evaluations per step "
              f"{number(row.get('friction_evaluations_per_step'), '.3g')}")
    return row, row["wall_per_simulated_s"] / twin_wall, detail


def friction_targets(key: str, scene_rows: pd.DataFrame, rows: pd.DataFrame) -> list[dict[str, Any]]:
    """Per Exudyn configuration on a friction scene: the cost of friction at the efficiency level."""
    free = select(rows, scene=f"frictionless-{key.split('-')[1]}")
    exudyn = select(scene_rows, engine="exudyn")
    out = []
    for label in exudyn["config"].unique():
        row, ratio, detail = friction_cost(label, select(exudyn, config=label), free)
        out.append({"target": "friction_cost", "scene": key, "variant": label,
                    "exudyn": describe_row(row), "other": "", "measured": ratio,
                    "limit": FRICTION_COST_TARGET,
                    "met": bool(np.isfinite(ratio) and ratio <= FRICTION_COST_TARGET),
                    "detail": detail})
    return out


def paper_targets(paper: dict[str, Any]) -> list[dict[str, Any]]:
    """The eleven paper scenes' wall time and accuracy against their limits, per engine."""
    out = []
    for engine, limit, name in (("exudyn", PAPER_EXUDYN_TARGET_S, "paper_exudyn"),
                                ("reference", PAPER_REFERENCE_TARGET_S, "paper_reference")):
        part = paper[engine]
        met = part["wall_s"] < limit and part["max_error"] <= EFFICIENCY_TARGET and part["failed"] == 0
        out.append({"target": name, "scene": "paper's eleven", "variant": part["config"],
                    "exudyn": "", "other": "", "measured": part["wall_s"], "limit": limit,
                    "met": bool(met),
                    "detail": (f"largest mean-efficiency error {number(part['max_error'], '.2g')} "
                               f"(limit {EFFICIENCY_TARGET:g}); {part['failed']} runs not ok; "
                               f"median of {part['repeats']}")})
    return out


def evaluate_targets(rows: pd.DataFrame, paper: dict[str, Any] | None) -> list[dict[str, Any]]:
    """The targets of :data:`TARGETS` with their measured ratios, from one bench run.

    Parameters
    ----------
    rows : pandas.DataFrame
        The work-precision rows (:func:`cardan_exudyn.studies.bench_ladders.work_precision`).
    paper : dict or None
        The paper scenes' timing (:func:`paper_scenes_timing`), None when not run.

    Returns
    -------
    list of dict
        One record per target and variant: ``target``, ``scene``, ``variant``, ``exudyn``,
        ``other``, ``measured`` (a ratio [-] or a wall time [s]), ``limit``, ``met``, ``detail``.
    """
    out = []
    for key in SCENES:
        scene_rows = select(rows, scene=key)
        if scene_rows.empty:
            continue
        if key.startswith("frictionless-"):
            out += kinematics_targets(key, scene_rows)
        else:
            out += friction_targets(key, scene_rows, rows)
    if paper:
        out += paper_targets(paper)
    return out


def paper_scenes(parameters: str = "literal") -> list[Scene]:
    """The paper's eleven scenes with friction (Table 2 and the speed study), summary only."""
    return [replace(paper_scene(c["shaft_angle_deg"], c["speed_rpm"], parameters=parameters),
                    **{"record.timeseries": False}) for c in paper_cases()]


def timing_part(config: str, walls: list[float], results: list[Result], exact: list[float],
                scenes: list[Scene]) -> dict[str, Any]:
    """One engine's entry of :func:`paper_scenes_timing`."""
    errors = [abs(r.summary.mean_efficiency - e) if r.success else float("nan")
              for r, e in zip(results, exact, strict=True)]
    finite = [e for e in errors if np.isfinite(e)]
    return {"config": config, "wall_s": float(np.median(walls)), "walls_s": walls,
            "max_error": max(finite) if finite else float("nan"), "errors": errors,
            "failed": sum(not r.success for r in results), "repeats": len(walls),
            "scenes": [s.name for s in scenes]}


def paper_scenes_timing(repeats: int = 3, exudyn_steps: int = PAPER_EXUDYN_STEPS,
                        exudyn_options: ExudynOptions = EXUDYN_TUNED,
                        reference_options: ReferenceOptions = PAPER_REFERENCE_OPTIONS,
                        progress: Progress | None = None) -> dict[str, Any]:
    """Wall time of the eleven scenes, one after the other in this process, per engine.

    Exudyn runs at ``exudyn_steps`` per revolution with ``exudyn_options``; the reference with
    ``reference_options``. Errors are against the reference at its default (tight) settings.

    Returns
    -------
    dict
        Per engine (``exudyn``, ``reference``): ``config``, ``wall_s`` (median of the rounds)
        and ``walls_s`` [s], ``errors`` and ``max_error`` (mean efficiency) [-], ``failed``,
        ``repeats``, ``scenes``.
    """
    say = progress or quiet
    scenes = paper_scenes()
    exact = [yardstick(s).summary.mean_efficiency for s in scenes]

    def at_steps(scene: Scene) -> Scene:
        return replace(scene, **{"numerics.dt": 2.0 * math.pi / scene.drive.max_speed() / exudyn_steps})

    runners = {"exudyn": lambda s: engines.run(at_steps(s), "exudyn", exudyn_options),
               "reference": lambda s: engines.run(s, "reference", reference_options)}
    walls: dict[str, list[float]] = {k: [] for k in runners}
    last: dict[str, list[Result]] = {}
    for round_ in range(repeats):
        for engine, runner in runners.items():
            start = time.perf_counter()
            last[engine] = [runner(s) for s in scenes]
            walls[engine].append(time.perf_counter() - start)
            say(f"paper scenes round {round_ + 1}/{repeats} {engine}: {walls[engine][-1]:.2f} s")
    configs = {"exudyn": f"tuned, {exudyn_steps} steps/rev",
               "reference": f"samples {reference_options.samples_per_revolution}/rev, quadrature "
                            f"rtol {reference_options.quadrature_rtol:g}"}
    return {engine: timing_part(configs[engine], walls[engine], results, exact, scenes)
            for engine, results in last.items()}
