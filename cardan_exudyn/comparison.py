"""Cross-engine comparison: one scene, several engines, differences per column.

:func:`compare` runs each engine on the same scene, joins the time tables on the input angle and
returns a :class:`Comparison`: per later engine, the maximum and RMS difference from the first
engine (the *base*) of every shared column, with the scale of the column, and the differences of
the mean values. Fixed-step engines choose their step from the scene; the reference engine is
then asked for rows at the base engine's step (``numerics.dt``), which only sets where its exact
solution is sampled, so for constant-speed scenes the rows coincide and no interpolation enters
the differences. Otherwise the other engine's columns are interpolated onto the base's input
angles with a cubic spline, and the comparison says so.

The first ``skip_revolutions`` (default 0) can be left out of the per-column statistics, e.g. to
keep an integrator's start-up transient apart from its steady-state error; the comparison gives
both.

Example::

    import cardan_exudyn
    from reference import named_scene

    comparison = cardan_exudyn.compare(named_scene("paper-10deg"), ("exudyn", "reference"))
    print(comparison.differences_table(rtol=1e-3))

The module is not named ``compare``: a submodule of that name would replace the package's
function ``cardan_exudyn.compare`` as soon as anything imported it.
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
        The engine compared, and the base engine it is compared with.
    join : str
        How the rows were matched: ``"same rows"`` or a cubic spline in the input angle.
    means : dict[str, float]
        ``engine - against`` of the :data:`SUMMARY_KEYS` (units of each key), only when both
        runs ended ``ok`` and both values are finite.
    overall, steady : pandas.DataFrame
        Per column (the index, named ``column``): ``max_abs`` and ``rms`` of the difference, the
        base column's largest magnitude ``scale`` (units of the column), ``max_rel`` =
        ``max_abs / scale`` [-] and the number of ``rows``; over all rows, and after the
        comparison's ``skip_revolutions``.
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
        Per engine, the wall time of its run [s].
    differences : dict[str, EngineDifference]
        Per later engine that produced a table (none when the base produced none).
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
        """What the report says about one engine's run: status, reason, version, wall time [s],
        step [s], steps, the direction of the power flow, and the :data:`SUMMARY_KEYS` the run
        has a value for."""
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
        """The columns that differ by more than ``atol + rtol * scale``.

        Parameters
        ----------
        rtol : float
            Tolerance relative to the base column's largest magnitude [-].
        atol : float
            Absolute tolerance, in the units of each column.
        steady : bool
            Judge the rows after ``skip_revolutions`` (default) or all rows.

        Returns
        -------
        pandas.DataFrame
            One row per (engine, column) over the limit: ``engine``, ``column`` and the
            statistics of :class:`EngineDifference`.
        """
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
        """:meth:`differing` as a markdown table, for an assertion message or a terminal.

        Parameters
        ----------
        rtol, atol, steady
            As for :meth:`differing`.

        Returns
        -------
        str
            Columns engine, column, max |difference|, RMS, scale, max |difference| / scale.
        """
        columns = ["engine", "column", "max_abs", "rms", "scale", "max_rel"]
        formats = {c: ".3e" for c in columns[2:]}
        return markdown_table(self.differing(rtol, atol, steady), columns, formats)


def summary_values(summary: Summary) -> dict[str, float]:
    """The :data:`SUMMARY_KEYS` that ``summary`` has a value for (a failed run has no means)."""
    values = {key: getattr(summary, key) for key in MEAN_KEYS}
    values.update({f"loss_work_{p}": summary.pair_loss_work.get(p) for p in PAIR_NAMES})
    return {key: value for key, value in values.items() if value is not None}


def statistics_dict(stats: pd.DataFrame) -> dict[str, dict[str, float]]:
    """Per-column statistics as the JSON report writes them: column -> :data:`SERIALISED` key ->
    value (``rows`` an integer)."""
    return {column: {key: int(row[key]) if key == "rows" else float(row[key]) for key in SERIALISED}
            for column, row in stats.iterrows()}


def join_on_input_angle(base: pd.DataFrame, other: pd.DataFrame) -> tuple[dict[str, np.ndarray], str]:
    """``other``'s columns at ``base``'s input angles, and how they were obtained.

    Rows are taken as they are when both tables have the same input angles (to 1e-9 rad);
    otherwise each column is interpolated by a cubic spline in the input angle, over the span
    both tables cover (base rows outside it are NaN).

    Parameters
    ----------
    base : pandas.DataFrame
        The base engine's time table (``theta_in`` [rad] and the :data:`COMPARED` columns).
    other : pandas.DataFrame
        Another engine's time table of the same scene.

    Returns
    -------
    columns : dict of str to ndarray
        Each :data:`COMPARED` column ``other`` has, at ``base``'s rows (units of the column).
    join : str
        ``"same rows"`` or ``"cubic spline in the input angle"``.
    """
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
    """Statistics of ``joined - base`` over the rows in ``mask``, per column.

    Parameters
    ----------
    base : pandas.DataFrame
        The base engine's time table.
    joined : mapping of str to ndarray
        The other engine's columns at the base's rows (:func:`join_on_input_angle`).
    mask : ndarray of bool
        The base rows to take.

    Returns
    -------
    pandas.DataFrame
        Index ``column``; ``max_abs`` and ``rms`` of the difference and ``scale``, the base
        column's largest magnitude (units of the column), ``max_rel = max_abs / scale`` [-] (NaN
        for a column that is zero in the base) and ``rows`` (rows where both are finite).
        Columns without such a row are left out.
    """
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
        Run with every step recorded (``record.timeseries``, ``record.every = 1``).
    engines : sequence of str
        At least two distinct keys of :data:`cardan_exudyn.engines.ENGINES`; the first is the base.
    options : mapping, optional
        Engine name -> options object of that engine (``ExudynOptions``, ...); engines not in
        it run with their defaults.
    skip_revolutions : float
        Input revolutions [-] left out of the ``steady`` per-column statistics.
    progress : callable, optional
        Called with one line of text before each engine runs.

    Returns
    -------
    Comparison

    Raises
    ------
    TypeError
        ``scene`` not a Scene, ``engines`` a string or holding something else than names,
        ``options`` not a mapping, ``skip_revolutions`` not a number, ``progress`` not callable.
    ValueError
        Fewer than two engines, an engine twice, a negative ``skip_revolutions`` or one that
        leaves none of the scene's revolutions.
    EngineUnavailable
        An engine that is unknown, not installed, or cannot run the scene (before any engine
        runs, except for the last reason).
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
    """``engines`` as a list of engine names; ``TypeError`` naming the argument for a single
    string (``"exudyn,reference"`` is one name, not two) or anything that is not a sequence of
    strings."""
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
    """Refuse a comparison that cannot be made, before any engine runs.

    Parameters
    ----------
    engines : list of str
        The engines, the base first.
    options : mapping
        Engine name -> options of that engine.
    skip_revolutions : float
        Input revolutions left out of the steady statistics [-].

    Raises
    ------
    TypeError, ValueError, EngineUnavailable, OptionsError
        As :func:`compare` describes.
    """
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
    """Run each engine on ``scene`` with every step recorded; engines in :data:`SAMPLED_ENGINES`
    are sampled at the step of the first engine that reports one, unless the scene sets it.

    Parameters
    ----------
    scene : Scene
        The scene.
    engines : sequence of str
        The engines, in order.
    options : mapping
        Engine name -> options; engines not in it run with their defaults.
    progress : callable, optional
        Called with one line of text before each engine runs.
    runner : callable
        ``runner(scene, engine, options) -> Result``: :func:`cardan_exudyn.engines.run`, or a
        caching wrapper of it (the pytest plugin's).

    Returns
    -------
    results : dict of str to Result
        Per engine, in order.
    walls : dict of str to float
        Per engine, the wall time of its run [s].
    """
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
    """Every later engine that produced a table against the first (none without a base table).

    Parameters
    ----------
    results : mapping of str to Result
        Per engine, the base first.
    skip_revolutions : float
        Input revolutions left out of the steady statistics [-].

    Returns
    -------
    dict of str to EngineDifference
        Per later engine with a table.
    """
    base_name, *others = results
    base = results[base_name].table
    if base is None:
        return {}
    steady = after_revolutions(base["theta_in"].to_numpy(float), skip_revolutions)
    return {engine: difference(results[base_name], results[engine], base_name, engine, steady)
            for engine in others if results[engine].table is not None}


def difference(base: Result, other: Result, base_name: str, engine: str,
               steady: np.ndarray) -> EngineDifference:
    """``other`` against ``base``: the join, the mean-value and the per-column differences.

    Parameters
    ----------
    base, other : Result
        The two runs, each with a table.
    base_name, engine : str
        Their engines.
    steady : ndarray of bool
        The base rows after the skipped revolutions.

    Returns
    -------
    EngineDifference
        Mean-value differences only when both runs ended ``ok``.
    """
    joined, how = join_on_input_angle(base.table, other.table)
    means = {}
    if base.success and other.success:
        a = summary_values(base.summary)
        b = summary_values(other.summary)
        means = {k: b[k] - a[k] for k in SUMMARY_KEYS if is_number(a.get(k)) and is_number(b.get(k))}
    return EngineDifference(engine, base_name, how, means,
                            column_differences(base.table, joined, np.ones_like(steady)),
                            column_differences(base.table, joined, steady))
