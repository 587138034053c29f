"""The speed targets of the project (:data:`TARGETS`), evaluated side by side from one bench run
(:func:`evaluate_targets`), and the friction-cost ladders (:func:`friction_ladders`): every
Exudyn run on a friction scene next to its frictionless twin at the same step.

Measured: ``docs/benchmarks.md`` (*Speed targets*).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from benchmarks.startup import IMPORT_TARGET_MS
from cardan_exudyn.report.format import number
from cardan_exudyn.studies.bench.configs import SCENES
from cardan_exudyn.studies.bench.result import cheapest
from reference.results.summary import Status
from reference.scene import COUPLINGS

__all__ = ["SPEED_RATIO_TARGET", "EFFICIENCY_TARGET", "FRICTION_COST_TARGET", "KINEMATICS_TARGET",
           "PAPER_EXUDYN_TARGET_S", "PAPER_REFERENCE_TARGET_S", "STARTUP_TARGET_MS", "TARGETS",
           "KINEMATICS_SCENES", "is_friction_scene", "frictionless_twin_scene",
           "frictionless_twin_config", "select", "best", "evaluate_targets", "friction_ladders",
           "paper_targets", "startup_target"]

SPEED_RATIO_TARGET = 2e-5
"""Equal-accuracy level of the kinematic target: largest speed-ratio error [-]."""
EFFICIENCY_TARGET = 1e-4
"""Mean-efficiency accuracy of the friction and paper targets [-]."""
FRICTION_COST_TARGET = 1.5
"""Friction run over the frictionless run at the same step, wall time per simulated second [-]."""
KINEMATICS_TARGET = 1.0
"""Exudyn over MuJoCo, wall time per simulated second at equal accuracy [-]."""
PAPER_EXUDYN_TARGET_S = 2.0
"""The eleven paper scenes with Exudyn, one after the other [s]."""
PAPER_REFERENCE_TARGET_S = 0.5
"""The eleven paper scenes with the reference engine [s]."""
STARTUP_TARGET_MS = IMPORT_TARGET_MS
"""Import cost of ``cardan run`` before its engine runs [ms]."""
KINEMATICS_SCENES = ("frictionless-35deg", "frictionless-10deg")
"""Scenes of the kinematic target (35 deg the target's, 10 deg shown beside it)."""
TARGETS = {
    "kinematics": f"frictionless: Exudyn's cheapest run with a speed-ratio error <= "
                  f"{SPEED_RATIO_TARGET:g} and a drive-torque error after rev. 1 no larger than "
                  f"MuJoCo's cheapest run at that speed-ratio error, at <= {KINEMATICS_TARGET:g} x "
                  f"MuJoCo's wall time per simulated second",
    "friction_cost": f"friction: mean efficiency within {EFFICIENCY_TARGET:g} of the reference at "
                     f"<= {FRICTION_COST_TARGET:g} x the frictionless run's cost at the same step "
                     f"(10 and 35 deg, and with sliding pairs), per coupling",
    "paper_exudyn": f"the eleven paper scenes within {EFFICIENCY_TARGET:g} in <= "
                    f"{PAPER_EXUDYN_TARGET_S:g} s with Exudyn",
    "paper_reference": f"the eleven paper scenes within {EFFICIENCY_TARGET:g} in <= "
                       f"{PAPER_REFERENCE_TARGET_S:g} s with the reference engine",
    "startup": f"import cost of `cardan run` up to its engine dispatch (the scene's build included) "
               f"<= {STARTUP_TARGET_MS:g} ms",
}


def select(rows: pd.DataFrame, **values: Any) -> pd.DataFrame:
    """The rows whose columns equal ``values`` (``select(rows, engine="mujoco")``)."""
    mask = np.ones(len(rows), dtype=bool)
    for column, value in values.items():
        mask &= (rows[column] == value).to_numpy()
    return rows[mask]


def is_friction_scene(key: str) -> bool:
    """True for the default scene keys with friction (``friction-...``)."""
    return key.startswith("friction-")


def frictionless_twin_scene(key: str) -> str:
    """The frictionless scene key at the same geometry as the friction scene key ``key``."""
    return key.replace("friction-", "frictionless-", 1)


def frictionless_twin_config(label: str) -> str:
    """The frictionless configuration a friction configuration's cost is compared with: the same
    label without its friction coupling (``"exudyn tuned lagged"`` -> ``"exudyn tuned"``)."""
    for coupling in COUPLINGS:
        if label.endswith(" " + coupling):
            return label[:-len(coupling) - 1]
    return label


def best(rows: pd.DataFrame, error: str, level: float) -> pd.Series | None:
    """The ok row with the least wall time per simulated second whose ``error`` is <= ``level``."""
    return cheapest(rows, {error: level})


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

    walls = both("wall_per_simulated_s")
    ratios = both("speed_ratio_error")
    torques = both("torque_in_error_steady")
    return (f"wall per simulated second Exudyn {walls[0]} s, MuJoCo {walls[1]} s; speed-ratio "
            f"error {ratios[0]} vs {ratios[1]}; drive-torque error after rev. 1 {torques[0]} vs "
            f"{torques[1]}")


def kinematics_targets(key: str, scene_rows: pd.DataFrame) -> list[dict[str, Any]]:
    """MuJoCo's cheapest run at the speed-ratio level sets the drive-torque level; Exudyn's
    cheapest run (any configuration) meeting both levels over MuJoCo's wall time."""
    mj = best(select(scene_rows, engine="mujoco"), "speed_ratio_error", SPEED_RATIO_TARGET)
    exudyn = select(scene_rows, engine="exudyn")
    if exudyn.empty:
        return []
    ex = None
    if mj is not None:
        ex = cheapest(exudyn, {"speed_ratio_error": SPEED_RATIO_TARGET,
                               "torque_in_error_steady": float(mj["torque_in_error_steady"])})
    ratio = (ex["wall_per_simulated_s"] / mj["wall_per_simulated_s"]
             if ex is not None and mj is not None else float("nan"))
    return [{"target": "kinematics", "scene": key, "variant": "speed ratio and drive torque",
             "exudyn": describe_row(ex), "other": "MuJoCo: " + describe_row(mj),
             "measured": ratio, "limit": KINEMATICS_TARGET,
             "met": bool(np.isfinite(ratio) and ratio <= KINEMATICS_TARGET),
             "detail": kinematics_detail(ex, mj)}]


def twin_wall(free: pd.DataFrame, label: str, steps: int) -> float:
    """Wall per simulated second of the frictionless twin of ``label`` at ``steps`` (NaN: none)."""
    twin = select(free, config=frictionless_twin_config(label), steps_per_revolution=steps)
    twin = twin[twin["status"] == Status.OK]
    return float(twin.iloc[0]["wall_per_simulated_s"]) if not twin.empty else float("nan")


def friction_cost(label: str, sel: pd.DataFrame, free: pd.DataFrame) -> tuple[pd.Series | None,
                                                                              float, str]:
    """The cheapest run of one configuration at the efficiency level, its cost over the same
    configuration's frictionless run at the same step, and a sentence on both."""
    row = best(sel, "mean_efficiency_error", EFFICIENCY_TARGET)
    if row is None:
        return None, float("nan"), "no step size on the ladder reaches the accuracy"
    twin = twin_wall(free, label, row["steps_per_revolution"])
    if not np.isfinite(twin):
        return row, float("nan"), "no frictionless run at the same step to compare with"
    detail = (f"efficiency error {row['mean_efficiency_error']:.2g}; "
              f"{row['wall_per_simulated_s']:.3g} vs frictionless "
              f"({frictionless_twin_config(label)}) {twin:.3g} s per simulated s; friction "
              f"evaluations per step {number(row.get('friction_evaluations_per_step'), '.3g')}")
    return row, row["wall_per_simulated_s"] / twin, detail


def friction_targets(key: str, scene_rows: pd.DataFrame, rows: pd.DataFrame) -> list[dict[str, Any]]:
    """Per Exudyn configuration on a friction scene: the cost of friction at the efficiency level."""
    free = select(rows, scene=frictionless_twin_scene(key))
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


def friction_ladders(rows: pd.DataFrame) -> pd.DataFrame:
    """Every Exudyn run on a friction scene next to its frictionless twin at the same step.

    Returns
    -------
    pandas.DataFrame
        One row per friction scene, configuration and step: ``scene``, ``config``, ``coupling``,
        ``steps_per_revolution``, ``status``, ``mean_efficiency_error`` [-],
        ``wall_per_simulated_s`` [-], ``frictionless_wall_per_simulated_s`` [-] (the twin
        configuration on the twin scene, NaN when not run) and ``cost_ratio`` [-].
    """
    out = []
    for key in dict.fromkeys(rows["scene"]) if not rows.empty else ():
        if not is_friction_scene(key):
            continue
        free = select(rows, scene=frictionless_twin_scene(key))
        for _, row in select(rows, scene=key, engine="exudyn").iterrows():
            twin = twin_wall(free, row["config"], row["steps_per_revolution"])
            out.append({"scene": key, "config": row["config"], "coupling": row.get("coupling"),
                        "steps_per_revolution": int(row["steps_per_revolution"]),
                        "status": row["status"], "mean_efficiency_error": row["mean_efficiency_error"],
                        "wall_per_simulated_s": row["wall_per_simulated_s"],
                        "frictionless_wall_per_simulated_s": twin,
                        "cost_ratio": row["wall_per_simulated_s"] / twin})
    return pd.DataFrame(out)


def paper_targets(paper: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The eleven paper scenes' wall time and accuracy against their limits, per engine."""
    out = []
    for engine, limit, name in (("exudyn", PAPER_EXUDYN_TARGET_S, "paper_exudyn"),
                                ("reference", PAPER_REFERENCE_TARGET_S, "paper_reference")):
        part = paper[engine]
        met = part["wall_s"] <= limit and part["max_error"] <= EFFICIENCY_TARGET and part["failed"] == 0
        out.append({"target": name, "scene": "paper's eleven", "variant": part["config"],
                    "exudyn": "", "other": "", "measured": part["wall_s"], "limit": limit,
                    "met": bool(met),
                    "detail": (f"largest mean-efficiency error {number(part['max_error'], '.2g')} "
                               f"(limit {EFFICIENCY_TARGET:g}); {part['failed']} runs not ok; "
                               f"median of {part['repeats']}")})
    return out


def startup_target(startup: Mapping[str, Any]) -> dict[str, Any]:
    """The import cost of ``cardan run`` (:func:`benchmarks.startup.import_cost`:
    its ``import_ms``, the imports up to the engine dispatch, scene build included) against its
    limit."""
    measured = float(startup["import_ms"])
    top = ", ".join(f"{name} {ms:.0f}" for name, ms in (startup.get("top") or [])[:5])
    return {"target": "startup", "scene": "cardan run", "variant": "imports up to the engine",
            "exudyn": "", "other": "", "measured": measured, "limit": STARTUP_TARGET_MS,
            "met": bool(np.isfinite(measured) and measured <= STARTUP_TARGET_MS),
            "detail": (f"median of {startup.get('repeats')} runs of python -X importtime [ms]: "
                       f"{number(startup.get('import_ms'), '.0f')} before the scene, "
                       f"{number(startup.get('scene_build_ms'), '.0f')} while it is built; "
                       f"largest: {top}")}


def evaluate_targets(rows: pd.DataFrame, paper: Mapping[str, Any] | None,
                     startup: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
    """The targets of :data:`TARGETS` with their measured ratios, from one bench run.

    Parameters
    ----------
    rows : pandas.DataFrame
        The work-precision rows (:func:`cardan_exudyn.studies.bench.ladders.work_precision`) of
        the default scenes, keyed as :data:`cardan_exudyn.studies.bench.configs.SCENES`.
    paper : dict or None
        The paper scenes' timing (:func:`benchmarks.targets.paper.paper_scenes_timing`), None
        when not run.
    startup : dict or None
        The import cost (:func:`benchmarks.startup.import_cost`), None when not measured.

    Returns
    -------
    list of dict
        One record per target and variant: ``target``, ``scene``, ``variant``, ``exudyn``,
        ``other``, ``measured`` (a ratio [-], a wall time [s] or an import time [ms]), ``limit``,
        ``met``, ``detail``.
    """
    out = []
    for key in SCENES:
        scene_rows = select(rows, scene=key) if not rows.empty else rows
        if scene_rows.empty:
            continue
        if key in KINEMATICS_SCENES:
            out += kinematics_targets(key, scene_rows)
        elif is_friction_scene(key):
            out += friction_targets(key, scene_rows, rows)
    if paper:
        out += paper_targets(paper)
    if startup:
        out.append(startup_target(startup))
    return out
