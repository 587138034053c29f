"""The campaign's model runs: one recording's measured drive and load on the joint with given parameter
values and input changes, run once (journal), many at a time on all cores.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import multiprocessing
import signal
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

from cardan_exudyn.engines import run
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.sweep.executors import connect
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from rigdata.campaign.journal import Journal, Outcome
from rigdata.campaign.prepare import Prepared
from rigdata.campaign.spec import Parameter, with_values
from rigdata.model import measured_scene

__all__ = ["ModelRun", "Outcome", "Evaluator", "model_pool", "run_key"]


@dataclass(frozen=True)
class ModelRun:
    """One model run asked for.

    Attributes
    ----------
    recording : int
        The recording's index in the campaign.
    engine : str
    values : tuple of float
        The calibrated parameters' values, in the campaign's order.
    changes : tuple of (str, float)
        Other scene keys set to a value (the stated inputs' perturbations).
    load_offset : float
        Added to the measured load [N m].
    phase_shift : float
        Added to the input yoke phase [rad].
    """

    recording: int
    engine: str
    values: tuple[float, ...]
    changes: tuple[tuple[str, float], ...] = ()
    load_offset: float = 0.0
    phase_shift: float = 0.0



def run_scene(scene: Scene, engine: str) -> Outcome:
    """Run ``scene`` on ``engine``; a worker's task (module level, so it pickles)."""
    start = time.perf_counter()
    summary = run(scene, engine).summary
    eta = summary.mean_efficiency
    return Outcome(str(summary.status), summary.reason, None if eta is None else float(eta),
                   summary.efficiency_error_estimate, time.perf_counter() - start)


def run_key(scene: Scene, engine: str) -> str:
    """The journal's key of ``scene`` on ``engine``: SHA-256 of the whole scene (joint, parameters,
    measured drive and load, numerics), so a run is reused only for exactly the same model.
    """
    text = json.dumps([engine, to_jsonable(scene_to_dict(scene))], sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


@contextlib.contextmanager
def model_pool(workers: int, scheduler: Any = None) -> Iterator[Any]:
    """Where the campaign's runs go: a Dask client for ``scheduler`` (an address or a client, as for
    sweeps), else ``workers`` spawned processes, else (``workers <= 1``) None, this process. Each has
    ``submit(function, *args)`` returning a future with ``result()``.
    """
    if scheduler is not None:
        client = connect(scheduler)
        try:
            yield client
        finally:
            if client is not scheduler:  # made here: closed here
                client.close()
        return
    if workers <= 1:
        yield None
        return
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_ignore_signals)
    try:
        yield pool
    except BaseException:
        _stop(pool)
        raise
    pool.shutdown(wait=True)


def _ignore_signals() -> None:
    """Worker initializer: Ctrl-C and SIGTERM to the process group are the driver's to act on."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)


STOP_GRACE_S = 2.0
"""How long an interrupted campaign lets its workers finish the runs in hand before stopping them [s]."""


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started, let the runs in hand finish for :data:`STOP_GRACE_S`, then stop the
    workers still running: a worker stopped mid-run leaves the pool's semaphores for multiprocessing's
    tracker to report at exit."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    deadline = time.monotonic() + STOP_GRACE_S
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
    for process in processes:
        if process.is_alive():
            with contextlib.suppress(OSError, ValueError, AttributeError):
                process.kill()  # SIGKILL: the workers ignore SIGINT and SIGTERM
    pool.shutdown(wait=True)


class Evaluator:
    """Runs :class:`ModelRun` requests on the prepared recordings, each at most once per journal.

    ``prepared`` maps recording index to :class:`Prepared`; ``parameters`` are the campaign's; ``pool``
    from :func:`model_pool`; ``journal`` keeps every outcome on disk; ``on_run(n)`` is told of each new run.
    """

    def __init__(self, prepared: Mapping[int, Prepared], parameters: tuple[Parameter, ...],
                 journal: Journal | None = None, pool: ProcessPoolExecutor | None = None,
                 on_run: Callable[[int], None] | None = None) -> None:
        self.prepared = prepared
        self.parameters = parameters
        self.journal = journal
        self.pool = pool
        self.on_run = on_run or (lambda n: None)
        self.memory: dict[str, Outcome] = dict(journal.outcomes) if journal else {}
        self._keys: dict[ModelRun, str] = {}
        self._scenes: dict[str, Scene] = {}
        self.runs = 0
        self.reused = 0

    def scene(self, request: ModelRun) -> Scene:
        """The scene of ``request``: the recording's joint, parameter values and changes, measured
        drive and load.
        """
        prepared = self.prepared[request.recording]
        base = with_values(prepared.scene, self.parameters, request.values, dict(request.changes))
        return measured_scene(prepared.conditioned, base, phase_shift=request.phase_shift,
                              load_offset=request.load_offset)

    def __call__(self, requests: Sequence[ModelRun]) -> list[Outcome]:
        """The outcome of each request, in order; the ones not in the journal run now (in parallel)."""
        keys = [self._key(r) for r in requests]
        todo = {key: r for key, r in zip(keys, requests, strict=True) if key not in self.memory}
        self.reused += sum(1 for key in set(keys) if key not in todo)
        scenes = {key: self._scenes.pop(key, None) or self.scene(r) for key, r in todo.items()}
        for key in keys:  # scenes of runs already made are not needed
            self._scenes.pop(key, None)
        self._run(todo, scenes)
        return [self.memory[key] for key in keys]

    def _key(self, request: ModelRun) -> str:
        """The journal key of ``request`` (its scene's fingerprint), remembered per request; the scene
        built for it is kept until it runs."""
        key = self._keys.get(request)
        if key is None:
            scene = self.scene(request)
            key = self._keys[request] = run_key(scene, request.engine)
            self._scenes[key] = scene
        return key

    def _run(self, todo: Mapping[str, ModelRun], scenes: Mapping[str, Scene]) -> None:
        """Run ``todo`` (key -> request) on its ``scenes``, record each outcome as it arrives."""
        if not todo:
            return
        if self.pool is None:
            for key, r in todo.items():
                self._keep(key, run_scene(scenes[key], r.engine))
            return
        futures = {key: self.pool.submit(run_scene, scenes[key], r.engine) for key, r in todo.items()}
        for key, future in futures.items():
            self._keep(key, future.result())

    def _keep(self, key: str, outcome: Outcome) -> None:
        """Remember ``outcome`` under ``key``, in memory and the journal."""
        self.memory[key] = outcome
        if self.journal is not None:
            self.journal.add(key, outcome)
        self.runs += 1
        self.on_run(self.runs)
