"""What a sweep runs: the specification (:class:`SweepSpec`), its grids, and reading it from TOML.

Everything validates on construction and raises :class:`~cardan_exudyn.sweep.checks.SweepError`
naming the key.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.sweep.checks import MAX_CASES, SweepError, finite_number
from cardan_exudyn.sweep.functions import DEFAULT_FUNCTION, CaseFunction, function_args, function_name
from cardan_exudyn.sweep.sampling import DISTRIBUTIONS, Distribution, RandomSpec
from reference.scene.files import read_toml
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene

__all__ = ["GRID_FORMS", "SPEC_KEYS", "RANDOM_KEYS", "SweepSpec", "grid_values", "flatten_paths",
           "random_spec", "spec_from_mapping", "read_spec_file", "load_spec", "looks_like_path"]

GRID_FORMS = ("linspace", "geomspace")
"""The spaced forms of a grid parameter, ``{linspace = [start, stop, num]}`` (numpy's)."""
SPEC_KEYS = ("scene", "engine", "function", "function_args", "fixed", "grid", "random", "cases")
"""The keys of a spec table."""
RANDOM_KEYS = ("samples", "seed", "method", "parameters")
"""The keys of its ``[random]`` table."""


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep.

    Attributes
    ----------
    scene : str, dict or Scene
        Named scene, path to a scene TOML, a scene table, or a scene.
    engine : str
        Engine of :data:`cardan_exudyn.engines.ENGINES` (a grid or a case may set ``engine``).
    fixed : dict
        Overrides of the base scene for every case (dotted path -> value).
    grid : dict
        Dotted path -> list of values (or ``{"linspace": [start, stop, num]}``, ``{"geomspace": ...}``);
        cases are the cartesian product, last path fastest.
    random : RandomSpec or None
        Random samples; with a grid, every grid point takes every sample.
    cases : tuple of dict
        Explicit cases (dotted path -> value; optional ``id``, ``engine``); excludes grid and random.
    function : str or callable
        Case function ``fn(scene, engine, **function_args) -> dict`` of scalars, or its
        ``"module:name"``; default :func:`cardan_exudyn.sweep.summary_outputs`.
    function_args : dict
        JSON-able keyword arguments of the case function; part of the plan.
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
        object.__setattr__(self, "function_args", function_args(self.function_args))

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
    """:class:`SweepError` for a path set in two of ``fixed``, ``grid`` and ``random``, or an
    ``engine`` anywhere but the top level, the grid or the cases."""
    random = set(spec.random.parameters) if spec.random else set()
    for a, b, keys in (("fixed", "grid", set(spec.fixed) & set(spec.grid)),
                       ("fixed", "random", set(spec.fixed) & random),
                       ("grid", "random", set(spec.grid) & random)):
        if keys:
            raise SweepError(f"{sorted(keys)} appear in both `{a}` and `{b}`")
    if "engine" in spec.fixed or "engine" in random:
        raise SweepError("`engine` can be set at the top level, in `grid` or in `cases` only")


def grid_values(path: str, spec: Any) -> tuple:
    """Values of grid parameter ``path``: ``spec`` a list or ``{linspace|geomspace = [start, stop, num]}``."""
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
    """The values of ``{linspace|geomspace = [start, stop, num]}`` (``where`` names the key)."""
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


def flatten_paths(table: Mapping[str, Any], is_leaf: Callable[[Any], bool] | None = None,
                  prefix: str = "") -> dict[str, Any]:
    """Dotted path -> value of a nested ``table`` (TOML's unquoted dotted keys), each path prefixed by
    ``prefix``; a sub-table for which ``is_leaf(sub)`` is true stays one value.
    """
    out = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and not (is_leaf and is_leaf(value)):
            out.update(flatten_paths(value, is_leaf, path + "."))
        else:
            out[path] = value
    return out


def _grid_leaf(value: Any) -> bool:
    """A grid's ``{linspace|geomspace = [...]}``: one value, not a sub-table."""
    return isinstance(value, Mapping) and bool(set(value) & set(GRID_FORMS))


def _random_leaf(value: Any) -> bool:
    """A distribution's table: one value, not a sub-table."""
    return isinstance(value, Mapping) and bool(set(value) & {"dist", "low", "high", "mean", "std"})


def _table(data: Mapping, key: str) -> Mapping:
    """``data[key]`` (empty when missing); :class:`SweepError` unless it is a table."""
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
    """The :class:`Distribution` of parameter ``path`` from its table; errors name the path."""
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
    """A :class:`SweepSpec` from a TOML-shaped ``data`` (keys of :data:`SPEC_KEYS`), a relative scene
    path taken from ``base_dir``; SweepError naming an unknown key or invalid value.
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
