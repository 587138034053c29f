"""One sweep runner: a scene over a grid, random samples, or a list of parameter overrides.

A sweep is a base scene, an engine and a list of *cases*; a case is an id, an engine name and a
dictionary of dotted scene paths to values (``{"joint.geometry.shaft_angle_deg": 20}``). Each case
runs ``function(replace(base, **overrides), engine)`` (by default :func:`summary_outputs`, the
scalar values of the engine's summary) and becomes one flat record.

Files in the output folder ``OUT``:

- ``plan.json``: the specification, the base scene's hash and every case, written before the
  first case runs; a rerun with the same ``OUT`` must have the same plan (or ``restart``).
- ``cases.jsonl``: one JSON record per finished case, appended (flushed and fsync'ed) by the
  driver as soon as the case finishes, so that an interrupted sweep resumes where it stopped; an
  incomplete last line (a kill during the write) is dropped on resume.
- ``results.csv`` (one row per case in plan order, parameters as columns) and ``sweep.json``
  (specification, counts, wall time, per-output statistics, environment), written atomically
  when every case has a record.

Cases run in the driver (``workers=1``), in a local process pool (``workers=N``, spawned
processes), or on a Dask distributed cluster (``scheduler="tcp://host:port"``). Workers return
records; only the driver writes files.
"""

from __future__ import annotations

import contextlib
import datetime
import functools
import hashlib
import importlib
import itertools
import json
import math
import os
import platform
import sys
import time
import traceback
import uuid
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.io import OutputError, atomic_write, check_output_folder, to_jsonable
from reference.scene import Scene, SceneError, replace, scene_to_dict
from reference.schema import Summary

PLAN_FILE, CASES_FILE, RESULTS_FILE, SUMMARY_FILE = "plan.json", "cases.jsonl", "results.csv", "sweep.json"
SWEEP_FILES = (PLAN_FILE, CASES_FILE, RESULTS_FILE, SUMMARY_FILE)
PLAN_FORMAT = "cardan-sweep/1"
DEFAULT_FUNCTION = "cardan_exudyn.sweep.runner:summary_outputs"
# keys of a record that the runner sets; a case function must not return them
RECORD_KEYS = ("id", "engine", "overrides", "status", "reason", "error_type", "error", "case_wall_s")
RESERVED_OUTPUTS = frozenset({"id", "overrides", "error_type", "error", "case_wall_s", "traceback"})
GRID_FORMS = ("linspace", "geomspace")
SAMPLING_METHODS = ("random", "lhs")
DISTRIBUTIONS = {"uniform": ("low", "high"), "loguniform": ("low", "high"),
                 "normal": ("mean", "std", "low", "high")}
# quantiles of a random parameter checked against the scene's validation before any case runs
CHECKED_QUANTILES = (1e-9, 0.5, 1.0 - 1e-9)


class SweepError(ValueError):
    """The sweep specification or the output folder is invalid; the message names the key."""


class SweepIncomplete(RuntimeError):
    """The sweep stopped before every case had a record (e.g. the Dask cluster went away)."""




