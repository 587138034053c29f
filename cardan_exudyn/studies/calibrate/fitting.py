"""The paper's eleven cases under given parameter values, and a set's open values as an optimiser
sees them: ``u`` in ``[0, 1]^n``, each number mapped linearly or (bounds spanning decades) on a
log scale, so one step size and one tolerance fit every parameter.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cardan_exudyn.engines import run
from reference.paper import apply_parameters, case_key, paper_cases, paper_scene, parameter_set, plausible_box
from reference.scene import replace
from reference.scene.validation import SceneError

__all__ = ["FIT_ENGINES", "FIT_ACCURACY", "MATCHED_BOUNDS", "cases_named", "case_scene", "CaseModel",
           "Space", "box_space", "choice_combinations", "set_space"]

FIT_ENGINES = ("reference", "exudyn")
"""Engines a fit may use: the reference (default: independent, no step, about 0.03 s a run) or
Exudyn (``numerics.accuracy`` 1e-4, about a second a run)."""
FIT_ACCURACY = 1e-4
"""``numerics.accuracy`` of every run in a fit [-] (Exudyn's step follows it): ten times below
the paper's last digit."""
MATCHED_BOUNDS = {
    "spider_lever": (0.002, 1.0, 0.024),
    "frame_lever": (0.002, 2.0, 0.05),
    "input_eccentricity": (1e-6, 0.01, 2e-4),
}
"""The matched set's bounds and start [m] (lower, upper, start): wide on purpose, the values are
not held to plausible dimensions; searched on a log scale."""


def cases_named(keys: Sequence[str]) -> list[dict[str, Any]]:
    """The paper's cases named by ``keys`` (:func:`reference.paper.cases.case_key`), in that order."""
    by_key = {case_key(c): c for c in paper_cases()}
    missing = [k for k in keys if k not in by_key]
    if missing:
        raise ValueError(f"unknown case(s) {missing}; cases are {list(by_key)}")
    return [by_key[k] for k in keys]


def case_scene(case: Mapping[str, Any], values: Mapping[str, Any]):
    """The scene of paper ``case`` under ``values`` (as :func:`reference.paper.scenes.paper_scene`), one
    input revolution (periodic at constant speed), no time series, mean-input load solved.
    """
    plain = {k: v for k, v in values.items() if k != "torque_reading"}
    scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"], parameters=plain)
    # the accuracy sets Exudyn's step; the reference engine only compares its estimate with it
    scene = replace(scene, **{"revolutions": 1.0, "record.timeseries": False,
                              "numerics.accuracy": FIT_ACCURACY})
    if "torque_reading" in values:
        scene = apply_parameters(scene, {"torque_reading": values["torque_reading"]})
    return scene


@dataclass
class CaseModel:
    """Mean efficiency of the paper's cases under parameter values, cached by scene.

    Parameters
    ----------
    engine : {"reference", "exudyn"}
    progress : callable, optional
        Called with a line of text every ``every`` runs.
    """

    engine: str = "reference"
    progress: Callable[[str], None] | None = None
    every: int = 200

    def __post_init__(self) -> None:
        """Check the engine; start the counters and the cache."""
        if not isinstance(self.engine, str) or self.engine not in FIT_ENGINES:
            raise ValueError(f"`engine` must be one of {list(FIT_ENGINES)}, got {self.engine!r:.80}")
        self.runs = 0
        self.cache: dict[tuple, tuple[float, str, str]] = {}
        self.start = time.perf_counter()

    def run_case(self, case: Mapping[str, Any], values: Mapping[str, Any]) -> tuple[float, str, str]:
        """Mean efficiency [-] (NaN when failed), status and reason of paper ``case`` under ``values``."""
        key = (case["shaft_angle_deg"], case["speed_rpm"], tuple(sorted(values.items())))
        if key not in self.cache:
            self.cache[key] = self._run(case, values)
        return self.cache[key]

    def efficiency(self, case: Mapping[str, Any], values: Mapping[str, Any]) -> float:
        """Mean efficiency [-] of paper ``case`` under ``values``; NaN when the run failed."""
        return self.run_case(case, values)[0]

    def _run(self, case: Mapping[str, Any], values: Mapping[str, Any]) -> tuple[float, str, str]:
        """One counted run of ``case`` under ``values``; no mean-input load means a self-locking joint."""
        self.runs += 1
        if self.progress and self.runs % self.every == 0:
            self.progress(f"{self.runs} runs, {time.perf_counter() - self.start:.0f} s")
        try:
            result = run(case_scene(case, values), self.engine)
        except SceneError as exc:  # the mean-input load could not be found: the joint locks
            return float("nan"), "self_locking", str(exc)
        if not result.success or result.mean_efficiency is None:
            return float("nan"), str(getattr(result.status, "value", result.status)), result.message
        return float(result.mean_efficiency), "ok", ""


@dataclass(frozen=True)
class Space:
    """The open numbers of a fit and their map to the unit box: ``names``, ``lower``, ``upper`` [m],
    ``log`` (searched on a log scale) and ``held`` (values not searched).
    """

    names: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    log: tuple[bool, ...]
    held: tuple[tuple[str, Any], ...] = ()

    def values(self, u: Sequence[float]) -> dict[str, Any]:
        """Parameter values at ``u`` (unit box), the held ones included."""
        out = dict(self.held)
        for name, lo, hi, log, x in zip(self.names, self.lower, self.upper, self.log, u, strict=True):
            x = min(max(float(x), 0.0), 1.0)
            out[name] = (math.exp(math.log(lo) + x * (math.log(hi) - math.log(lo))) if log
                         else lo + x * (hi - lo))
        return out

    def unit(self, values: Mapping[str, float]) -> np.ndarray:
        """``u`` of ``values`` (clipped to the box)."""
        out = []
        for name, lo, hi, log in zip(self.names, self.lower, self.upper, self.log, strict=True):
            v = values[name]
            x = (math.log(v / lo) / math.log(hi / lo)) if log else (v - lo) / (hi - lo)
            out.append(min(max(x, 0.0), 1.0))
        return np.asarray(out)

    def corners(self) -> list[np.ndarray]:
        """Every corner of the box in ``u``."""
        return [np.asarray(c, dtype=float) for c in itertools.product((0.0, 1.0), repeat=len(self.names))]


def box_space(held: Mapping[str, Any] | None = None) -> tuple[Space, list[dict[str, str]]]:
    """The plausible box as a linear :class:`Space` and every combination of its discrete options."""
    box = plausible_box()
    numbers = [k for k, v in box.items() if "range" in v and k not in (held or {})]
    space = Space(tuple(numbers), tuple(box[k]["range"][0] for k in numbers),
                  tuple(box[k]["range"][1] for k in numbers), (False,) * len(numbers),
                  tuple((held or {}).items()))
    return space, choice_combinations({k: v["options"] for k, v in box.items() if "options" in v})


def choice_combinations(options: Mapping[str, Sequence[str]]) -> list[dict[str, str]]:
    """Every combination of discrete ``options`` (name -> options), in their order."""
    names = list(options)
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*options.values())]


