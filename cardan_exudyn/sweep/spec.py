"""What a sweep runs: the specification, its distributions and grids, and reading it from TOML.

A :class:`SweepSpec` names a base scene, an engine, overrides applied to every case (``fixed``),
and the cases: a ``grid`` (cartesian product), ``random`` samples (:class:`RandomSpec` of
:class:`Distribution`), both, or an explicit list. Its case function is named ``"module:name"``
(with keyword arguments ``function_args``) so that worker processes and Dask workers can import
it: :class:`CaseFunction` is what they receive. Everything here validates on construction and
raises :class:`SweepError` naming the key.
"""

from __future__ import annotations

import functools
import importlib
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.jsonable import to_jsonable
from reference.scene.files import read_toml
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene

__all__ = ["SweepError", "Distribution", "RandomSpec", "SweepSpec", "CaseFunction",
           "DEFAULT_FUNCTION", "grid_values", "function_name", "resolve_function", "flatten_paths",
           "random_spec", "spec_from_mapping", "read_spec_file", "load_spec", "looks_like_path"]

# the public face's name, not the defining module's: it survives moves inside the package
DEFAULT_FUNCTION = "cardan_exudyn.sweep:summary_outputs"
GRID_FORMS = ("linspace", "geomspace")
MAX_CASES = 100_000
"""Most cases one sweep may have (grid points times random samples): more would take weeks and a
plan too large for memory."""
SAMPLING_METHODS = ("random", "lhs")
DISTRIBUTIONS = {"uniform": ("low", "high"), "loguniform": ("low", "high"),
                 "normal": ("mean", "std", "low", "high")}
SPEC_KEYS = ("scene", "engine", "function", "function_args", "fixed", "grid", "random", "cases")
RANDOM_KEYS = ("samples", "seed", "method", "parameters")
# arguments a case function always receives; `function_args` must not set them
CASE_ARGUMENTS = ("scene", "engine")


class SweepError(ValueError):
    """The sweep specification or the output folder is invalid; the message names the key."""


