"""Cross-engine comparison: one scene, several engines, per-column differences from the first (base).

Tables are joined on the input angle: the same rows when the angles match (the reference engine
is sampled at the base's step), else a cubic spline of the other engine's columns.
Not named ``compare``: such a submodule would shadow the function ``cardan_exudyn.compare``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from cardan_exudyn.engines import get_engine, resolve, run
from cardan_exudyn.report.format import is_number, markdown_table
from reference.results.columns import table_columns
from reference.results.means import after_revolutions
from reference.results.result import Result
from reference.results.summary import OptionsError, Summary
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import require_scene

__all__ = ["Comparison", "EngineDifference", "SUMMARY_KEYS", "COMPARED", "SAMPLED_ENGINES", "compare",
           "check_request", "engine_list", "run_engines", "join_on_input_angle", "column_differences",
           "summary_values"]

MEAN_KEYS = ("mean_efficiency", "mean_instantaneous_efficiency", "work_ratio", "input_work",
             "output_work", "loss_work", "mean_torque_in")
SUMMARY_KEYS = (*MEAN_KEYS, *(f"loss_work_{p}" for p in PAIR_NAMES))
"""Mean values whose differences a comparison reports (``loss_work_<pair>``: per-pair loss)."""
COMPARED = [c for c in table_columns() if c != "t"]
"""Columns whose differences are reported: the schema's numerical columns but time."""
SAMPLED_ENGINES = ("reference",)
"""Engines whose ``numerics.dt`` only sets where an exact solution is sampled (not its error):
they are asked for rows at the base engine's step, so that no interpolation enters."""
STATISTICS = ("max_abs", "rms", "scale", "max_rel", "rows")
"""Per-column statistics of a difference (:func:`column_differences`)."""
SERIALISED = ("max_abs", "rms", "scale", "rows")
"""The per-column keys the JSON report writes (``max_rel`` follows from two of them)."""


@dataclass
class EngineDifference:
    """How one engine's run differs from the base engine's run of the same scene.

    Attributes
    ----------
    engine, against : str
        The engine compared, and the base engine.
    join : str
        ``"same rows"`` or ``"cubic spline in the input angle"``.
    means : dict[str, float]
        ``engine - against`` of the :data:`SUMMARY_KEYS`, when both runs ended ``ok`` and are finite.
    overall, steady : pandas.DataFrame
        Per ``column``: ``max_abs``, ``rms``, the base column's largest magnitude ``scale``,
        ``max_rel = max_abs / scale`` [-] and ``rows``; over all rows, and after ``skip_revolutions``.
    """

    engine: str
    against: str
    join: str
    means: dict[str, float]
    overall: pd.DataFrame
    steady: pd.DataFrame

    def to_dict(self) -> dict[str, Any]:
        """The JSON shape: ``against``, ``join``, ``means``, ``all`` and ``steady`` per column."""
        return {"against": self.against, "join": self.join, "means": dict(self.means),
                "all": statistics_dict(self.overall), "steady": statistics_dict(self.steady)}


