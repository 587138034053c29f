"""The one engine dispatch: every engine takes a :class:`reference.scene.scene.Scene` and options, and
returns a :class:`reference.results.result.Result` with the same columns and summary fields.

Like scipy's ``solve_ivp(method=...)`` over its ``METHODS`` table: callers name an engine (or
pass options of an engine's class) and never import an engine module themselves. Engines are
imported on first use, so a missing optional engine (MuJoCo) costs nothing until asked for.

Many scenes at once: :func:`run_batch`. An engine with a batched pass (the reference engine's
:mod:`reference.engine.batch.solve`) runs the scenes of equal :func:`batch_key` together; the
others, and scenes whose key is None, run one at a time as :func:`run` would.
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
    """An entry of :data:`ENGINES`.

    Attributes
    ----------
    name : str
        The key in :data:`ENGINES`.
    module : str
        The module whose ``run(scene, options) -> Result`` runs a scene (imported on first use).
    options : str
        Its options class, as ``"module:Class"``.
    description : str
        One line for listings.
    batch : str
        Module with ``check_scenes``, ``batch_key(scene)`` and ``run_batch(scenes, options)``;
        "": no batched pass.
    """

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
    """The options class of ``engine`` (a frozen dataclass validated on construction).

    Raises
    ------
    EngineUnavailable
        An unknown engine, or one whose options module does not import.
    """
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

    Returns
    -------
    object
        An instance of :func:`options_class` ``(engine)``.

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
    """The run function ``run(scene, options=None) -> Result`` of the named engine.

    Raises
    ------
    EngineUnavailable
        An unknown engine, or one that is not installed.
    """
    return _import(name, _entry(name).module).run


def engine_of(options: Any) -> str:
    """The engine whose options class ``options`` is an instance of (matched by class name, so
    that the engine's module need not be imported).

    Raises
    ------
    OptionsError
        ``options`` of no engine's class.
    """
    for name, entry in ENGINES.items():
        if type(options).__name__ == entry.options_name:
            return name
    raise OptionsError(f"`options` must be the options of an engine in {sorted(ENGINES)}, "
                       f"got {type(options).__name__}")


DEFAULT_ENGINE = "exudyn"
"""The engine of a run that names none and gives no options."""


def resolve(engine: str | None = None, options: Any = None, **option_values: Any) -> tuple[str, Any]:
    """The engine and an instance of its options from what a caller gave (see :func:`run`).

    Parameters
    ----------
    engine : str, optional
        A key of :data:`ENGINES`; by default the engine of ``options``, else :data:`DEFAULT_ENGINE`.
    options : optional
        An instance of the engine's options class.
    **option_values
        Or the fields of the options, as keywords.

    Returns
    -------
    engine : str
    options : object
        An instance of the engine's options class.

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
        The scene to run.
    engine : str, optional
        A key of :data:`ENGINES`; by default the engine of ``options``, else ``"exudyn"``.
    options : optional
        An instance of the engine's options class (``ExudynOptions``, ``ReferenceOptions``,
        ``MujocoOptions``); or give its fields as keywords (``node_type="EP"``).
    **option_values
        The options' fields, when ``options`` is not given.

    Returns
    -------
    Result
        The time table (built when first read) and the summary; a run that failed returns a
        result with its status and reason, it does not raise.

    Raises
    ------
    TypeError
        ``scene`` is not a Scene (:class:`reference.scene.validation.SceneTypeError`), or ``engine``
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


def has_batch(engine: str) -> bool:
    """Whether ``engine`` has a batched pass (:func:`run_batch` then runs scenes together)."""
    return bool(_entry(engine).batch)


def batch_key(scene: Scene, engine: str | None = None) -> Hashable | None:
    """The key that groups scenes in :func:`run_batch`.

    Parameters
    ----------
    scene : Scene
        The scene.
    engine : str, optional
        A key of :data:`ENGINES` (default :data:`DEFAULT_ENGINE`).

    Returns
    -------
    hashable or None
        Scenes of one engine with equal keys run together; None: the scene runs on its own
        (always None for an engine without a batched pass).

    Raises
    ------
    TypeError
        ``scene`` is not a Scene, or ``engine`` not a string.
    EngineUnavailable
        Unknown or uninstalled engine.
    """
    require_scene(scene)
    engine = DEFAULT_ENGINE if engine is None else engine
    entry = _entry(engine)
    return _import(engine, entry.batch).batch_key(scene) if entry.batch else None


def run_batch(scenes: Sequence[Scene], engine: str | None = None, options: Any = None,
              **option_values: Any) -> list[Result]:
    """Run many scenes with one engine: one :class:`Result` per scene, in order, each equal to
    ``run(scene, engine, options)`` (to rounding, or to the quadrature tolerance where the batched
    pass adapts differently: :mod:`reference.engine.batch.solve`).

    Scenes of equal :func:`batch_key` run in one pass of the engine's batched evaluation (a scene
    that locks or fails gets its own failed Result); the others, and every scene of an engine
    without a batched pass, run one at a time.

    Parameters
    ----------
    scenes : sequence of Scene
        The scenes, in the order of the results.
    engine, options, option_values
        As in :func:`run`.

    Returns
    -------
    list of Result
        One per scene, in order.

    Raises
    ------
    TypeError
        ``scenes`` is not a sequence, or one of them not a Scene (the message names its index).
    EngineUnavailable, OptionsError
        As in :func:`run`; raised before any scene runs.
    SceneError
        A scene the engine's batched pass refuses before running (a table beyond the step
        limit), named by its index in ``scenes``; raised before any scene runs.
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
