"""The one engine dispatch: every engine takes a :class:`reference.scene.Scene` and options, and
returns a :class:`reference.schema.Result` with the same columns and summary fields.

Like scipy's ``solve_ivp(method=...)`` over its ``METHODS`` table: callers name an engine (or
pass options of an engine's class) and never import an engine module themselves. Engines are
imported on first use, so a missing optional engine (MuJoCo) costs nothing until asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from reference.scene import Scene
from reference.schema import OptionsError, Result
from reference.validation import require_scene


@dataclass(frozen=True)
class Engine:
    """An entry of :data:`ENGINES`: the module whose ``run(scene, options)`` runs a scene, and
    its options class as ``"module:Class"``."""

    name: str
    module: str
    options: str
    description: str

    @property
    def options_name(self) -> str:
        return self.options.rpartition(":")[2]


ENGINES: dict[str, Engine] = {
    "exudyn": Engine("exudyn", "cardan_exudyn.model.solve", "cardan_exudyn.model.options:ExudynOptions",
                     "Exudyn multibody model, generalized-alpha, friction from the joint reactions"),
    "reference": Engine("reference", "reference.engine", "reference.engine:ReferenceOptions",
                        "independent numpy/scipy engine: closed-form or dual-number kinematics, "
                        "minimal-coordinate dynamics, adaptive work quadrature"),
    "mujoco": Engine("mujoco", "cardan_exudyn.mujoco_engine", "cardan_exudyn.mujoco_engine:MujocoOptions",
                     "MuJoCo (optional extra): frictionless scenes with a constant load only"),
}


class EngineUnavailable(ValueError):
    """The engine is unknown, not installed, or cannot run this kind of scene."""


def _entry(name: str) -> Engine:
    if not isinstance(name, str):
        raise TypeError(f"`engine` must be the name of an engine (a string, one of {sorted(ENGINES)}), "
                        f"got {type(name).__name__} {name!r:.80}")
    if name not in ENGINES:
        raise EngineUnavailable(f"`engine` must be one of {sorted(ENGINES)}, got {name!r}")
    return ENGINES[name]


def _import(name: str, module: str) -> Any:
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise EngineUnavailable(f"engine {name!r} is not available: {exc}") from None


def options_class(engine: str) -> type:
    """The options class of ``engine`` (a frozen dataclass validated on construction)."""
    module, _, cls = _entry(engine).options.partition(":")
    return getattr(_import(engine, module), cls)


def make_options(engine: str, **values: Any) -> Any:
    """Options of ``engine`` from keyword values; unknown names raise :class:`OptionsError`."""
    cls = options_class(engine)
    unknown = sorted(set(values) - set(cls.__dataclass_fields__))
    if unknown:
        raise OptionsError(f"unknown option(s) {unknown} for engine {engine!r}; "
                           f"known: {sorted(cls.__dataclass_fields__)}")
    return cls(**values)


def get_engine(name: str) -> Callable[..., Result]:
    """The run function ``run(scene, options=None) -> Result`` of the named engine."""
    return _import(name, _entry(name).module).run


def engine_of(options: Any) -> str:
    """The engine whose options class ``options`` is an instance of."""
    for name, entry in ENGINES.items():
        if type(options).__name__ == entry.options_name:
            return name
    raise OptionsError(f"`options` must be the options of an engine in {sorted(ENGINES)}, "
                       f"got {type(options).__name__}")


DEFAULT_ENGINE = "exudyn"


def resolve(engine: str | None = None, options: Any = None, **option_values: Any) -> tuple[str, Any]:
    """The engine and an instance of its options from what a caller gave (see :func:`run`).

    Raises
    ------
    EngineUnavailable
        An unknown or uninstalled engine.
    OptionsError
        Both ``options`` and option keywords, unknown or out-of-range keywords, or options of
        another engine's class.
    """
    if options is not None and option_values:
        raise OptionsError("give `options` or option keywords, not both")
    if engine is None:
        engine = engine_of(options) if options is not None else DEFAULT_ENGINE
    if options is None:
        return engine, make_options(engine, **option_values)
    if engine_of(options) != engine:
        raise OptionsError(f"`options` are {type(options).__name__}, not the options of "
                           f"engine {engine!r}")
    return engine, options


def run(scene: Scene, engine: str | None = None, options: Any = None, **option_values: Any) -> Result:
    """Run ``scene`` with an engine.

    Parameters
    ----------
    scene : Scene
    engine : str, optional
        A key of :data:`ENGINES`; by default the engine of ``options``, else ``"exudyn"``.
    options : optional
        An instance of the engine's options class (``ExudynOptions``, ``ReferenceOptions``,
        ``MujocoOptions``); or give its fields as keywords (``node_type="EP"``).

    Raises
    ------
    TypeError
        ``scene`` is not a Scene (:class:`reference.validation.SceneTypeError`), or ``engine``
        not a string.
    EngineUnavailable
        Unknown or uninstalled engine, or a scene the engine cannot express.
    OptionsError
        Options of another engine's class, unknown or out-of-range option values.
    """
    require_scene(scene)
    engine, options = resolve(engine, options, **option_values)
    run_function = get_engine(engine)
    try:
        return run_function(scene, options)
    except NotImplementedError as exc:
        raise EngineUnavailable(f"engine {engine!r} cannot run scene {scene.name!r}: {exc}") from None
