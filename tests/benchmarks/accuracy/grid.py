"""The accuracy grid: cells that are not the paper's (shaft angle 0-60 deg, input speed
1-10,000 rpm, friction coefficient 0-0.6, with and without mounting errors, speed, angle and
torque drives); each cell runs its scene with Exudyn at ``numerics.accuracy`` and with the
reference engine at tight settings, and records the true error of the Exudyn mean efficiency,
the run's own estimate (``summary.efficiency_error_estimate``), whether the run met its target,
and the cost of the estimate (the companion run's share of the wall time, measured in the same
run). ``docs/accuracy.md`` has the numbers.
"""

from __future__ import annotations

import itertools
import math
import multiprocessing
import time
from typing import Any

import numpy as np

from cardan_exudyn.engines import run
from reference.paper import named_scene
from reference.results.accuracy import RunAccuracy
from reference.scene import replace
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM

__all__ = ["ANGLES_DEG", "SPEEDS_RPM", "FRICTIONS", "ERRORS", "DRIVES", "REFERENCE_TIGHT",
           "MOUNTING_ERRORS", "CELL_TIMEOUT_S", "grid_cells", "cell_scene", "run_cell",
           "run_cell_limited"]


ANGLES_DEG = (0.0, 15.0, 35.0, 60.0)


SPEEDS_RPM = (1.0, 100.0, 2000.0, 10000.0)


FRICTIONS = (0.0, 0.05, 0.2, 0.6)


ERRORS = (False, True)


DRIVES = ("speed", "angle", "torque")


REFERENCE_TIGHT = {"quadrature_rtol": 1e-11, "ode_rtol": 1e-12, "ode_atol": 1e-12}


MOUNTING_ERRORS = {"joint.errors.a2": 0.2e-3, "joint.errors.alpha1": 0.3 * DEG}


def grid_cells(cells: int | None = None, seed: int = 0) -> list[dict[str, Any]]:
    """The full grid, or ``cells`` of its cells drawn without replacement (seeded)."""
    grid = [dict(angle_deg=a, rpm=r, friction=f, errors=e, drive=d)
            for a, r, f, e, d in itertools.product(ANGLES_DEG, SPEEDS_RPM, FRICTIONS, ERRORS, DRIVES)]
    if cells is None or cells >= len(grid):
        return grid
    pick = np.random.default_rng(seed).choice(len(grid), size=cells, replace=False)
    return [grid[i] for i in sorted(pick)]


def cell_scene(cell: dict[str, Any], accuracy: float) -> Scene:
    """The scene of a cell: the paper's joint at the cell's angle, speed, friction (spider pairs
    ``f``, frame pairs ``f / 2``), mounting errors and drive; 2 revolutions, the first skipped
    for the angle and torque drives."""
    speed = cell["rpm"] * RPM
    f = cell["friction"]
    changes: dict[str, Any] = {"joint.geometry.shaft_angle": cell["angle_deg"] * DEG,
                               "numerics.accuracy": accuracy, "record.timeseries": False,
                               "revolutions": 2.0}
    for pair, value in (("input_spider", f), ("spider_output", f), ("frame_input", f / 2),
                        ("output_frame", f / 2)):
        changes[f"joint.pairs.{pair}.friction_coefficient"] = value
    if cell["errors"]:
        changes.update(MOUNTING_ERRORS)
    period = 2.0 * math.pi / speed
    if cell["drive"] == "speed":
        changes["drive"] = {"kind": "speed", "speed": speed}
    elif cell["drive"] == "angle":  # speed varying +-20 % twice a revolution
        t = np.linspace(0.0, 2.5 * period, 41)
        changes["drive"] = {"kind": "angle", "time": t.tolist(),
                            "angle": (speed * t + 0.1 * period * speed / math.pi
                                      * np.sin(2.0 * math.pi * t / period)).tolist()}
        changes["record.skip_revolutions"] = 0.5
    else:  # torque: twice the load, starting at the cell's speed
        changes["drive"] = {"kind": "torque", "torque": 4.0, "initial_speed": speed}
        changes["record.skip_revolutions"] = 0.5
    return replace(named_scene("paper-literal-10deg"), **changes)


def run_cell(cell: dict[str, Any], accuracy: float) -> dict[str, Any]:
    """One cell: the Exudyn run with its estimate against the reference at tight settings."""
    scene = cell_scene(cell, accuracy)
    row = dict(cell)
    ref = run(scene, "reference", **REFERENCE_TIGHT).summary
    ex = run(scene, "exudyn").summary
    row["status"] = f"{ex.status}/{ref.status}"
    if not (ex.success and ref.success) or ex.mean_efficiency is None or ref.mean_efficiency is None:
        return row
    info = ex.accuracy or RunAccuracy()
    true = abs(ex.mean_efficiency - ref.mean_efficiency)
    estimate = ex.efficiency_error_estimate
    pilot = info.pilot
    overhead = ((info.companion.wall_time_s if info.companion else None) or 0.0) + (
        0.0 if pilot is None or pilot.is_companion else pilot.wall_time_s or 0.0)
    row.update(steps_per_revolution=info.steps_per_revolution, mean_efficiency=ex.mean_efficiency,
               true_error=true, estimate=estimate, met=ex.accuracy_met, within_target=true <= accuracy,
               ratio=true / estimate if estimate else (0.0 if true == 0 else math.inf),
               cost_ratio=ex.wall_time_s / max(ex.wall_time_s - overhead, 1e-12),
               order=info.order, loss_fraction=info.loss_fraction,
               model=info.model, richardson=info.richardson)
    return row


CELL_TIMEOUT_S = 600.0
"""Wall-time limit of one cell [s] (``--timeout``): a cell that exceeds it is recorded as
``timeout``, not compared, and counted against the grid."""


def _cell_worker(connection: Any, cell: dict[str, Any], accuracy: float) -> None:
    """The body of a cell's subprocess: send :func:`run_cell`'s row (or the error) back."""
    try:
        connection.send(run_cell(cell, accuracy))
    except Exception as exc:  # noqa: BLE001 - the parent records any failure of the cell as its row
        connection.send({**cell, "status": f"error: {type(exc).__name__}: {exc}"[:200]})
    connection.close()


def run_cell_limited(cell: dict[str, Any], accuracy: float,
                     timeout: float = CELL_TIMEOUT_S) -> dict[str, Any]:
    """:func:`run_cell` in a subprocess stopped after ``timeout`` seconds (status ``timeout``);
    ``wall_time_s`` is the cell's wall time."""
    context = multiprocessing.get_context("spawn")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_cell_worker, args=(send, cell, accuracy), daemon=True)
    start = time.perf_counter()
    process.start()
    send.close()
    try:
        row = receive.recv() if receive.poll(timeout) else {**cell, "status": f"timeout ({timeout:g} s)"}
    except EOFError:  # the subprocess died without a row
        row = {**cell, "status": f"crashed (exit {process.exitcode})"}
    finally:
        if process.is_alive():
            process.terminate()
        process.join(5.0)
    row["wall_time_s"] = time.perf_counter() - start
    return row
