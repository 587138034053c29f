"""A sweep's case function by name (what workers receive), checked to import back to the same
callable with JSON arguments.
"""

from __future__ import annotations

import functools
import importlib
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.sweep.checks import SweepError
from reference.scene.scene import Scene

__all__ = ["DEFAULT_FUNCTION", "CASE_ARGUMENTS", "CaseFunction", "function_args", "function_name",
           "resolve_function"]

# the public face's name, not the defining module's: it survives moves inside the package
DEFAULT_FUNCTION = "cardan_exudyn.sweep:summary_outputs"
CASE_ARGUMENTS = ("scene", "engine")
"""Arguments a case function always receives; ``function_args`` must not set them."""


@dataclass(frozen=True)
class CaseFunction:
    """A case function by name, with keyword arguments: ``name(scene, engine, **args)``.

    Like :func:`functools.partial` of an importable function, but a name and plain data, so it
    pickles anywhere the package is installed.

    Attributes
    ----------
    name : str
        ``"module:qualname"`` of a top-level callable ``fn(scene, engine, **args) -> dict``.
    args : dict
        Keyword arguments (JSON-able values).
    """

    name: str = DEFAULT_FUNCTION
    args: Mapping[str, Any] = field(default_factory=dict)

    def __call__(self, scene: Scene, engine: str) -> Any:
        """``name(scene, engine, **args)``: the case's outputs."""
        return resolve_function(self.name)(scene, engine, **self.args)


def function_args(args: Any) -> dict[str, Any]:
    """``function_args`` checked: a table of keyword names to JSON-able values; SweepError for
    anything else or a name of :data:`CASE_ARGUMENTS`.
    """
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


def function_name(function: Any) -> str:
    """``"module:qualname"`` of ``function`` (a name or a top-level callable), checked to import back
    to the same object (workers import it); SweepError otherwise.
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
