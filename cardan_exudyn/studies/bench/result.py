"""The whole of ``cardan bench`` in one call (:func:`run_bench`), its :class:`BenchResult`, and the
cheapest run of each configuration at the scene's accuracy.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.report.environment import environment
from cardan_exudyn.studies.bench.configs import ENGINE_NAMES, BenchError, Progress, fixed_scenes
from cardan_exudyn.studies.bench.ladders import work_precision
from reference.results.summary import Status
from reference.scene.scene import Scene

__all__ = ["BenchResult", "accuracy_measure", "cheapest", "at_accuracy", "check_inputs", "run_bench"]


def accuracy_measure(scene: Scene) -> str:
    """The error column ``numerics.accuracy`` bounds for ``scene``: mean-efficiency error with friction,
    speed-ratio error without (every engine reports exactly 1 there).
    """
    return "mean_efficiency_error" if scene.has_friction else "speed_ratio_error"


def cheapest(rows: pd.DataFrame, levels: Mapping[str, float]) -> pd.Series | None:
    """The ok row of ``rows`` with the least wall time per simulated second whose every error column of
    ``levels`` is at most its level [-] (NaN never is); None when none qualifies.
    """
    ok = (rows["status"] == Status.OK) & rows["wall_per_simulated_s"].notna()
    for column, level in levels.items():
        ok &= rows[column].astype(float) <= level
    ok_rows = rows[ok.to_numpy()]
    if ok_rows.empty:
        return None
    return ok_rows.loc[ok_rows["wall_per_simulated_s"].idxmin()]


@dataclass
class BenchResult:
    """Everything one bench run measured: ``rows`` (one per configuration and step), ``scenes`` (by
    key), ``environment``, ``settings`` (``quick``, ``repeats``, ``scenes``, ``engines``,
    ``scene_options``) and ``wall_s`` [s].
    """

    rows: pd.DataFrame
    scenes: dict[str, Scene]
    environment: dict[str, Any]
    settings: dict[str, Any] = field(default_factory=dict)
    wall_s: float = 0.0

    def summary(self) -> dict[str, Any]:
        """What ``--json`` prints: environment, settings, wall time, and :func:`at_accuracy`'s entries."""
        return {"environment": self.environment, "settings": self.settings, "wall_s": self.wall_s,
                "configurations": at_accuracy(self)}


def _best_record(scene: str, config: str, sel: pd.DataFrame, measure: str,
                 level: float) -> dict[str, Any]:
    """One configuration's entry of :func:`at_accuracy`."""
    ok = sel[sel["status"] == Status.OK]
    fastest = ok["wall_per_simulated_s"].min() if not ok.empty else np.nan
    row = cheapest(sel, {measure: level})
    record = {"scene": scene, "config": config, "runs": len(sel), "ok": len(ok),
              "fastest_wall_per_simulated_s": float(fastest) if np.isfinite(fastest) else None,
              "measure": measure, "accuracy": level, "steps_per_revolution": None, "error": None,
              "wall_per_simulated_s": None}
    if row is not None:
        record.update(steps_per_revolution=int(row["steps_per_revolution"]), error=float(row[measure]),
                      wall_per_simulated_s=float(row["wall_per_simulated_s"]))
    return record


def at_accuracy(result: BenchResult) -> list[dict[str, Any]]:
    """Per scene and configuration: ``runs``, ``ok``, ``fastest_wall_per_simulated_s``, ``measure``,
    ``accuracy`` and the cheapest step within it (``steps_per_revolution``, ``error``,
    ``wall_per_simulated_s``; None when no step reaches it).
    """
    out = []
    if result.rows.empty:
        return out
    for (key, config), sel in result.rows.groupby(["scene", "config"], sort=False):
        scene = result.scenes[key]
        out.append(_best_record(key, config, sel, accuracy_measure(scene), scene.numerics.accuracy))
    return out


def check_inputs(engines: Iterable[str], repeats: int | None, quick: bool) -> tuple[list[str], int]:
    """``engines`` and ``repeats`` (None: 3, ``quick`` 1) checked; BenchError for an unknown engine or
    repeats not a positive integer.
    """
    engines = list(engines)
    bad = [e for e in engines if e not in ENGINE_NAMES]
    if bad:
        raise BenchError(f"`--engines` must be among {', '.join(ENGINE_NAMES)}, got {bad}")
    repeats = repeats if repeats is not None else (1 if quick else 3)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise BenchError(f"`--repeats` must be a positive integer, got {repeats!r}")
    return engines, repeats


def run_bench(scenes: Mapping[str, Scene] | None = None, quick: bool = False,
              repeats: int | None = None, engines: Iterable[str] = ENGINE_NAMES,
              progress: Progress | None = None,
              scene_options: Iterable[str] = ()) -> BenchResult:
    """Every engine configuration on every scene (default :func:`~.configs.fixed_scenes`): errors
    against the reference and wall times; ``scene_options`` is recorded in the settings. BenchError
    for bad engines or repeats, or a scene the reference cannot solve.
    """
    engines, repeats = check_inputs(engines, repeats, quick)
    scenes = dict(fixed_scenes() if scenes is None else scenes)
    start = time.perf_counter()
    env = environment()
    rows = work_precision(scenes, quick, repeats, engines, progress)
    settings = {"quick": quick, "repeats": repeats, "scenes": list(scenes), "engines": engines,
                "scene_options": list(scene_options)}
    return BenchResult(rows, scenes, env, settings, time.perf_counter() - start)
