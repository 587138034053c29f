"""What ``cardan bench`` runs: its default scenes and every engine configuration (Exudyn settings,
couplings, projections, node types; MuJoCo on frictionless ideal scenes; the reference's
tolerances and samples) on its ladder of steps per revolution.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from dataclasses import replace as dc_replace
from typing import Any

from cardan_exudyn import engines
from cardan_exudyn.model.options import NODE_TYPES, ExudynOptions
from reference.engine import ReferenceOptions
from reference.paper import named_scene, paper_errors
from reference.results.result import Result
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["SCENES", "MOUNTING_ERROR_SCENES", "ENGINE_NAMES", "EXUDYN_DEFAULT", "EXUDYN_TUNED",
           "FULL_LADDER", "QUICK_LADDER", "QUICK_FULL_LADDER", "BenchError", "Progress", "quiet",
           "Config", "bench_scene", "fixed_scenes", "frozen_changes", "exudyn_settings",
           "exudyn_configs", "mujoco_configs", "reference_configs", "configurations",
           "simulated_time"]

SCENES = {
    "frictionless-10deg": "paper-literal-10deg-frictionless",
    "frictionless-35deg": "paper-literal-35deg-frictionless",
    "frictionless-errors-10deg": "paper-physical-10deg-frictionless",
    "friction-10deg": "paper-literal-10deg",
    "friction-35deg": "paper-literal-35deg",
    "friction-errors-10deg": "paper-physical-10deg",
}
"""The default scene set: key -> named scene (all at 2000 rpm, the paper's masses, load and
gravity). The ``-errors-`` scenes get Section 4.2's mounting tolerances on top
(:data:`MOUNTING_ERROR_SCENES`)."""

MOUNTING_ERROR_SCENES = frozenset({"frictionless-errors-10deg", "friction-errors-10deg"})
"""Scenes with the paper's Section 4.2 tolerances (:func:`reference.paper.scenes.paper_errors`: offsets
``a1 = a2 = a3 = 0.5 mm``, twist errors ``alpha1 = alpha2 = alpha3 = 6e-3 deg``), so that the
cylindrical pairs slide. They use the physical parameter set: under the literal set these
offsets make the reference engine report self-locking from the first instant."""

ENGINE_NAMES = ("exudyn", "mujoco", "reference")
"""The engines the bench compares (keys of :data:`cardan_exudyn.engines.ENGINES`), in its order."""

# "tuned": modified Newton with one Jacobian per step and a relative Newton tolerance of 1e-8
# (the speed-ratio and efficiency errors do not change: tests/test_bench.py); "default": the
# engine's defaults (full Newton, 1e-10). Both without the engine's own error estimate: a given
# step with friction would otherwise add a companion run at twice the step (half again the cost,
# friction runs only), and the bench measures every error against the reference itself.
EXUDYN_DEFAULT = ExudynOptions(error_estimate=False)
EXUDYN_TUNED = ExudynOptions(modified_newton=True, jacobian_every_step=True,
                             newton_relative_tolerance=1e-8, error_estimate=False)

# Steps (Exudyn, MuJoCo) or table samples (reference) per input revolution. Exudyn's full ladder
# is denser between 200 and 800, where the paper's friction scenes reach an efficiency error of
# 1e-4.
FULL_LADDER = {"exudyn": (25, 50, 100, 200, 300, 400, 600, 800, 1600),
               "mujoco": (20, 25, 30, 40, 60, 100, 200), "reference": (36, 360)}
QUICK_LADDER = {"exudyn": (50, 200, 800), "mujoco": (25, 60), "reference": (36,)}
# Configurations that run the whole quick ladder (the others its first two steps): the tuned
# Newton settings, against which every other configuration's cost reads, and the one-solve
# coupling, which needs the finest step for an efficiency error of 1e-4 at 35 deg.
QUICK_FULL_LADDER = ("exudyn tuned", "exudyn tuned extrapolated")

Progress = Callable[[str], None]
"""A progress callback: called with one line of text per finished piece of work."""


def quiet(text: str) -> None:
    """The progress callback that shows nothing."""


class BenchError(ValueError):
    """Bad bench input (unknown scene key or engine, bad repeats)."""


def bench_scene(key: str) -> Scene:
    """The scene of bench key ``key`` (of :data:`SCENES`); BenchError for an unknown key."""
    if key not in SCENES:
        raise BenchError(f"`scene` must be one of {list(SCENES)}, got {key!r}")
    scene = named_scene(SCENES[key])
    if key in MOUNTING_ERROR_SCENES:
        scene = replace(scene, **paper_errors(), name=scene.name + "-errors",
                        description=scene.description + ", Section 4.2 tolerances")
    return scene


def fixed_scenes(keys: Iterable[str] | None = None) -> dict[str, Scene]:
    """The default scenes named by ``keys`` (of :data:`SCENES`; None: all), in that order; BenchError
    for an unknown key.
    """
    keys = list(SCENES) if keys is None else list(keys)
    unknown = [k for k in keys if k not in SCENES]
    if unknown:
        raise BenchError(f"`--scenes` must be among {list(SCENES)}, got {unknown}")
    return {key: bench_scene(key) for key in dict.fromkeys(keys)}


def frozen_changes(changes: Mapping[str, Any] | Iterable[tuple[str, Any]]) -> tuple[tuple[str, Any], ...]:
    """Scene changes as a sorted tuple of ``(dotted path, value)`` pairs (hashable)."""
    items = changes.items() if isinstance(changes, Mapping) else changes
    return tuple(sorted((str(k), v) for k, v in items))


@dataclass(frozen=True)
class Config:
    """One engine configuration at one resolution.

    ``engine``, ``label`` (its name in tables and plots), ``steps`` (steps or, for the reference,
    table samples per input revolution), ``options`` (None: the engine's defaults), ``changes``
    (scene changes for :func:`reference.scene.mapping.replace`, stored as a sorted tuple of pairs)
    and ``sets_step`` (``steps`` sets the scene's step; else the options hold the resolution).
    """

    engine: str
    label: str
    steps: int
    options: Any = None
    changes: Any = field(default=())
    sets_step: bool = True

    def __post_init__(self) -> None:
        """Store ``changes`` as a sorted tuple of pairs (hashable)."""
        object.__setattr__(self, "changes", frozen_changes(self.changes))

    @property
    def coupling(self) -> str | None:
        """The friction coupling the configuration switches the scene to (None: the scene's)."""
        return dict(self.changes).get("friction.coupling")

    def scene(self, base: Scene) -> Scene:
        """``base`` at this configuration's step, with its scene changes."""
        changes = dict(self.changes)
        if self.sets_step:
            changes["numerics.dt"] = 2.0 * math.pi / base.drive.max_speed() / self.steps
        return replace(base, **changes) if changes else base

    def run(self, scene: Scene) -> Result:
        """Run ``scene`` (made by :meth:`scene`) with this configuration's engine and options."""
        return engines.run(scene, self.engine, self.options)

    def describe(self) -> dict[str, Any]:
        """The configuration as a record: engine, label, steps, coupling, scene changes, options."""
        options = self.options
        if options is not None:
            options = {name: getattr(options, name) for name in options.__dataclass_fields__}
        return {"engine": self.engine, "config": self.label, "steps_per_revolution": self.steps,
                "coupling": self.coupling,
                "scene_changes": "; ".join(f"{k}={v}" for k, v in self.changes),
                "options": options}


Setting = tuple[str, ExudynOptions, dict[str, Any]]
"""An Exudyn configuration without its step: ``(label, options, scene changes)``."""


def exudyn_settings(friction: bool, quick: bool) -> list[Setting]:
    """``(label, options, scene changes)`` of the Exudyn configurations for a scene with or without
    ``friction`` (``quick``: no other node types). With friction the coupling is always given, so a
    label means one scheme whatever the scene's default.
    """
    converged = {"friction.coupling": "converged"} if friction else {}
    out: list[Setting] = [("exudyn default", EXUDYN_DEFAULT, converged),
                          ("exudyn tuned", EXUDYN_TUNED, converged)]
    projected = dc_replace(EXUDYN_TUNED, velocity_projection=True)
    if friction:
        out += [(f"exudyn tuned {c}", EXUDYN_TUNED, {"friction.coupling": c})
                for c in ("extrapolated", "lagged")]
    else:
        out += [("exudyn tuned + projection", projected, {}),
                ("exudyn tuned + projection + richardson", projected, {"numerics.richardson": True})]
    if not quick:
        out += [(f"exudyn tuned {node}", dc_replace(EXUDYN_TUNED, node_type=node), converged)
                for node in NODE_TYPES[1:]]
    return out


def exudyn_configs(friction: bool, quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """Every Exudyn setting on ``ladder`` (engine -> steps per revolution); ``quick`` runs only
    :data:`QUICK_FULL_LADDER` on the whole ladder, the others on its first two steps.
    """
    out = []
    for label, options, changes in exudyn_settings(friction, quick):
        steps = ladder["exudyn"]
        if quick and label not in QUICK_FULL_LADDER:
            steps = steps[:2]
        out += [Config("exudyn", label, n, options, changes) for n in steps]
    return out


def mujoco_configs(quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """MuJoCo, RK4, constraint time constants of 10 and (not ``quick``) 20 steps on ``ladder["mujoco"]``;
    none without the optional extra.
    """
    out = []
    for tc in ((10.0,) if quick else (10.0, 20.0)):
        try:
            options = engines.make_options("mujoco", timeconst_steps=tc)
        except engines.EngineUnavailable:  # MuJoCo is an optional extra: its rows are left out
            return []
        label = f"mujoco RK4 tc {tc:g} dt" + (" (recommended)" if tc == 20.0 else "")
        out += [Config("mujoco", label, n, options) for n in ladder["mujoco"]]
    return out


def reference_configs(quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """The reference at quadrature tolerances 1e-9, 1e-6, 1e-4 (``quick``: 1e-6), ``ladder["reference"]``."""
    return [Config("reference", f"reference rtol {rtol:g}", n,
                   ReferenceOptions(samples_per_revolution=n, quadrature_rtol=rtol), sets_step=False)
            for rtol in ((1e-6,) if quick else (1e-9, 1e-6, 1e-4)) for n in ladder["reference"]]


def configurations(scene: Scene, quick: bool = False,
                   engines: Iterable[str] = ENGINE_NAMES) -> list[Config]:
    """Every configuration benchmarked on ``scene`` for ``engines`` (``quick``: short ladders, fewer
    settings). MuJoCo runs frictionless scenes without mounting errors only: its joints are ideal and
    its friction not proportional to the reactions.
    """
    engines = set(engines)
    ladder = QUICK_LADDER if quick else FULL_LADDER
    friction = scene.has_friction
    out: list[Config] = []
    if "exudyn" in engines:
        out += exudyn_configs(friction, quick, ladder)
    if "mujoco" in engines and not friction and not scene.joint.errors.any:
        out += mujoco_configs(quick, ladder)
    if "reference" in engines:
        out += reference_configs(quick, ladder)
    return out


def simulated_time(scene: Scene) -> float:
    """The time the scene's revolutions take at the drive's highest speed [s]."""
    return 2.0 * math.pi * scene.revolutions / scene.drive.max_speed()