@dataclass
class Comparison:
    """Several engines run on one scene, and how every later engine differs from the first.

    Attributes
    ----------
    scene : Scene
        The scene every engine ran (recording every step's row).
    skip_revolutions : float
        Input revolutions left out of the ``steady`` statistics [-].
    results : dict[str, Result]
        Per engine, in the order asked for; the first is the base.
    wall_time_s : dict[str, float]
        Per engine [s].
    differences : dict[str, EngineDifference]
        Per later engine that produced a table.
    """

    scene: Scene
    skip_revolutions: float
    results: dict[str, Result]
    wall_time_s: dict[str, float]
    differences: dict[str, EngineDifference]

    @property
    def base(self) -> str:
        """The engine the others are compared with."""
        return next(iter(self.results))

    @property
    def success(self) -> bool:
        """True when every engine ran to status ``ok``."""
        return all(result.success for result in self.results.values())

    def engine_record(self, engine: str) -> dict[str, Any]:
        """The report's record of ``engine``'s run: status, reason, version, wall time [s], step [s],
        steps, power flow and its :data:`SUMMARY_KEYS`."""
        s = self.results[engine].summary
        return {"status": s.status.value, "reason": s.reason, "engine_version": s.engine_version,
                "wall_time_s": self.wall_time_s[engine], "dt": s.dt, "steps": s.steps,
                "power_flow": s.power_flow, **summary_values(s)}

    def to_dict(self) -> dict[str, Any]:
        """The JSON report (``comparison.json``, ``cardan compare --json``): no time tables."""
        return {"scene": self.scene.name, "skip_revolutions": self.skip_revolutions,
                "engines": {engine: self.engine_record(engine) for engine in self.results},
                "differences": {engine: d.to_dict() for engine, d in self.differences.items()}}

    def differing(self, rtol: float = 0.0, atol: float = 0.0, steady: bool = True) -> pd.DataFrame:
        """The (``engine``, ``column``, statistics) rows whose ``max_abs`` exceeds ``atol + rtol * scale``
        (``atol`` in the column's units, ``rtol`` of the base's largest magnitude [-]); ``steady``: judge
        the rows after ``skip_revolutions``, else all rows."""
        frames = []
        for engine, d in self.differences.items():
            stats = (d.steady if steady else d.overall).reset_index()
            over = stats[stats["max_abs"] > atol + rtol * stats["scale"]]
            frames.append(over.assign(engine=engine))
        columns = ["engine", "column", *STATISTICS]
        if not frames:
            return pd.DataFrame(columns=columns)
        return pd.concat(frames, ignore_index=True)[columns]

    def differences_table(self, rtol: float = 0.0, atol: float = 0.0, steady: bool = True) -> str:
        """:meth:`differing` as a markdown table, for an assertion message or a terminal."""
        columns = ["engine", "column", "max_abs", "rms", "scale", "max_rel"]
        formats = {c: ".3e" for c in columns[2:]}
        return markdown_table(self.differing(rtol, atol, steady), columns, formats)


def summary_values(summary: Summary) -> dict[str, float]:
    """The :data:`SUMMARY_KEYS` that ``summary`` has a value for (a failed run has no means)."""
    values = {key: getattr(summary, key) for key in MEAN_KEYS}
    values.update({f"loss_work_{p}": summary.pair_loss_work.get(p) for p in PAIR_NAMES})
    return {key: value for key, value in values.items() if value is not None}


def statistics_dict(stats: pd.DataFrame) -> dict[str, dict[str, float]]:
    """Per-column statistics as the JSON report writes them: column -> :data:`SERIALISED` key -> value."""
    return {column: {key: int(row[key]) if key == "rows" else float(row[key]) for key in SERIALISED}
            for column, row in stats.iterrows()}


def join_on_input_angle(base: pd.DataFrame, other: pd.DataFrame) -> tuple[dict[str, np.ndarray], str]:
    """``(columns, join)``: ``other``'s :data:`COMPARED` columns at ``base``'s input angles, taken as
    they are when the angles match to 1e-9 rad, else by cubic spline (NaN outside the shared span)."""
    theta_b = base["theta_in"].to_numpy(float)
    theta_o = other["theta_in"].to_numpy(float)
    if theta_b.shape == theta_o.shape and np.max(np.abs(theta_b - theta_o)) <= 1e-9:
        return {c: other[c].to_numpy(float) for c in COMPARED if c in other}, "same rows"
    sign = 1.0 if theta_o[-1] >= theta_o[0] else -1.0
    x = sign * theta_o
    keep = np.concatenate([[True], np.diff(x) > 0])  # strictly increasing for the spline
    at = sign * theta_b
    inside = (at >= x[keep][0]) & (at <= x[keep][-1])
    out = {}
    for c in (c for c in COMPARED if c in other):
        y = other[c].to_numpy(float)[keep]
        values = np.full(theta_b.shape, np.nan)
        if np.all(np.isfinite(y)):
            values[inside] = CubicSpline(x[keep], y)(at[inside])
        out[c] = values
    return out, "cubic spline in the input angle"


