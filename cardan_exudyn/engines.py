"""Engine registry: every engine takes a :class:`reference.scene.Scene` and returns a
:class:`reference.schema.Result` with the same columns and summary keys."""

from __future__ import annotations

import importlib
from collections.abc import Callable

from reference.scene import Scene
from reference.schema import Result

# name -> "module:function"; imported on first use so that a missing optional engine costs nothing
ENGINES = {
    "exudyn": "cardan_exudyn.engine:run",
    "reference": "reference.engine:run",
    "mujoco": "cardan_exudyn.mujoco_engine:run",  # optional extra; frictionless scenes only
}


class EngineUnavailable(ValueError):
    """The engine is unknown, not installed, or cannot run this kind of scene."""


def get_engine(name: str) -> Callable[[Scene], Result]:
    if name not in ENGINES:
        raise EngineUnavailable(f"`--engine` must be one of {sorted(ENGINES)}, got {name!r}")
    module, func = ENGINES[name].split(":")
    try:
        return getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError) as exc:
        raise EngineUnavailable(f"engine {name!r} is not available: {exc}") from None


def run_scene(scene: Scene, engine: str = "exudyn") -> Result:
    """Run ``scene`` with the named engine."""
    run = get_engine(engine)
    try:
        return run(scene)
    except NotImplementedError as exc:
        raise EngineUnavailable(f"engine {engine!r} cannot run scene {scene.name!r}: {exc}") from None