def finite_number(where: str, value: Any) -> float:
    """``value`` as a float; :class:`SweepError` naming ``where`` unless a finite number."""
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
        self._set_parameters()
        self._check_ranges()

    def _set_parameters(self) -> None:
        allowed = DISTRIBUTIONS[self.dist]
        for name in ("low", "high", "mean", "std"):
            value = getattr(self, name)
            if value is not None:
                if name not in allowed:
                    raise SweepError(f"`{name}` is not a parameter of {self.dist!r}; give {allowed}")
                object.__setattr__(self, name, finite_number(f"`{name}`", value))
        required = ("mean", "std") if self.dist == "normal" else ("low", "high")
        missing = [n for n in required if getattr(self, n) is None]
        if missing:
            raise SweepError(f"{self.dist!r} needs {list(required)}, missing {missing}")

    def _check_ranges(self) -> None:
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
        from scipy.special import ndtr  # scipy loads only for a normal distribution

        lo, hi = self._bounds()
        return float(ndtr(hi) - ndtr(lo))

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Inverse distribution function.

        Parameters
        ----------
        u : array_like
            Probabilities in [0, 1).

        Returns
        -------
        numpy.ndarray
            The values, in the parameter's unit.
        """
        u = np.clip(np.asarray(u, dtype=float), np.finfo(float).tiny, 1.0 - np.finfo(float).epsneg)
        if self.dist == "uniform":
            return self.low + u * (self.high - self.low)
        if self.dist == "loguniform":
            return np.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        if self._truncated():
            from scipy.stats import truncnorm  # scipy.stats takes about 0.5 s to import

            lo, hi = self._bounds()
            return truncnorm.ppf(u, lo, hi, loc=self.mean, scale=self.std)
        from scipy.special import ndtri  # as above: only a normal distribution needs scipy

        return self.mean + self.std * ndtri(u)

    def to_dict(self) -> dict[str, Any]:
        """The table of the spec file (parameters that are set)."""
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
        if not 1 <= self.samples <= MAX_CASES:
            raise SweepError(f"`random.samples` must be in [1, {MAX_CASES}], got {self.samples!r}")
        if self.seed < 0:
            raise SweepError(f"`random.seed` must be >= 0, got {self.seed!r}")
        if self.method not in SAMPLING_METHODS:
            raise SweepError(f"`random.method` must be one of {list(SAMPLING_METHODS)}, got {self.method!r}")
        if not self.parameters:
            raise SweepError("`random.parameters` is empty: give at least one parameter")

    def points(self) -> list[dict[str, float]]:
        """The N samples, each a dictionary path -> value (in the parameter's unit)."""
        rng = np.random.default_rng(self.seed)
        d = len(self.parameters)
        if self.method == "lhs":
            from scipy.stats import qmc  # scipy.stats takes about 0.5 s to import

            u = qmc.LatinHypercube(d, rng=rng).random(self.samples)
        else:
            u = rng.random((self.samples, d))
        columns = [dist.ppf(u[:, j]) for j, dist in enumerate(self.parameters.values())]
        return [{path: float(col[i]) for path, col in zip(self.parameters, columns, strict=True)}
                for i in range(self.samples)]

    def to_dict(self) -> dict[str, Any]:
        """The ``[random]`` table of the spec file."""
        return {"samples": int(self.samples), "seed": int(self.seed), "method": self.method,
                "parameters": {k: v.to_dict() for k, v in self.parameters.items()}}


@dataclass(frozen=True)
class CaseFunction:
    """A case function by name, with keyword arguments: ``name(scene, engine, **args)``.

    What the driver sends to worker processes and Dask workers (a name and plain data pickle
    anywhere the package is installed), like :func:`functools.partial` of an importable function.

    Attributes
    ----------
    name : str
        ``"module:qualname"`` of a top-level callable ``fn(scene, engine, **args) -> dict``.
    args : dict
        Keyword arguments (JSON-able values), e.g. a folder the function writes files into.
    """

    name: str = DEFAULT_FUNCTION
    args: Mapping[str, Any] = field(default_factory=dict)

    def __call__(self, scene: Scene, engine: str) -> Any:
        return resolve_function(self.name)(scene, engine, **self.args)


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep.

    Attributes
    ----------
    scene : str, dict or Scene
        Named scene (``reference.paper.scenes.named_scene``), path to a scene TOML, a scene table, or a
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
        Case function ``fn(scene, engine, **function_args) -> dict`` of scalars, a top-level
        callable or its ``"module:name"``; default :func:`cardan_exudyn.sweep.summary_outputs`.
    function_args : dict
        Keyword arguments of the case function (JSON-able values); part of the plan, so a sweep
        resumes only with the same arguments.
    """

    scene: Any
    engine: str = "exudyn"
    fixed: dict[str, Any] = field(default_factory=dict)
    grid: dict[str, Any] = field(default_factory=dict)
    random: RandomSpec | None = None
    cases: tuple = ()
    function: Any = DEFAULT_FUNCTION
    function_args: dict[str, Any] = field(default_factory=dict)

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
        total = math.prod(len(v) for v in self.grid.values()) * (self.random.samples if self.random else 1)
        if max(total, len(self.cases)) > MAX_CASES:
            raise SweepError(f"the sweep has {max(total, len(self.cases))} cases; at most {MAX_CASES} are "
                             "allowed (fewer grid values or samples)")
        object.__setattr__(self, "function", function_name(self.function))
        object.__setattr__(self, "function_args", _function_args(self.function_args))

    def case_function(self) -> CaseFunction:
        """The case function with its arguments, as sent to the workers."""
        return CaseFunction(self.function, dict(self.function_args))

    def to_dict(self) -> dict[str, Any]:
        """The spec as JSON-able data (``function_args`` only when given)."""
        scene = scene_to_dict(self.scene) if isinstance(self.scene, Scene) else self.scene
        data = {"scene": scene, "engine": self.engine, "function": self.function,
                "fixed": dict(self.fixed), "grid": {k: list(v) for k, v in self.grid.items()},
                "random": self.random.to_dict() if self.random else None, "cases": list(self.cases)}
        if self.function_args:
            data["function_args"] = dict(self.function_args)
        return to_jsonable(data)


def _check_disjoint(spec: SweepSpec) -> None:
    random = set(spec.random.parameters) if spec.random else set()
    for a, b, keys in (("fixed", "grid", set(spec.fixed) & set(spec.grid)),
                       ("fixed", "random", set(spec.fixed) & random),
                       ("grid", "random", set(spec.grid) & random)):
        if keys:
            raise SweepError(f"{sorted(keys)} appear in both `{a}` and `{b}`")
    if "engine" in spec.fixed or "engine" in random:
        raise SweepError("`engine` can be set at the top level, in `grid` or in `cases` only")


def _function_args(args: Any) -> dict[str, Any]:
    """``function_args`` checked: a table of keyword names to JSON-able values."""
    if not isinstance(args, Mapping):
        raise SweepError(f"`function_args` must be a table, got {args!r}")
    for name in args:
        if not isinstance(name, str) or not name.isidentifier():
            raise SweepError(f"`function_args` keys must be argument names, got {name!r}")
        if name in CASE_ARGUMENTS:
            raise SweepError(f"`function_args` cannot set `{name}`: the runner passes it")
    values = to_jsonable(dict(args))
    try:
        json.dumps(values)  # they go into plan.json and to the workers
    except (TypeError, ValueError) as exc:
        raise SweepError(f"`function_args` must hold JSON values: {exc}") from None
    return values


def grid_values(path: str, spec: Any) -> tuple:
    """The values of one grid parameter.

    Parameters
    ----------
    path : str
        Dotted scene path (named in errors).
    spec : list or dict
        The values, or ``{linspace|geomspace = [start, stop, num]}``.

    Returns
    -------
    tuple
        The values, in the parameter's unit.
    """
    where = f"`grid.\"{path}\"`"
    if isinstance(spec, Mapping):
        return _spaced_values(where, spec)
    if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence):
        raise SweepError(f"{where} must be a list of values or {{linspace = [start, stop, num]}}, "
                         f"got {spec!r}")
    if len(spec) == 0:
        raise SweepError(f"{where} is an empty list: give at least one value")
    return tuple(spec)


def _spaced_values(where: str, spec: Mapping) -> tuple:
    if len(spec) != 1 or next(iter(spec)) not in GRID_FORMS:
        raise SweepError(f"{where} must be a list or one of "
                         f"{[f'{{{f} = [start, stop, num]}}' for f in GRID_FORMS]}, got {spec!r}")
    form, args = next(iter(spec.items()))
    if not isinstance(args, Sequence) or len(args) != 3:
        raise SweepError(f"{where}: {form} needs [start, stop, num], got {args!r}")
    start, stop = (finite_number(f"{where} {form} start/stop", v) for v in args[:2])
    num = args[2]
    if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= MAX_CASES:
        raise SweepError(f"{where}: {form} num must be an integer >= 1 and at most {MAX_CASES}, got {num!r}")
    if form == "geomspace" and (start <= 0.0 or stop <= 0.0):
        raise SweepError(f"{where}: geomspace needs positive start and stop, got {args!r}")
    return tuple(float(v) for v in getattr(np, form)(start, stop, num))


def function_name(function: Any) -> str:
    """``"module:qualname"`` of a case function, checked to import back to the same object.

    Parameters
    ----------
    function : str or callable
        The name, or a top-level callable.
    """
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
def resolve_function(name: str) -> Callable[..., Mapping[str, Any]]:
    """The callable named ``"module:qualname"``; :class:`SweepError` when it does not import."""
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


def flatten_paths(table: Mapping[str, Any], is_leaf: Callable[[Any], bool] | None = None,
                  prefix: str = "") -> dict[str, Any]:
    """Dotted paths of a nested table (so that TOML's unquoted dotted keys mean what they look
    like); a sub-table for which ``is_leaf`` is true is kept as one value."""
    out = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and not (is_leaf and is_leaf(value)):
            out.update(flatten_paths(value, is_leaf, path + "."))
        else:
            out[path] = value
    return out


def _grid_leaf(value: Any) -> bool:
    return isinstance(value, Mapping) and bool(set(value) & set(GRID_FORMS))


def _random_leaf(value: Any) -> bool:
    return isinstance(value, Mapping) and bool(set(value) & {"dist", "low", "high", "mean", "std"})


def _table(data: Mapping, key: str) -> Mapping:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise SweepError(f"`{key}` must be a table, got {value!r}")
    return value


def random_spec(data: Mapping[str, Any]) -> RandomSpec:
    """A :class:`RandomSpec` from its ``[random]`` table; errors name the key."""
    if not isinstance(data, Mapping):
        raise SweepError(f"`random` must be a table, got {data!r}")
    unknown = sorted(set(data) - set(RANDOM_KEYS))
    if unknown:
        raise SweepError(f"[random] unknown key(s) {unknown}; allowed: {list(RANDOM_KEYS)}")
    for key in ("samples", "seed"):
        if key not in data:
            raise SweepError(f"[random] `{key}` is required (an integer; the seed makes the samples "
                             "reproducible and the sweep resumable)")
    parameters = {path: _distribution(path, dist)
                  for path, dist in flatten_paths(_table(data, "parameters"), _random_leaf).items()}
    return RandomSpec(data["samples"], data["seed"], parameters, data.get("method", "random"))


def _distribution(path: str, dist: Any) -> Distribution:
    if not isinstance(dist, Mapping):
        raise SweepError(f"[random.parameters] \"{path}\" must be a table like "
                         f"{{dist = \"uniform\", low = 0, high = 1}}, got {dist!r}")
    if "dist" not in dist:
        raise SweepError(f"[random.parameters] \"{path}\" needs `dist`, one of {sorted(DISTRIBUTIONS)}")
    try:
        return Distribution(**dist)
    except TypeError:
        raise SweepError(f"[random.parameters] \"{path}\": unknown key(s) "
                         f"{sorted(set(dist) - {'dist', 'low', 'high', 'mean', 'std'})}") from None
    except SweepError as exc:
        raise SweepError(f"[random.parameters] \"{path}\": {exc}") from None


def spec_from_mapping(data: Mapping[str, Any], base_dir: str | os.PathLike | None = None) -> SweepSpec:
    """A :class:`SweepSpec` from a (TOML-shaped) dictionary; unknown keys are errors.

    Parameters
    ----------
    data : mapping
        The keys of :data:`SPEC_KEYS`.
    base_dir : path, optional
        Folder a relative scene path is taken relative to (the spec file's folder).
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
    cases = [flatten_paths(c) if isinstance(c, Mapping) else c for c in cases]
    return SweepSpec(
        scene=scene, engine=data.get("engine", "exudyn"),
        fixed=flatten_paths(_table(data, "fixed")),
        grid=flatten_paths(_table(data, "grid"), _grid_leaf),
        random=random_spec(data["random"]) if "random" in data else None,
        cases=tuple(cases), function=data.get("function", DEFAULT_FUNCTION),
        function_args=_table(data, "function_args"))


def read_spec_file(path: str | os.PathLike) -> dict[str, Any]:
    """The raw table of a sweep spec TOML file; :class:`SweepError` if unreadable or not TOML."""
    return read_toml(path, "sweep spec", "a spec", SweepError)


def load_spec(path: str | os.PathLike) -> SweepSpec:
    """Load a sweep specification from a TOML file (a relative scene path is relative to it)."""
    try:
        return spec_from_mapping(read_spec_file(path), base_dir=Path(path).parent)
    except SweepError as exc:
        raise SweepError(f"{path}: {exc}") from None


def looks_like_path(text: str) -> bool:
    """Whether a ``scene`` value names a file rather than a named scene."""
    return text.endswith(".toml") or os.sep in text or "/" in text