def column_differences(base: pd.DataFrame, joined: Mapping[str, np.ndarray],
                       mask: np.ndarray) -> pd.DataFrame:
    """Per column (index ``column``), :data:`STATISTICS` of ``joined - base`` over the rows in ``mask``
    (``max_rel`` NaN for a column zero in the base; columns with no finite row left out)."""
    records = {}
    for c, values in joined.items():
        b = base[c].to_numpy(float)[mask]
        d = values[mask] - b
        ok = np.isfinite(d)
        if np.any(ok):
            records[c] = _statistics(d[ok], b)
    table = pd.DataFrame.from_dict(records, orient="index", columns=list(STATISTICS))
    table.index.name = "column"
    return table.astype({"rows": int})


def _statistics(d: np.ndarray, b: np.ndarray) -> dict[str, float]:
    """Statistics of the finite differences ``d`` of a base column ``b``."""
    finite = b[np.isfinite(b)]
    scale = float(np.max(np.abs(finite))) if finite.size else float("nan")
    max_abs = float(np.max(np.abs(d)))
    return {"max_abs": max_abs, "rms": float(np.sqrt(np.mean(d ** 2))), "scale": scale,
            "max_rel": max_abs / scale if scale > 0 else float("nan"), "rows": int(d.size)}


def compare(scene: Scene, engines: Sequence[str] = ("exudyn", "reference"),
            options: Mapping[str, Any] | None = None, skip_revolutions: float = 0.0,
            progress: Callable[[str], None] | None = None) -> Comparison:
    """Run ``engines`` on ``scene`` and compare every later engine with the first.

    Parameters
    ----------
    scene : Scene
        Run with every step recorded.
    engines : sequence of str
        At least two distinct keys of :data:`cardan_exudyn.engines.ENGINES`; the first is the base.
    options : mapping, optional
        Engine name -> options object of that engine; others run with their defaults.
    skip_revolutions : float
        Input revolutions [-] left out of the ``steady`` per-column statistics.
    progress : callable, optional
        Called with one line of text before each engine runs.

    Raises
    ------
    TypeError
        An argument of the wrong type (``engines`` a single string).
    ValueError
        Fewer than two engines, an engine twice, a negative ``skip_revolutions`` or one that
        leaves none of the scene's revolutions.
    EngineUnavailable
        An engine unknown, not installed (before any engine runs), or unable to run the scene.
    OptionsError
        Options for an engine not compared, or of another engine's class.
    """
    require_scene(scene)
    engines = engine_list(engines)
    if options is not None and not isinstance(options, Mapping):
        raise TypeError(f"`options` must be a mapping of engine name to options, got "
                        f"{type(options).__name__} {options!r:.80}")
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be callable or None, got {type(progress).__name__}")
    options = dict(options or {})
    check_request(engines, options, skip_revolutions)
    if skip_revolutions >= scene.revolutions:
        raise ValueError(f"`skip_revolutions` = {skip_revolutions!r} leaves nothing of the scene's "
                         f"{scene.revolutions!r} revolutions to compare: it must be below them")
    results, walls = run_engines(scene, engines, options, progress)
    scene = replace(scene, **{"record.timeseries": True, "record.every": 1})
    return Comparison(scene, skip_revolutions, results, walls,
                      differences(results, skip_revolutions))


