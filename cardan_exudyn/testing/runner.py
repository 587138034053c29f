"""A runner that runs each (scene, engine, options) once and hands out copies of the result.

The key is by value (scenes and options are frozen dataclasses); options are resolved first, so
no options, the default options and the same values as keywords are one key.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cardan_exudyn.engines import resolve
from cardan_exudyn.engines import run as run_engine
from cardan_exudyn.model.error_estimate import ErrorEstimate, error_estimate
from reference.results.result import Result
from reference.results.summary import Status
from reference.scene.scene import Scene

__all__ = ["RunRecord", "CachingRunner"]


@dataclass
class RunRecord:
    """One engine run of a session: scene name, revolutions, engine, step [s], status, wall time [s]
    and ``reused`` (times handed out again from the cache).
    """

    scene: str
    revolutions: float
    engine: str
    dt: float | None
    status: Status
    mean_efficiency: float | None
    wall_time_s: float
    reused: int = 0


class CachingRunner:
    """``runner(scene, engine=None, options=None, **option_values) -> Result``, each distinct run
    computed once.

    Every call returns its own deep copy, so a test may change it. Failed runs (status not ``ok``)
    are cached; exceptions are not.

    Parameters
    ----------
    run : callable, optional
        ``run(scene, engine, options) -> Result``; default :func:`cardan_exudyn.engines.run`.
    cache : bool
        False runs the engine on every call (the records still list each run).
    """

    def __init__(self, run: Callable[..., Result] | None = None, cache: bool = True) -> None:
        self._run = run or run_engine
        self.cache = cache
        self._results: dict[tuple[Scene, str, Any], Result] = {}
        self._records: dict[tuple[Scene, str, Any], RunRecord] = {}
        self._uncached: list[RunRecord] = []

    def __call__(self, scene: Scene, engine: str | None = None, options: Any = None,
                 **option_values: Any) -> Result:
        """Run ``scene`` with ``engine`` (default ``"exudyn"``, or the engine of ``options``), or return a
        copy of an identical earlier run; raises what :func:`cardan_exudyn.engines.run` raises.
        """
        key = self.key(scene, engine, options, **option_values)
        if self.cache and key in self._results:
            self._records[key].reused += 1
            return copy.deepcopy(self._results[key])
        result = self._run(*key)
        record = RunRecord(scene.name, scene.revolutions, key[1], result.summary.dt, result.status,
                           result.mean_efficiency, result.summary.wall_time_s)
        if self.cache:
            self._results[key] = result
            self._records[key] = record
            return copy.deepcopy(result)
        self._uncached.append(record)
        return result

    @staticmethod
    def key(scene: Scene, engine: str | None = None, options: Any = None,
            **option_values: Any) -> tuple[Scene, str, Any]:
        """The cache key ``(scene, engine, options)``, engine and options resolved (``options`` or its fields
        as keywords). Raises TypeError for a non-Scene, OptionsError for both or for another engine's options.
        """
        if not isinstance(scene, Scene):
            raise TypeError(f"`scene` must be a reference.scene.scene.Scene, got {type(scene).__name__}")
        engine, options = resolve(engine, options, **option_values)
        return scene, engine, options

    def error_estimate(self, result: Result) -> ErrorEstimate | None:
        """:func:`cardan_exudyn.model.error_estimate.error_estimate`, this runner running the half step."""
        return error_estimate(result, run=self)

    @property
    def records(self) -> list[RunRecord]:
        """Every engine run so far, in order."""
        return [*self._records.values(), *self._uncached]

    @property
    def runs(self) -> int:
        """Engine runs computed so far."""
        return len(self._records) + len(self._uncached)

    @property
    def reused(self) -> int:
        """Calls answered from the cache so far."""
        return sum(record.reused for record in self._records.values())