def _number(where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SweepError(f"{where} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SweepError(f"{where} must be finite, got {value!r}")
    return value


@dataclass(frozen=True)
class Distribution:
    """Distribution of one random parameter.

    Attributes
    ----------
    dist : {"uniform", "loguniform", "normal"}
        ``uniform``: on [low, high); ``loguniform``: log-uniform on [low, high), 0 < low;
        ``normal``: mean and standard deviation, optionally truncated to [low, high] (either
        bound may be given alone).
    low, high, mean, std : float or None
        In the parameter's own unit (the unit of its scene path, e.g. deg for ``..._deg``).
    """

    dist: str
    low: float | None = None
    high: float | None = None
    mean: float | None = None
    std: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.dist, str) or self.dist not in DISTRIBUTIONS:
            raise SweepError(f"`dist` must be one of {sorted(DISTRIBUTIONS)}, got {self.dist!r}")
        allowed = DISTRIBUTIONS[self.dist]
        for name in ("low", "high", "mean", "std"):
            value = getattr(self, name)
            if value is not None:
                if name not in allowed:
                    raise SweepError(f"`{name}` is not a parameter of {self.dist!r}; give {allowed}")
                object.__setattr__(self, name, _number(f"`{name}`", value))
        required = ("mean", "std") if self.dist == "normal" else ("low", "high")
        missing = [n for n in required if getattr(self, n) is None]
        if missing:
            raise SweepError(f"{self.dist!r} needs {list(required)}, missing {missing}")
        if self.std is not None and self.std <= 0.0:
            raise SweepError(f"`std` must be positive, got {self.std!r}")
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise SweepError(f"`low` must be below `high`, got low = {self.low!r}, high = {self.high!r}")
        if self.dist == "loguniform" and self.low <= 0.0:
            raise SweepError(f"`low` of 'loguniform' must be positive, got {self.low!r}")
        if self.dist == "normal" and self._truncated() and self._mass() < 1e-12:
            raise SweepError(f"normal(mean = {self.mean!r}, std = {self.std!r}) has no probability in "
                             f"[{self.low!r}, {self.high!r}]")

    def _truncated(self) -> bool:
        return self.low is not None or self.high is not None

    def _bounds(self) -> tuple[float, float]:
        """Truncation bounds in standard deviations from the mean."""
        lo = -math.inf if self.low is None else (self.low - self.mean) / self.std
        hi = math.inf if self.high is None else (self.high - self.mean) / self.std
        return lo, hi

    def _mass(self) -> float:
        from scipy.special import ndtr

        lo, hi = self._bounds()
        return float(ndtr(hi) - ndtr(lo))

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Inverse distribution function: values at the probabilities ``u`` in [0, 1)."""
        u = np.clip(np.asarray(u, dtype=float), np.finfo(float).tiny, 1.0 - np.finfo(float).epsneg)
        if self.dist == "uniform":
            return self.low + u * (self.high - self.low)
        if self.dist == "loguniform":
            return np.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        if self._truncated():
            from scipy.stats import truncnorm

            lo, hi = self._bounds()
            return truncnorm.ppf(u, lo, hi, loc=self.mean, scale=self.std)
        from scipy.special import ndtri

        return self.mean + self.std * ndtri(u)

    def to_dict(self) -> dict[str, Any]:
        return {k: v for k, v in vars(self).items() if v is not None}


@dataclass(frozen=True)
class RandomSpec:
    """Random samples of several parameters, reproducible from ``seed``.

    Attributes
    ----------
    samples : int
        Number of samples N, >= 1.
    seed : int
        Seed of :func:`numpy.random.default_rng`; the same seed gives the same samples.
    parameters : dict of str to Distribution
        Dotted scene path -> distribution. The order matters: parameter j takes column j of the
        unit-cube samples.
    method : {"random", "lhs"}
        Independent uniform draws, or a Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`),
        mapped through each distribution's inverse distribution function.
    """

    samples: int
    seed: int
    parameters: dict[str, Distribution]
    method: str = "random"

    def __post_init__(self) -> None:
        for name in ("samples", "seed"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise SweepError(f"`random.{name}` must be an integer, got {value!r}")
        if self.samples < 1:
            raise SweepError(f"`random.samples` must be >= 1, got {self.samples!r}")
        if self.seed < 0:
            raise SweepError(f"`random.seed` must be >= 0, got {self.seed!r}")
        if self.method not in SAMPLING_METHODS:
            raise SweepError(f"`random.method` must be one of {list(SAMPLING_METHODS)}, got {self.method!r}")
        if not self.parameters:
            raise SweepError("`random.parameters` is empty: give at least one parameter")

    def points(self) -> list[dict[str, float]]:
        """The N samples, each a dictionary path -> value."""
        rng = np.random.default_rng(self.seed)
        d = len(self.parameters)
        if self.method == "lhs":
            from scipy.stats import qmc

            u = qmc.LatinHypercube(d, rng=rng).random(self.samples)
        else:
            u = rng.random((self.samples, d))
        columns = [dist.ppf(u[:, j]) for j, dist in enumerate(self.parameters.values())]
        return [{path: float(col[i]) for path, col in zip(self.parameters, columns, strict=True)}
                for i in range(self.samples)]

    def to_dict(self) -> dict[str, Any]:
        return {"samples": int(self.samples), "seed": int(self.seed), "method": self.method,
                "parameters": {k: v.to_dict() for k, v in self.parameters.items()}}


@dataclass(frozen=True)
class Case:
    """One run of a sweep: ``function(replace(base, **overrides), engine)``."""

    id: str
    engine: str
    overrides: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "engine": self.engine, "overrides": to_jsonable(self.overrides)}


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep.

    Attributes
    ----------
    scene : str, dict or Scene
        Named scene (``reference.paper.named_scene``), path to a scene TOML, a scene table, or a
        scene.
    engine : str
        Engine of :data:`cardan_exudyn.engines.ENGINES` (a grid or a case may set ``engine``).
    fixed : dict
        Overrides applied to the base scene for every case (dotted path -> value).
    grid : dict
        Dotted path -> list of values (or ``{"linspace": [start, stop, num]}``,
        ``{"geomspace": [...]}``); the cases are the cartesian product, last path fastest.
    random : RandomSpec or None
        Random samples; with a grid, every grid point takes every sample (common samples).
    cases : tuple of dict
        Explicit cases (dotted path -> value; optional ``id`` and ``engine``); excludes grid
        and random.
    function : str or callable
        Case function ``fn(scene, engine) -> dict`` of scalars, a top-level callable or its
        ``"module:name"``; default :func:`summary_outputs`.
    """

    scene: Any
    engine: str = "exudyn"
    fixed: dict[str, Any] = field(default_factory=dict)
    grid: dict[str, Any] = field(default_factory=dict)
    random: RandomSpec | None = None
    cases: tuple = ()
    function: Any = DEFAULT_FUNCTION

    def __post_init__(self) -> None:
        if not isinstance(self.engine, str) or not self.engine:
            raise SweepError(f"`engine` must be an engine name, got {self.engine!r}")
        if self.scene is None:
            raise SweepError("`scene` is required: a named scene, a scene TOML path or a table")
        for name in ("fixed", "grid"):
            if not isinstance(getattr(self, name), Mapping):
                raise SweepError(f"`{name}` must be a table, got {getattr(self, name)!r}")
        object.__setattr__(self, "grid", {p: grid_values(p, v) for p, v in self.grid.items()})
        object.__setattr__(self, "cases", tuple(self.cases))
        if self.cases and (self.grid or self.random):
            raise SweepError("give either `cases` or `grid`/`random`, not both")
        if not (self.cases or self.grid or self.random):
            raise SweepError("nothing to sweep: give `grid`, `random` or `cases`")
        _check_disjoint(self)
        object.__setattr__(self, "function", function_name(self.function))

    def expand(self) -> list[Case]:
        """Every case of the sweep, in order; ids ``0000``, ``0001``, ... unless given."""
        if self.cases:
            return _explicit_cases(self.cases, self.engine)
        grid = [dict(zip(self.grid, combo, strict=True))
                for combo in itertools.product(*self.grid.values())] or [{}]
        samples = self.random.points() if self.random else [{}]
        points = [{**g, **s} for g in grid for s in samples]
        width = max(4, len(str(len(points) - 1)))
        cases = []
        for i, point in enumerate(points):
            engine = point.pop("engine", self.engine)
            cases.append(Case(f"{i:0{width}d}", engine, point))
        return cases

    def to_dict(self) -> dict[str, Any]:
        scene = scene_to_dict(self.scene) if isinstance(self.scene, Scene) else self.scene
        return to_jsonable({
            "scene": scene, "engine": self.engine, "function": self.function,
            "fixed": dict(self.fixed), "grid": {k: list(v) for k, v in self.grid.items()},
            "random": self.random.to_dict() if self.random else None, "cases": list(self.cases)})


def _check_disjoint(spec: SweepSpec) -> None:
    random = set(spec.random.parameters) if spec.random else set()
    for a, b, keys in (("fixed", "grid", set(spec.fixed) & set(spec.grid)),
                       ("fixed", "random", set(spec.fixed) & random),
                       ("grid", "random", set(spec.grid) & random)):
        if keys:
            raise SweepError(f"{sorted(keys)} appear in both `{a}` and `{b}`")
    if "engine" in spec.fixed or "engine" in random:
        raise SweepError("`engine` can be set at the top level, in `grid` or in `cases` only")


def grid_values(path: str, spec: Any) -> tuple:
    """The values of one grid parameter from a list or ``{linspace|geomspace = [a, b, n]}``."""
    where = f"`grid.\"{path}\"`"
    if isinstance(spec, Mapping):
        if len(spec) != 1 or next(iter(spec)) not in GRID_FORMS:
            raise SweepError(f"{where} must be a list or one of "
                             f"{[f'{{{f} = [start, stop, num]}}' for f in GRID_FORMS]}, got {spec!r}")
        form, args = next(iter(spec.items()))
        if not isinstance(args, Sequence) or len(args) != 3:
            raise SweepError(f"{where}: {form} needs [start, stop, num], got {args!r}")
        start, stop = (_number(f"{where} {form} start/stop", v) for v in args[:2])
        num = args[2]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise SweepError(f"{where}: {form} num must be an integer >= 1, got {num!r}")
        if form == "geomspace" and (start <= 0.0 or stop <= 0.0):
            raise SweepError(f"{where}: geomspace needs positive start and stop, got {args!r}")
        return tuple(float(v) for v in getattr(np, form)(start, stop, num))
    if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence):
        raise SweepError(f"{where} must be a list of values or {{linspace = [start, stop, num]}}, "
                         f"got {spec!r}")
    if len(spec) == 0:
        raise SweepError(f"{where} is an empty list: give at least one value")
    return tuple(spec)


