"""A sweep's plan: the spec expanded into cases with stable ids, validated before any case runs.

A rerun into the same folder resumes only when its plan equals the stored ``plan.json``.
"""

from __future__ import annotations

import hashlib
import itertools
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.engines import get_engine
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.sweep.checks import SweepError
from cardan_exudyn.sweep.functions import resolve_function
from cardan_exudyn.sweep.spec import SweepSpec, looks_like_path, spec_from_mapping
from reference.paper.scenes import named_scene
from reference.scene.files import load_scene, scene_from_mapping
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

__all__ = ["PLAN_FORMAT", "Case", "Plan", "expand_cases", "base_scene", "make_plan", "plan_difference"]

PLAN_FORMAT = "cardan-sweep/1"
"""The ``format`` of ``plan.json``; a stored plan of another format is another sweep."""
CHECKED_QUANTILES = (1e-9, 0.5, 1.0 - 1e-9)
"""Quantiles of a random parameter checked against the scene's validation before any case runs."""


@dataclass(frozen=True)
class Case:
    """One run of a sweep: ``function(replace(base, **overrides), engine)``.

    Attributes
    ----------
    id : str
        Unique within the sweep; stable across reruns of the same spec.
    engine : str
        A key of :data:`cardan_exudyn.engines.ENGINES`.
    overrides : dict
        Dotted scene path -> value (in the path's unit).
    """

    id: str
    engine: str
    overrides: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        """The case as stored in ``plan.json`` and at the head of its record."""
        return {"id": self.id, "engine": self.engine, "overrides": to_jsonable(self.overrides)}


def expand_cases(spec: SweepSpec) -> list[Case]:
    """Every case of the sweep, in order; ids ``0000``, ``0001``, ... (or the explicit cases' own),
    the same for the same spec so that a sweep can resume.
    """
    if spec.cases:
        return _explicit_cases(spec.cases, spec.engine)
    grid = [dict(zip(spec.grid, combo, strict=True))
            for combo in itertools.product(*spec.grid.values())] or [{}]
    samples = spec.random.points() if spec.random else [{}]
    points = [{**g, **s} for g in grid for s in samples]
    width = max(4, len(str(len(points) - 1)))
    cases = []
    for i, point in enumerate(points):
        engine = point.pop("engine", spec.engine)
        cases.append(Case(f"{i:0{width}d}", engine, point))
    return cases


def _explicit_cases(cases: Sequence, engine: str) -> list[Case]:
    """The spec's explicit ``cases`` with their ids (or index) and engines (or ``engine``); SweepError
    for a case that is no table or an id used twice.
    """
    width = max(4, len(str(len(cases) - 1)))
    out = []
    seen = set()
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


def base_scene(spec: SweepSpec) -> Scene:
    """The spec's scene (named, a file or a table) with its ``fixed`` overrides applied."""
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
    """A validated sweep: the spec, the base scene (``fixed`` applied) and every case, in order."""

    spec: SweepSpec
    base: Scene
    cases: list[Case]

    @property
    def base_hash(self) -> str:
        """SHA-256 of the base scene's canonical JSON."""
        text = json.dumps(to_jsonable(scene_to_dict(self.base)), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()

    @property
    def parameters(self) -> list[str]:
        """Every overridden path, in first-seen order."""
        return list(dict.fromkeys(p for c in self.cases for p in c.overrides))

    def to_dict(self) -> dict[str, Any]:
        """The content of ``plan.json`` (``function_args`` only when the spec has any)."""
        data = {"format": PLAN_FORMAT, "spec": self.spec.to_dict(), "function": self.spec.function,
                "base_scene_sha256": self.base_hash, "cases": [c.to_dict() for c in self.cases]}
        if self.spec.function_args:
            data["function_args"] = to_jsonable(dict(self.spec.function_args))
        return data


def make_plan(spec: SweepSpec | Mapping[str, Any]) -> Plan:
    """Validate a spec and expand it into a :class:`Plan`.

    The scene, the engines, the first case's scene, every grid value and the 1e-9, 0.5 and
    1 - 1e-9 quantiles of every random parameter are checked before any case runs.

    Parameters
    ----------
    spec : SweepSpec or dict
        A dict is read by :func:`cardan_exudyn.sweep.spec_from_mapping`.

    Raises
    ------
    SweepError, SceneError, EngineUnavailable
        Naming the key, value or case at fault.
    """
    spec = spec if isinstance(spec, SweepSpec) else spec_from_mapping(spec)
    base = base_scene(spec)
    cases = expand_cases(spec)
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
    """``SceneError`` prefixed with ``what`` when ``overrides`` make no valid scene of ``base``."""
    try:
        replace(base, **overrides)
    except SceneError as exc:
        raise SceneError(f"{what}: {exc}") from None


def plan_difference(stored: Mapping[str, Any], new: Mapping[str, Any]) -> str:
    """The first difference, in words, between ``stored`` ``plan.json`` content and ``new``
    (:meth:`Plan.to_dict`); "" when a rerun may resume the stored sweep.
    """
    if stored.get("format") != PLAN_FORMAT:
        return f"plan format {stored.get('format')!r}, expected {PLAN_FORMAT!r}"
    if not _same_function(stored.get("function"), new["function"]):
        return f"case function {stored.get('function')!r} then, {new['function']!r} now"
    if stored.get("base_scene_sha256") != new["base_scene_sha256"]:
        return "the base scene differs (scene, its file, `fixed` or the code that builds it changed)"
    old_cases = stored.get("cases", [])
    new_cases = new["cases"]
    if len(old_cases) != len(new_cases):
        return f"{len(old_cases)} cases then, {len(new_cases)} now"
    for old, case in zip(old_cases, new_cases, strict=True):
        if old != case:
            return f"case {case['id']}: {old} then, {case} now"
    old_args = stored.get("function_args", {})
    new_args = new.get("function_args", {})
    if old_args != new_args:
        return f"case function arguments {old_args} then, {new_args} now"
    return ""


def _same_function(old: Any, new: str) -> bool:
    """Same name, or two names of one function (its module's and the public face's)."""
    if old == new:
        return True
    try:
        return resolve_function(old) is resolve_function(new)
    except SweepError:
        return False
