"""The one engine dispatch: every engine runs a :class:`reference.scene.scene.Scene` with its options
into a :class:`reference.results.result.Result` of the same columns and summary fields.

Engines import on first use, so a missing optional engine (MuJoCo) costs nothing until asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import Any

from cardan_exudyn.interrupts import deferred_signals
from reference.results.result import Result
from reference.results.summary import OptionsError
from reference.scene.scene import Scene
from reference.scene.validation import require_scene


@dataclass(frozen=True)
class Engine:
    """An entry of :data:`ENGINES`: ``module`` has ``run(scene, options) -> Result``, ``options`` is
    ``"module:Class"``, ``batch`` a module with ``check_scenes``, ``batch_key``, ``run_batch`` ("": none)."""

    name: str
    module: str
    options: str
    description: str
    batch: str = ""

    @property
    def options_name(self) -> str:
        """The options class's name (what :func:`engine_of` matches)."""
        return self.options.rpartition(":")[2]


ENGINES: dict[str, Engine] = {  # the one dispatch table
    "exudyn": Engine("exudyn", "cardan_exudyn.model.accuracy", "cardan_exudyn.model.options:ExudynOptions",
                     "Exudyn multibody model, generalized-alpha, friction from the joint reactions"),
    "reference": Engine("reference", "reference.engine.solve", "reference.engine.options:ReferenceOptions",
                        "independent numpy/scipy engine: closed-form or dual-number kinematics, "
                        "minimal-coordinate dynamics, adaptive work quadrature",
                        batch="reference.engine.batch.solve"),
    "mujoco": Engine("mujoco", "cardan_exudyn.mujoco.engine", "cardan_exudyn.mujoco.options:MujocoOptions",
                     "MuJoCo (optional extra): frictionless scenes with a constant load only"),
}


__all__ = ["Engine", "ENGINES", "DEFAULT_ENGINE", "EngineUnavailable", "options_class", "make_options",
           "get_engine", "engine_of", "resolve", "run", "has_batch", "batch_key", "run_batch"]


class EngineUnavailable(ValueError):
    """The engine is unknown, not installed, or cannot run this kind of scene."""


def _entry(name: str) -> Engine:
    """The entry of engine ``name``; ``TypeError`` for a non-string, :class:`EngineUnavailable`
    for an unknown name."""
    if not isinstance(name, str):
        raise TypeError(f"`engine` must be the name of an engine (a string, one of {sorted(ENGINES)}), "
                        f"got {type(name).__name__} {name!r:.80}")
    if name not in ENGINES:
        raise EngineUnavailable(f"`engine` must be one of {sorted(ENGINES)}, got {name!r}")
    return ENGINES[name]


def _import(name: str, module: str) -> Any:
    """Import an engine's ``module``; a missing dependency makes engine ``name`` unavailable."""
    try:
        # a Ctrl-C inside a compiled module's initialisation comes back as an ImportError
        # (Exudyn: "initialization failed"); held back, it arrives after the import as itself
        with deferred_signals():
            return importlib.import_module(module)
    except ImportError as exc:
        raise EngineUnavailable(f"engine {name!r} is not available: {exc}") from None


def options_class(engine: str) -> type:
    """The options class of ``engine`` (a frozen dataclass validated on construction);
    :class:`EngineUnavailable` for an unknown engine or one whose options module does not import."""
    module, _, cls = _entry(engine).options.partition(":")
    return getattr(_import(engine, module), cls)


def make_options(engine: str, **values: Any) -> Any:
    """Options of ``engine`` from keyword values.

    Parameters
    ----------
    engine : str
        A key of :data:`ENGINES`.
    **values
        Fields of its options class.

    Raises
    ------
    EngineUnavailable
        An unknown or uninstalled engine.
    OptionsError
        An unknown field name, or a value its class refuses.
    """
    cls = options_class(engine)
    unknown = sorted(set(values) - set(cls.__dataclass_fields__))
    if unknown:
        raise OptionsError(f"unknown option(s) {unknown} for engine {engine!r}; "
                           f"known: {sorted(cls.__dataclass_fields__)}")
    return cls(**values)