def engine_list(engines: Any) -> list[str]:
    """``engines`` as a list of names; ``TypeError`` for one string or anything else than strings."""
    if isinstance(engines, (str, bytes)):
        raise TypeError(f"`engines` must be a sequence of engine names such as ['exudyn', 'reference'], "
                        f"not one string: got {engines!r:.80}")
    if not hasattr(engines, "__iter__"):
        raise TypeError(f"`engines` must be a sequence of engine names, got {type(engines).__name__}")
    out = list(engines)
    wrong = [e for e in out if not isinstance(e, str)]
    if wrong:
        raise TypeError(f"`engines` must hold engine names (strings), got {wrong[0]!r:.80} in {out!r:.120}")
    return out


def check_request(engines: list[str], options: Mapping[str, Any], skip_revolutions: float) -> None:
    """Refuse a comparison that cannot be made (as :func:`compare` describes), before any engine runs."""
    engines = engine_list(engines)
    if isinstance(skip_revolutions, bool) or not isinstance(skip_revolutions, (int, float, np.integer,
                                                                               np.floating)):
        raise TypeError(f"`skip_revolutions` must be a number of revolutions, got {skip_revolutions!r:.80}")
    if len(engines) < 2:
        raise ValueError(f"`engines` needs at least two engines, got {engines!r}")
    if len(set(engines)) != len(engines):
        raise ValueError(f"`engines` lists an engine twice: {engines!r}")
    if not math.isfinite(skip_revolutions) or skip_revolutions < 0:
        raise ValueError(f"`skip_revolutions` must be >= 0, got {skip_revolutions!r}")
    for engine in engines:  # unknown or uninstalled: EngineUnavailable
        get_engine(engine)
    for engine, value in options.items():
        if engine not in engines:
            raise OptionsError(f"`options` for {engine!r}, which is not among {engines!r}")
        resolve(engine, value)  # options of another engine's class: OptionsError


def run_engines(scene: Scene, engines: Sequence[str], options: Mapping[str, Any],
                progress: Callable[[str], None] | None = None,
                runner: Callable[..., Result] = run) -> tuple[dict[str, Result], dict[str, float]]:
    """``(results, walls [s])`` per engine of running ``scene`` with every step recorded through
    ``runner(scene, engine, options)``; :data:`SAMPLED_ENGINES` sample at the first reported step."""
    scene = replace(scene, **{"record.timeseries": True, "record.every": 1})
    results: dict[str, Result] = {}
    walls: dict[str, float] = {}
    base_dt = None
    for engine in engines:
        run_scene = scene
        if engine in SAMPLED_ENGINES and base_dt is not None and scene.numerics.dt is None:
            run_scene = replace(scene, **{"numerics.dt": base_dt})
        if progress:
            progress(f"{scene.name}: running {engine}")
        start = time.perf_counter()
        results[engine] = runner(run_scene, engine, options.get(engine))
        walls[engine] = time.perf_counter() - start
        if base_dt is None:
            base_dt = results[engine].summary.dt
    return results, walls


def differences(results: Mapping[str, Result], skip_revolutions: float) -> dict[str, EngineDifference]:
    """Per later engine with a table, its :class:`EngineDifference` from the first (none without a
    base table)."""
    base_name, *others = results
    base = results[base_name].table
    if base is None:
        return {}
    steady = after_revolutions(base["theta_in"].to_numpy(float), skip_revolutions)
    return {engine: difference(results[base_name], results[engine], base_name, engine, steady)
            for engine in others if results[engine].table is not None}


def difference(base: Result, other: Result, base_name: str, engine: str,
               steady: np.ndarray) -> EngineDifference:
    """``other`` against ``base`` (engines ``engine``, ``base_name``); ``steady`` marks the base rows
    after the skipped revolutions."""
    joined, how = join_on_input_angle(base.table, other.table)
    means = {}
    if base.success and other.success:
        a = summary_values(base.summary)
        b = summary_values(other.summary)
        means = {k: b[k] - a[k] for k in SUMMARY_KEYS if is_number(a.get(k)) and is_number(b.get(k))}
    return EngineDifference(engine, base_name, how, means,
                            column_differences(base.table, joined, np.ones_like(steady)),
                            column_differences(base.table, joined, steady))