def _explicit_cases(cases: Sequence, engine: str) -> list[Case]:
    width = max(4, len(str(len(cases) - 1)))
    out, seen = [], set()
    for i, item in enumerate(cases):
        if not isinstance(item, Mapping):
            raise SweepError(f"`cases[{i}]` must be a table of overrides, got {item!r}")
        overrides = dict(item)
        case_id = overrides.pop("id", f"{i:0{width}d}")
        if not isinstance(case_id, str) or not case_id or "\n" in case_id:
            raise SweepError(f"`cases[{i}].id` must be a non-empty string, got {case_id!r}")
        if case_id in seen:
            raise SweepError(f"`cases[{i}].id` {case_id!r} is used twice")
        seen.add(case_id)
        out.append(Case(case_id, overrides.pop("engine", engine), overrides))
    return out


def function_name(function: Any) -> str:
    """``"module:qualname"`` of a case function, checked to import back to the same object."""
    if isinstance(function, str):
        resolve_function(function)
        return function
    name = f"{getattr(function, '__module__', None)}:{getattr(function, '__qualname__', None)}"
    try:
        same = resolve_function(name) is function
    except SweepError:
        same = False
    if not same:
        raise SweepError(f"`function` must be a top-level callable importable as 'module:name' "
                         f"(it is sent to worker processes), got {function!r}")
    return name


@functools.lru_cache(maxsize=16)
def resolve_function(name: str) -> Callable[[Scene, str], Mapping[str, Any]]:
    """The callable named ``"module:qualname"``."""
    module, sep, qualname = name.partition(":") if isinstance(name, str) else ("", "", "")
    if not (module and sep and qualname):
        raise SweepError(f"`function` must look like 'package.module:function', got {name!r}")
    try:
        obj: Any = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        raise SweepError(f"`function` {name!r} cannot be imported: {exc}") from None
    if not callable(obj):
        raise SweepError(f"`function` {name!r} is not callable")
    return obj




def _flatten(table: Mapping[str, Any], is_leaf: Callable[[Any], bool], prefix: str = "") -> dict:
    """Dotted paths of a TOML table, so that unquoted dotted keys mean what they look like."""
    out = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and not is_leaf(value):
            out.update(_flatten(value, is_leaf, path + "."))
        else:
            out[path] = value
    return out


def _grid_leaf(value: Any) -> bool:
    return isinstance(value, Mapping) and bool(set(value) & set(GRID_FORMS))