def get_engine(name: str) -> Callable[..., Result]:
    """The function ``run(scene, options=None) -> Result`` of engine ``name``."""
    return _import(name, _entry(name).module).run


def engine_of(options: Any) -> str:
    """The engine whose options class ``options`` is an instance of (matched by class name, so the
    engine's module need not import); :class:`OptionsError` if none."""
    for name, entry in ENGINES.items():
        if type(options).__name__ == entry.options_name:
            return name
    raise OptionsError(f"`options` must be the options of an engine in {sorted(ENGINES)}, "
                       f"got {type(options).__name__}")


DEFAULT_ENGINE = "exudyn"
"""The engine of a run that names none and gives no options."""


def resolve(engine: str | None = None, options: Any = None, **option_values: Any) -> tuple[str, Any]:
    """``(engine, options)`` from what a caller gave to :func:`run` (``options`` or their keywords)."""
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

    Returns
    -------
    Result
        A failed run returns a result with its status and reason; it does not raise.

    Raises
    ------
    TypeError
        ``scene`` is not a Scene, or ``engine`` not a string.
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


def has_batch(engine: str) -> bool:
    """Whether ``engine`` has a batched pass."""
    return bool(_entry(engine).batch)


def batch_key(scene: Scene, engine: str | None = None) -> Hashable | None:
    """The key grouping ``scene`` in :func:`run_batch` for ``engine``; None: the scene runs on its own."""
    require_scene(scene)
    engine = DEFAULT_ENGINE if engine is None else engine
    entry = _entry(engine)
    return _import(engine, entry.batch).batch_key(scene) if entry.batch else None


def run_batch(scenes: Sequence[Scene], engine: str | None = None, options: Any = None,
              **option_values: Any) -> list[Result]:
    """Run many scenes with one engine: one :class:`Result` per scene, in order, each equal to
    ``run(scene, engine, options)`` to rounding or to the quadrature tolerance.

    Scenes of equal :func:`batch_key` run in one pass of the engine's batched evaluation; the others
    run one at a time.

    Parameters
    ----------
    scenes : sequence of Scene
    engine, options, option_values
        As in :func:`run`.

    Raises
    ------
    TypeError
        ``scenes`` is not a sequence, or one of them not a Scene (the message names its index).
    EngineUnavailable, OptionsError
        As in :func:`run`; raised before any scene runs.
    SceneError
        A scene the batched pass refuses (a table beyond the step limit), named by its index;
        raised before any scene runs.
    """
    if isinstance(scenes, (Scene, str, bytes)) or not isinstance(scenes, Sequence):
        raise TypeError(f"`scenes` must be a sequence of Scene, got {type(scenes).__name__} {scenes!r:.80}")
    for i, scene in enumerate(scenes):
        require_scene(scene, f"scenes[{i}]")
    engine, options = resolve(engine, options, **option_values)
    entry = _entry(engine)
    run_function = get_engine(engine)
    module = _import(engine, entry.batch) if entry.batch else None
    if module is not None:  # every scene, before any group runs, named by its index in `scenes`
        module.check_scenes(scenes, options)
    groups: dict[Hashable, list[int]] = {}
    for i, scene in enumerate(scenes):
        key = module.batch_key(scene) if module is not None else None
        groups.setdefault(("batch", key) if key is not None else ("single", i), []).append(i)
    results: list[Result | None] = [None] * len(scenes)
    for (kind, _), indices in groups.items():
        members = [scenes[i] for i in indices]
        try:
            done = (module.run_batch(members, options) if kind == "batch"
                    else [run_function(members[0], options)])
        except NotImplementedError as exc:
            raise EngineUnavailable(f"engine {engine!r} cannot run scene {members[0].name!r}: "
                                    f"{exc}") from None
        for i, result in zip(indices, done, strict=True):
            results[i] = result
    return results
