"""Many scenes through the reference engine at once.

Scenes with equal :func:`batch_key` (None: runs alone) share one vectorised pass; :func:`run_batch`
returns per scene, in order, :func:`reference.engine.solve.run`'s Result (to rounding, or to the
quadrature tolerance). A scene that locks, fails or does not close its loop gets its own failed
Result; invalid scenes raise before anything runs, naming the index. ``summary.wall_time_s`` is
the scene's share of its chunk's time.
"""

from __future__ import annotations

import time
from collections.abc import Hashable, Sequence

import numpy as np

from reference.engine.batch.model import SceneStack
from reference.engine.batch.quadrature import work_quadratures
from reference.engine.motion import input_motion
from reference.engine.options import ReferenceOptions
from reference.engine.periodic import period_rows, repeat_period
from reference.engine.slots import friction_slots
from reference.engine.solve import ENGINE_NAME, ENGINE_VERSION, means_from_works, run
from reference.engine.table import EXTRA_COLUMNS, table_times, table_verdict
from reference.results.result import Result, result_table
from reference.results.summary import OptionsError, Status, Summary
from reference.scene.drives import SpeedDrive
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError, check_steps, require_scene

__all__ = ["BATCH_SCENES", "batch_key", "check_scenes", "run_batch"]

BATCH_SCENES = 32
"""Scenes evaluated together at most: bounds the memory (their time tables are held at once); more
gain little time. Measured: docs/engines.md#constants-of-the-reference-engine."""


def batch_key(scene: Scene) -> Hashable | None:
    """Scenes with the same key may run in one pass; None: on its own."""
    require_scene(scene)
    if not isinstance(scene.drive, SpeedDrive) or not scene.load.constant:
        return None
    return ("speed", bool(scene.joint.errors.any), tuple(friction_slots(scene)), scene.friction.law,
            scene.friction.coupling)


def run_batch(scenes: Sequence, options: ReferenceOptions | None = None) -> list[Result]:
    """One Result per scene of ``scenes``, in order, sharing vectorised passes where :func:`batch_key`
    agrees; ``options`` the same for all (None: the defaults).
    """
    scenes = list(scenes)
    options = check_scenes(scenes, options)
    groups: dict[Hashable, list[int]] = {}
    for i, scene in enumerate(scenes):
        groups.setdefault(batch_key(scene), []).append(i)
    results: list[Result | None] = [None] * len(scenes)
    for key, members in groups.items():
        if key is None:
            for i in members:
                results[i] = run(scenes[i], options)
            continue
        for start in range(0, len(members), BATCH_SCENES):
            chunk = members[start:start + BATCH_SCENES]
            for i, result in zip(chunk, _run_chunk([scenes[i] for i in chunk], options), strict=True):
                results[i] = result
    return results


def check_scenes(scenes: Sequence, options: ReferenceOptions | None = None) -> ReferenceOptions:
    """The options in effect (None: defaults), after refusing what :func:`run_batch` would refuse:
    TypeError for a non-scene, OptionsError, SceneError beyond the step limit (naming the index).
    """
    for i, scene in enumerate(scenes):
        require_scene(scene, f"scenes[{i}]")
    if options is not None and not isinstance(options, ReferenceOptions):
        raise OptionsError(f"`options` must be ReferenceOptions or None, got {type(options).__name__}")
    options = options or ReferenceOptions()
    for i, scene in enumerate(scenes):
        try:
            _check_steps(scene, options)
        except SceneError as exc:
            raise SceneError(f"scenes[{i}]: {exc}") from None
    return options


def _check_steps(scene: Scene, options: ReferenceOptions) -> None:
    """The engine's step-limit checks without running: a torque drive's before integrating, any other's
    on its time table.
    """
    if scene.drive.kind == "torque":
        spr = options.samples_per_revolution or 360
        check_steps(scene.revolutions * spr,
                    f"{scene.revolutions:g} revolutions at {spr} samples per revolution")
    else:
        table_times(scene, input_motion(scene, options), options)


def _summary(scene: Scene, options: ReferenceOptions) -> Summary:
    """A fresh summary as :func:`reference.engine.solve.run` starts it."""
    return Summary(Status.OK, engine=ENGINE_NAME, engine_version=ENGINE_VERSION, scene=scene_to_dict(scene),
                   options={k: getattr(options, k) for k in options.__dataclass_fields__})


def _run_chunk(scenes: list[Scene], options: ReferenceOptions) -> list[Result]:
    """Results of scenes sharing one batch key (see the module documentation)."""
    start = time.perf_counter()
    # the checks the engine's first steps make (the loop at 0, its windings, its closure on the
    # sign bands' profile) for all at once; the scenes that pass are evaluated together
    stack = SceneStack(scenes)
    members = [k for k in range(len(scenes)) if k not in stack.failed]
    if stack.failed and members:
        stack = SceneStack([scenes[k] for k in members], [stack.sign_bands[k] for k in members])
    results: dict[int, Result] = {}
    if members:
        tables = _tables(stack, options)
        results = {k: tables[j] for j, k in enumerate(members) if j not in stack.failed}
    share = (time.perf_counter() - start) / max(1, len(results))
    for result in results.values():
        result.summary.wall_time_s = share
    results.update({k: run(scenes[k], options) for k in range(len(scenes)) if k not in results})
    return [results[k] for k in range(len(scenes))]


def _tables(stack: SceneStack, options: ReferenceOptions) -> list[Result]:
    """Every scene of ``stack``: time table, verdict, works and means (in ``stack`` order)."""
    motions = [input_motion(scene, options) for scene in stack.scenes]
    times = [table_times(scene, motion, options) for scene, motion in zip(stack.scenes, motions, strict=True)]
    # summary only: the first period of each table, repeated (reference.engine.table.table_columns)
    rows = [(None if scene.record.timeseries else period_rows(t, speed)) or t.size
            for scene, t, speed in zip(stack.scenes, times, stack.speed, strict=True)]
    owner = np.repeat(np.arange(len(times)), rows)
    columns = stack.columns(owner, np.concatenate([t[:n] for t, n in zip(times, rows, strict=True)]))
    bounds = np.cumsum([0, *rows])
    tables = [{key: value[bounds[k]:bounds[k + 1]] for key, value in columns.items()}
              for k in range(len(times))]
    tables = [repeat_period(table, t, speed) if n < t.size else table
              for table, t, speed, n in zip(tables, times, stack.speed, rows, strict=True)]
    summaries = []
    for k, scene in enumerate(stack.scenes):
        summary = _summary(scene, options)
        if scene.has_friction:
            summary.extras["sign_bands_m_s"] = {p: list(b) for p, b in stack.sign_bands[k].items()}
        table_verdict(times[k], tables[k], summary)
        summaries.append(summary)
    ok = [k for k, s in enumerate(summaries) if s.success]
    works = work_quadratures(stack, ok, [motions[k] for k in ok], [tables[k] for k in ok], options)
    for k, work in zip(ok, works, strict=True):
        means_from_works(stack.scenes[k], work, tables[k], options, summaries[k])
    return [Result(result_table(table, scene.record.every, EXTRA_COLUMNS) if scene.record.timeseries
                   else None, summary)
            for scene, table, summary in zip(stack.scenes, tables, summaries, strict=True)]