def _random_leaf(value: Any) -> bool:
    return isinstance(value, Mapping) and bool(set(value) & {"dist", "low", "high", "mean", "std"})


def _never_leaf(value: Any) -> bool:
    return False


SPEC_KEYS = ("scene", "engine", "function", "fixed", "grid", "random", "cases")
RANDOM_KEYS = ("samples", "seed", "method", "parameters")


def _table(data: Mapping, key: str) -> Mapping:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise SweepError(f"`{key}` must be a table, got {value!r}")
    return value


def random_spec(data: Mapping[str, Any]) -> RandomSpec:
    """A :class:`RandomSpec` from its table; errors name the key."""
    if not isinstance(data, Mapping):
        raise SweepError(f"`random` must be a table, got {data!r}")
    unknown = sorted(set(data) - set(RANDOM_KEYS))
    if unknown:
        raise SweepError(f"[random] unknown key(s) {unknown}; allowed: {list(RANDOM_KEYS)}")
    for key in ("samples", "seed"):
        if key not in data:
            raise SweepError(f"[random] `{key}` is required (an integer; the seed makes the samples "
                             "reproducible and the sweep resumable)")
    parameters = {}
    for path, dist in _flatten(_table(data, "parameters"), _random_leaf).items():
        if not isinstance(dist, Mapping):
            raise SweepError(f"[random.parameters] \"{path}\" must be a table like "
                             f"{{dist = \"uniform\", low = 0, high = 1}}, got {dist!r}")
        if "dist" not in dist:
            raise SweepError(f"[random.parameters] \"{path}\" needs `dist`, one of {sorted(DISTRIBUTIONS)}")
        try:
            parameters[path] = Distribution(**dist)
        except TypeError:
            raise SweepError(f"[random.parameters] \"{path}\": unknown key(s) "
                             f"{sorted(set(dist) - {'dist', 'low', 'high', 'mean', 'std'})}") from None
        except SweepError as exc:
            raise SweepError(f"[random.parameters] \"{path}\": {exc}") from None
    return RandomSpec(data["samples"], data["seed"], parameters, data.get("method", "random"))


def spec_from_mapping(data: Mapping[str, Any], base_dir: str | os.PathLike | None = None) -> SweepSpec:
    """A :class:`SweepSpec` from a (TOML-shaped) dictionary; unknown keys are errors.

    A relative scene path is taken relative to ``base_dir`` (the spec file's folder).
    """
    unknown = sorted(set(data) - set(SPEC_KEYS))
    if unknown:
        raise SweepError(f"unknown key(s) {unknown}; allowed: {list(SPEC_KEYS)}")
    scene = data.get("scene")
    if isinstance(scene, str) and base_dir is not None and looks_like_path(scene):
        scene = str(Path(base_dir, scene))
    cases = data.get("cases", [])
    if not isinstance(cases, Sequence) or isinstance(cases, str):
        raise SweepError(f"`cases` must be a list of tables, got {cases!r}")
    cases = [_flatten(c, _never_leaf) if isinstance(c, Mapping) else c for c in cases]
    return SweepSpec(
        scene=scene, engine=data.get("engine", "exudyn"),
        fixed=_flatten(_table(data, "fixed"), _never_leaf),
        grid=_flatten(_table(data, "grid"), _grid_leaf),
        random=random_spec(data["random"]) if "random" in data else None,
        cases=tuple(cases), function=data.get("function", DEFAULT_FUNCTION))


def read_spec_file(path: str | os.PathLike) -> dict[str, Any]:
    """The raw table of a sweep spec TOML file."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SweepError(f"cannot read sweep spec {str(path)!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise SweepError(f"sweep spec {str(path)!r} is not UTF-8 text (byte {exc.start}); a spec is a "
                         "TOML file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SweepError(f"sweep spec {str(path)!r} is not valid TOML: {exc}") from None


def load_spec(path: str | os.PathLike) -> SweepSpec:
    """Load a sweep specification from a TOML file (a relative scene path is relative to it)."""
    try:
        return spec_from_mapping(read_spec_file(path), base_dir=Path(path).parent)
    except SweepError as exc:
        raise SweepError(f"{path}: {exc}") from None


def looks_like_path(text: str) -> bool:
    return text.endswith(".toml") or os.sep in text or "/" in text


def base_scene(spec: SweepSpec) -> Scene:
    """The spec's scene with its ``fixed`` overrides applied."""
    from reference.paper import named_scene
    from reference.scene import load_scene, scene_from_mapping

    scene = spec.scene
    if isinstance(scene, Mapping):
        scene = scene_from_mapping(scene)
    elif isinstance(scene, str):
        scene = load_scene(scene) if looks_like_path(scene) or Path(scene).is_file() else named_scene(scene)
    elif not isinstance(scene, Scene):
        raise SweepError(f"`scene` must be a scene name, path, table or Scene, got {scene!r}")
    if not spec.fixed:
        return scene
    try:
        return replace(scene, **spec.fixed)
    except SceneError as exc:
        raise SceneError(f"`fixed` overrides: {exc}") from None