def set_space(name: str) -> tuple[Space, list[dict[str, str]], list[float]]:
    """Set ``name``'s fit: its :class:`Space` (plausible box, linear, for ``physical``;
    :data:`MATCHED_BOUNDS`, log, for ``matched``), the discrete combinations and the start ``u``;
    ValueError for a set with nothing to fit.
    """
    entries = parameter_set(name)["values"]
    fitted = [k for k, e in entries.items() if e.get("fitted")]
    if not fitted or not parameter_set(name)["fit_cases"]:
        raise ValueError(f"parameter set {name!r} has no fitted values or no fit cases; fit "
                         "'physical' or 'matched'")
    held = {k: e["value"] for k, e in entries.items() if k not in fitted}
    if name == "matched":
        unknown = [k for k in fitted if k not in MATCHED_BOUNDS]
        if unknown:
            raise ValueError(f"no bounds for the matched set's fitted value(s) {unknown}")
        bounds = [MATCHED_BOUNDS[k] for k in fitted]
        space = Space(tuple(fitted), tuple(b[0] for b in bounds), tuple(b[1] for b in bounds),
                      (True,) * len(fitted), tuple(held.items()))
        return space, [{}], list(space.unit({k: b[2] for k, b in zip(fitted, bounds, strict=True)}))
    box = plausible_box()
    space = Space(tuple(fitted), tuple(box[k]["range"][0] for k in fitted),
                  tuple(box[k]["range"][1] for k in fitted), (False,) * len(fitted),
                  tuple((k, v) for k, v in held.items() if "options" not in box.get(k, {})))
    options = {k: box[k]["options"] for k in held if "options" in box.get(k, {})}
    return space, choice_combinations(options), [0.5] * len(fitted)