@dataclass(frozen=True)
class Plan:
    """A validated sweep: the spec, the base scene and every case."""

    spec: SweepSpec
    base: Scene
    cases: list[Case]

    @property
    def base_hash(self) -> str:
        text = json.dumps(to_jsonable(scene_to_dict(self.base)), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()

    @property
    def parameters(self) -> list[str]:
        """Every overridden path, in first-seen order."""
        return list(dict.fromkeys(p for c in self.cases for p in c.overrides))

    def to_dict(self) -> dict[str, Any]:
        return {"format": PLAN_FORMAT, "spec": self.spec.to_dict(), "function": self.spec.function,
                "base_scene_sha256": self.base_hash, "cases": [c.to_dict() for c in self.cases]}


def make_plan(spec: SweepSpec | Mapping[str, Any]) -> Plan:
    """Validate a spec and expand it: scene, engines, the first case's scene, grid values and
    the quantiles of random parameters must all be valid before any case runs."""
    from cardan_exudyn.engines import get_engine

    spec = spec if isinstance(spec, SweepSpec) else spec_from_mapping(spec)
    base = base_scene(spec)
    cases = spec.expand()
    for engine in dict.fromkeys(c.engine for c in cases):
        get_engine(engine)
    first = cases[0]
    _check_scene(base, first.overrides, f"case {first.id}")
    for path, values in spec.grid.items():
        if path != "engine":
            for v in values:
                _check_scene(base, {**first.overrides, path: v}, f"`grid.\"{path}\"` value {v!r}")
    for path, dist in (spec.random.parameters.items() if spec.random else ()):
        for q, v in zip(CHECKED_QUANTILES, dist.ppf(np.array(CHECKED_QUANTILES)), strict=True):
            _check_scene(base, {**first.overrides, path: float(v)},
                         f"`random.parameters.\"{path}\"` at its {q:g} quantile ({float(v):.6g}); "
                         "narrow or truncate the distribution (low/high)")
    return Plan(spec, base, cases)


def _check_scene(base: Scene, overrides: dict[str, Any], what: str) -> None:
    try:
        replace(base, **overrides)
    except SceneError as exc:
        raise SceneError(f"{what}: {exc}") from None




def scalar_summary(summary: Summary | Mapping[str, Any]) -> dict[str, Any]:
    """The scalar values of an engine summary: numbers, strings, booleans and None at the top
    level, and those of nested tables as ``table.key``; the scene and lists are dropped."""
    out: dict[str, Any] = {}
    if isinstance(summary, Summary):
        summary = summary.to_dict()
    for key, value in summary.items():
        if key in ("scene", "schema_version"):
            continue
        if isinstance(value, Mapping):
            out.update({f"{key}.{k}": v for k, v in value.items() if _is_scalar(v)})
        elif _is_scalar(value):
            out[key] = value
    return to_jsonable(out)


def _is_scalar(value: Any) -> bool:
    return value is None or isinstance(value, (str, bool, int, float, np.generic))


def summary_outputs(scene: Scene, engine: str) -> dict[str, Any]:
    """Default case function: run the scene and keep the summary's scalar values."""
    from cardan_exudyn.engines import run_scene

    return scalar_summary(run_scene(scene, engine).summary)


def run_case(case: Case, base: Scene, function: str = DEFAULT_FUNCTION) -> dict[str, Any]:
    """Run one case and return its record; an exception becomes a record with status ``error``.

    Runs where the case is executed (the driver, a pool process or a Dask worker); nothing is
    written here.
    """
    start = time.perf_counter()
    record: dict[str, Any] = {"id": case.id, "engine": case.engine,
                              "overrides": to_jsonable(case.overrides)}
    try:
        scene = replace(base, **case.overrides) if case.overrides else base
        outputs = resolve_function(function)(scene, case.engine)
        if not isinstance(outputs, Mapping):
            raise TypeError(f"case function {function} returned {type(outputs).__name__}, not a dict")
        clash = sorted(RESERVED_OUTPUTS & set(outputs))
        if clash:
            raise ValueError(f"case function {function} returned reserved key(s) {clash}")
        outputs = to_jsonable({k: v for k, v in _flatten(outputs, _never_leaf).items()})
        status, reason = str(outputs.pop("status", "ok")), str(outputs.pop("reason", "") or "")
        error_type = error = tb = None
    except Exception as exc:
        outputs, status = {}, "error"
        error_type, error = type(exc).__name__, str(exc)
        reason = f"{error_type}: {error}"
        tb = "".join(traceback.format_exception(exc)[-12:])
    record.update(status=status, reason=reason, error_type=error_type, error=error,
                  case_wall_s=time.perf_counter() - start, **outputs)
    if tb is not None:
        record["traceback"] = tb
    return record


def _crash_record(case: Case, error_type: str, error: str) -> dict[str, Any]:
    return {"id": case.id, "engine": case.engine, "overrides": to_jsonable(case.overrides),
            "status": "error", "reason": f"{error_type}: {error}", "error_type": error_type,
            "error": error, "case_wall_s": None}




def _atomic_write_text(path: Path, text: str) -> None:
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def read_records(path: str | os.PathLike, *, truncate: bool = False) -> dict[str, dict[str, Any]]:
    """Records of ``cases.jsonl`` by case id (the last record of an id wins).

    An incomplete last line (no newline: the driver was killed while writing it) is ignored, and
    cut off when ``truncate`` so that the next record starts on a line of its own.
    """
    path = Path(path)
    if not path.exists():
        return {}
    data = path.read_bytes()
    end = data.rfind(b"\n") + 1
    records = {}
    for number, line in enumerate(data[:end].splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except ValueError as exc:
            raise SweepError(f"{path}:{number} is not a JSON record ({exc}); delete that line or "
                             "use --restart") from None
        if not isinstance(record, dict) or not isinstance(record.get("id"), str):
            raise SweepError(f"{path}:{number} is not a case record (no string `id`)")
        records[record["id"]] = record
    if truncate and end < len(data):
        with open(path, "r+b") as f:
            f.truncate(end)
            os.fsync(f.fileno())
    return records


class RecordWriter:
    """Appends records to ``cases.jsonl``, one line each, flushed and fsync'ed."""

    def __init__(self, path: Path) -> None:
        self._file = open(path, "ab")

    def write(self, record: Mapping[str, Any]) -> None:
        line = json.dumps(to_jsonable(record), allow_nan=False, separators=(",", ":")) + "\n"
        self._file.write(line.encode("utf-8"))
        self._file.flush()
        os.fsync(self._file.fileno())

    def close(self) -> None:
        self._file.close()


def _existing_records(out: Path, plan: Plan) -> dict[str, dict[str, Any]]:
    """Records already in ``out`` for this plan; a folder holding another sweep is refused."""
    plan_path, cases_path = out / PLAN_FILE, out / CASES_FILE
    if not plan_path.exists():
        if cases_path.exists():
            raise SweepError(f"{out} has {CASES_FILE} but no {PLAN_FILE}; use --restart or another --out")
        return {}
    try:
        stored = json.loads(plan_path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise SweepError(f"{plan_path} is not valid JSON ({exc}); use --restart") from None
    problem = _plan_difference(stored, plan.to_dict())
    if problem:
        raise SweepError(f"{out} holds a different sweep ({problem}); rerun with --restart to discard "
                         "its records, or use another --out")
    records = read_records(cases_path)
    ids = {c.id for c in plan.cases}
    unknown = sorted(set(records) - ids)
    if unknown:
        raise SweepError(f"{cases_path} has records of cases not in the plan: {unknown[:5]}")
    return records


def _plan_difference(stored: Mapping[str, Any], new: Mapping[str, Any]) -> str:
    if stored.get("format") != PLAN_FORMAT:
        return f"plan format {stored.get('format')!r}, expected {PLAN_FORMAT!r}"
    if stored.get("function") != new["function"]:
        return f"case function {stored.get('function')!r} then, {new['function']!r} now"
    if stored.get("base_scene_sha256") != new["base_scene_sha256"]:
        return "the base scene differs (scene, its file, `fixed` or the code that builds it changed)"
    old_cases, new_cases = stored.get("cases", []), new["cases"]
    if len(old_cases) != len(new_cases):
        return f"{len(old_cases)} cases then, {len(new_cases)} now"
    for old, case in zip(old_cases, new_cases, strict=True):
        if old != case:
            return f"case {case['id']}: {old} then, {case} now"
    return ""


@contextlib.contextmanager
def _locked(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``out`` so that two drivers never append to one sweep."""
    try:
        import fcntl
    except ImportError:  # Windows: no advisory lock
        yield
        return
    with open(out / ".lock", "w") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise SweepError(f"another sweep is running in {out}") from None
        yield




def default_workers() -> int:
    """Cores available to this process."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def _run_in_process(cases: Sequence[Case], base: Scene, function: str, emit) -> None:
    for case in cases:
        emit(run_case(case, base, function))


def _run_pool(cases: Sequence[Case], base: Scene, function: str, workers: int, emit) -> None:
    """Run cases in spawned processes, at most ``2 workers`` submitted at a time.

    A worker that dies (crash, ``os._exit``, out of memory) breaks the pool and every case in
    flight; those are rerun one at a time in a fresh process, where a case that kills the
    process is the one running, and is recorded as ``WorkerCrash``.
    """
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    queue = deque(cases)
    while queue:
        victims = _pool_round(queue, base, function, workers, context, emit)
        _run_one_at_a_time(deque(victims), base, function, context, emit)


def _pool_round(queue: deque, base: Scene, function: str, workers: int, context, emit) -> list[Case]:
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    running: dict[Any, Case] = {}
    with ProcessPoolExecutor(workers, mp_context=context) as pool:
        try:
            while queue or running:
                while queue and len(running) < 2 * workers:
                    case = queue.popleft()
                    running[pool.submit(run_case, case, base, function)] = case
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                broken = False
                for future in done:
                    if isinstance(future.exception(), BrokenProcessPool):
                        broken = True
                        continue
                    emit(future.result())
                    running.pop(future)
                if broken:
                    return list(running.values())
        except BaseException:
            for future in running:
                future.cancel()
            raise
    return []


def _run_one_at_a_time(queue: deque, base: Scene, function: str, context, emit) -> None:
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    while queue:
        with ProcessPoolExecutor(1, mp_context=context) as pool:
            while queue:
                case = queue.popleft()
                try:
                    record = pool.submit(run_case, case, base, function).result()
                except BrokenProcessPool:
                    emit(_crash_record(case, "WorkerCrash", "the worker process died while running "
                                       "this case alone (a crash, os._exit, or killed, e.g. out of memory)"))
                    break
                emit(record)


def connect(scheduler: Any):
    """A :class:`distributed.Client` for an address (``tcp://host:port``) or the client given."""
    try:
        from distributed import Client
    except ImportError as exc:
        raise SweepError(f"--scheduler needs the `distributed` package: {exc}") from None
    if isinstance(scheduler, Client):
        return scheduler
    try:
        return Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepError(f"cannot connect to the Dask scheduler at {scheduler!r}: {exc}") from None


def _run_dask(cases: Sequence[Case], base: Scene, function: str, client, emit) -> None:
    """Submit every case to the cluster and record them as they complete.

    A case whose worker dies repeatedly (Dask's ``KilledWorker``) is recorded as failed; any
    other failure of the cluster stops the sweep, recording nothing for the cases in flight.
    """
    from distributed import KilledWorker, as_completed

    if not cases:
        return
    token = uuid.uuid4().hex[:8]
    base_future = client.scatter(base, broadcast=True)
    futures = client.map(run_case, cases, base=base_future, function=function, pure=False,
                         key=[f"cardan-sweep-{token}-{case.id}" for case in cases])
    case_of = dict(zip(futures, cases, strict=True))
    try:
        for future, result in as_completed(futures, with_results=True, raise_errors=False):
            case = case_of[future]
            if future.status == "finished":
                emit(result)
                continue
            error = future.exception() if future.status == "error" else future.status
            if not isinstance(error, KilledWorker):
                raise SweepIncomplete(f"the Dask cluster failed on case {case.id}: "
                                      f"{type(error).__name__}: {error}; rerun to resume")
            emit(_crash_record(case, "KilledWorker", str(error)))
    finally:
        client.cancel(futures)




class _Progress:
    """Cases done / total, failures, elapsed and ETA on stderr (tqdm), or nothing."""

    def __init__(self, total: int, done: int, failed: int, show: bool) -> None:
        self.failed = failed
        self._bar = None
        if show:
            from tqdm import tqdm

            self._bar = tqdm(total=total, initial=done, unit="case", file=sys.stderr,
                             dynamic_ncols=True, desc="sweep", smoothing=0.1)
            self._bar.set_postfix(failed=failed)

    def update(self, ok: bool) -> None:
        self.failed += not ok
        if self._bar is not None:
            self._bar.set_postfix(failed=self.failed, refresh=False)
            self._bar.update(1)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def run_sweep(spec: SweepSpec | Mapping[str, Any], out: str | os.PathLike, *,
              workers: int | None = None, scheduler: Any = None, restart: bool = False,
              retry_failed: bool = False, progress: bool | None = None) -> dict[str, Any]:
    """Run (or resume) a sweep into the folder ``out`` and return its summary (``sweep.json``).

    Parameters
    ----------
    spec : SweepSpec or dict
        What to sweep; a dictionary is read by :func:`spec_from_mapping`.
    out : path
        Output folder; if it holds records of the same plan, only the missing cases run.
    workers : int, optional
        Local processes (default: every available core); 1 runs the cases in this process.
    scheduler : str or distributed.Client, optional
        Dask scheduler address (``tcp://host:port``) or client; the cases then run on that cluster.
    restart : bool
        Discard the sweep files in ``out`` (plan, records, tables) and start over.
    retry_failed : bool
        Also rerun cases recorded with a status other than ``ok``.
    progress : bool, optional
        Progress bar on stderr; default when stderr is a terminal.

    Returns
    -------
    dict
        The content of ``sweep.json``: spec, counts, wall time, statistics per output.

    Raises
    ------
    SweepError, SceneError, EngineUnavailable
        Invalid spec or output folder; raised before anything is written.
    SweepIncomplete
        The Dask cluster failed; the records so far are kept, rerun to resume.
    """
    start = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SweepError(f"`workers` must be an integer >= 1, got {workers!r}")
    plan = make_plan(spec)
    out = Path(out)
    try:
        check_output_folder(out, replace=False)
    except OutputError as exc:
        raise SweepError(f"--out {exc}") from None
    if not restart:
        _existing_records(out, plan)
    client = connect(scheduler) if scheduler is not None else None
    try:
        out.mkdir(parents=True, exist_ok=True)
        with _locked(out):
            records = _prepare(out, plan, restart)
            todo = [c for c in plan.cases if c.id not in records
                    or (retry_failed and records[c.id].get("status") != "ok")]
            executor = _execute(plan, todo, records, out, workers, client, progress)
            return _finish(plan, records, out, len(todo), time.perf_counter() - start, executor)
    finally:
        if client is not None and client is not scheduler:
            client.close()


def _prepare(out: Path, plan: Plan, restart: bool) -> dict[str, dict[str, Any]]:
    """Under the lock: reset or check the folder, write the plan, cut a torn last record."""
    if restart:
        for name in SWEEP_FILES:
            (out / name).unlink(missing_ok=True)
    records = _existing_records(out, plan)
    if not (out / PLAN_FILE).exists():
        _atomic_write_text(out / PLAN_FILE, json.dumps(plan.to_dict(), indent=1, allow_nan=False) + "\n")
    read_records(out / CASES_FILE, truncate=True)
    (out / RESULTS_FILE).unlink(missing_ok=True)
    (out / SUMMARY_FILE).unlink(missing_ok=True)
    return records


def _execute(plan: Plan, todo: list[Case], records: dict, out: Path, workers: int | None,
             client, progress: bool | None) -> dict[str, Any]:
    """Run ``todo``, appending each record as it arrives; returns how the cases were run."""
    rerun = {c.id for c in todo}
    failed = sum(r.get("status") != "ok" for i, r in records.items() if i not in rerun)
    show = sys.stderr.isatty() if progress is None else progress
    bar = _Progress(len(plan.cases), len(plan.cases) - len(todo), failed, show and bool(todo))
    writer = RecordWriter(out / CASES_FILE)

    def emit(record: dict[str, Any]) -> None:
        writer.write(record)
        records[record["id"]] = record
        bar.update(record.get("status") == "ok")

    function = plan.spec.function
    workers = min(workers or default_workers(), max(len(todo), 1))
    try:
        if client is not None:
            executor = {"kind": "dask", "scheduler": client.scheduler.address,
                        "threads": sum(client.nthreads().values())}
            _run_dask(todo, plan.base, function, client, emit)
        elif workers == 1:
            executor = {"kind": "in-process", "workers": 1}
            _run_in_process(todo, plan.base, function, emit)
        else:
            executor = {"kind": "processes", "workers": workers}
            _run_pool(todo, plan.base, function, workers, emit)
    finally:
        writer.close()
        bar.close()
    return executor


def _finish(plan: Plan, records: dict, out: Path, run_now: int, wall: float,
            executor: dict[str, Any]) -> dict[str, Any]:
    table = results_table(plan, records)
    ok = table["status"] == "ok"
    summary = {
        "spec": plan.spec.to_dict(),
        "base_scene": plan.base.name,
        "base_scene_sha256": plan.base_hash,
        "cases": len(plan.cases),
        "done": int(len(table)),
        "ok": int(ok.sum()),
        "failed": int((~ok).sum()),
        "status_counts": {str(k): int(v) for k, v in table["status"].value_counts().items()},
        "failed_ids": table.loc[~ok, "id"].tolist(),
        "run_now": run_now,
        "executor": executor,
        "wall_time_s": wall,
        "case_time_s": float(np.nansum(table["case_wall_s"].to_numpy(dtype=float))),
        "statistics": statistics(table, plan.parameters),
        "files": {"plan": PLAN_FILE, "records": CASES_FILE, "table": RESULTS_FILE},
        "environment": environment(),
    }
    _atomic_write_text(out / RESULTS_FILE, table.to_csv(index=False))
    _atomic_write_text(out / SUMMARY_FILE, json.dumps(to_jsonable(summary), indent=2,
                                                      allow_nan=False) + "\n")
    return to_jsonable(summary)


def results_table(plan: Plan, records: Mapping[str, Mapping[str, Any]]):
    """One row per recorded case in plan order: id, engine, parameters, status, outputs.

    A parameter whose value is not a scalar is written as JSON text; an output named like a
    parameter becomes ``result.<name>``.
    """
    import pandas as pd

    params = plan.parameters
    rows = []
    for case in plan.cases:
        record = records.get(case.id)
        if record is None:
            continue
        row: dict[str, Any] = {"id": case.id, "engine": record.get("engine", case.engine)}
        row.update({p: _cell(case.overrides.get(p)) for p in params})
        for key, value in record.items():
            if key in ("id", "engine", "overrides", "traceback"):
                continue
            row[f"result.{key}" if key in params else key] = _cell(value)
        rows.append(row)
    head = ["id", "engine", *params, *RECORD_KEYS[3:]]
    table = pd.DataFrame(rows)
    for column in head:
        if column not in table:
            table[column] = None
    return table[head + [c for c in table.columns if c not in head]]


def _cell(value: Any) -> Any:
    return json.dumps(to_jsonable(value)) if isinstance(value, (list, tuple, dict)) else value


def statistics(table, parameters: Sequence[str] = ()) -> dict[str, dict[str, float]]:
    """Per numeric output over the cases with status ``ok``: n, mean, std, min, 5 %, 50 %,
    95 % quantiles, max."""
    import pandas as pd

    ok = table[table["status"] == "ok"]
    skip = {"id", "engine", *parameters, *RECORD_KEYS}
    stats = {}
    for column in ok.columns:
        if column in skip or column == "case_wall_s":
            continue
        values = pd.to_numeric(ok[column], errors="coerce") if ok[column].dtype != bool else None
        if values is None or values.notna().sum() == 0 or ok[column].map(_is_text).any():
            continue
        x = values.dropna().to_numpy(dtype=float)
        q05, q50, q95 = np.quantile(x, [0.05, 0.5, 0.95])
        stats[column] = {"n": int(x.size), "mean": float(x.mean()),
                         "std": float(x.std(ddof=1)) if x.size > 1 else 0.0, "min": float(x.min()),
                         "p05": float(q05), "p50": float(q50), "p95": float(q95), "max": float(x.max())}
    wall = pd.to_numeric(table["case_wall_s"], errors="coerce").dropna().to_numpy(dtype=float)
    if wall.size:
        stats["case_wall_s"] = {"n": int(wall.size), "mean": float(wall.mean()), "min": float(wall.min()),
                                "p50": float(np.median(wall)), "max": float(wall.max())}
    return stats


def _is_text(value: Any) -> bool:
    return isinstance(value, (str, bool))


def environment() -> dict[str, Any]:
    """Versions, CPU, date and commit, for the head of ``sweep.json``."""
    from importlib import metadata

    versions = {}
    for package in ("cardan-exudyn", "numpy", "scipy", "exudyn", "distributed", "pandas",
                    "mujoco", "matplotlib"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    return {"python": platform.python_version(), "platform": platform.platform(),
            "machine": platform.machine(), "cpu": _cpu_model(),
            "cpu_count": os.cpu_count(), "packages": versions, "commit": _git_commit(),
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def _cpu_model() -> str:
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def _git_commit() -> str | None:
    import subprocess

    try:
        proc = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                              capture_output=True, text=True, timeout=5)
    except (OSError, subprocess.SubprocessError):
        return None
    return proc.stdout.strip() or None if proc.returncode == 0 else None
