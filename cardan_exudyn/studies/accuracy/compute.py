"""``cardan accuracy``: is the reported accuracy of the mean efficiency honest?

Over a grid that is not the paper's (shaft angle 0-60 deg, input speed 1-10,000 rpm, friction
coefficient 0-0.6, with and without mounting errors, speed, angle and torque drives), each cell
runs the scene with Exudyn at ``numerics.accuracy`` and with the reference engine at tight
settings, and records the true error of the Exudyn mean efficiency, the run's own estimate
(``summary.efficiency_error_estimate``), whether the run met its target, and the cost of the
estimate (the companion run's share of the wall time, measured in the same run). ``--fit``
prints the envelope constants of the a-priori model (:mod:`cardan_exudyn.model.stepsize`) that
the cells measure, to refit ``EFFICIENCY_FIRST_ORDER`` (``_ERRORS``) and ``EFFICIENCY_SECOND_ORDER``.
``docs/accuracy.md`` has the numbers.
"""

from __future__ import annotations

import argparse
import itertools
import math
import multiprocessing
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, count, number, out_folder
from cardan_exudyn.engines import run
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table
from reference.paper.scenes import named_scene
from reference.results.accuracy import RunAccuracy
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM

__all__ = ["ANGLES_DEG", "SPEEDS_RPM", "FRICTIONS", "DRIVES", "grid_cells", "cell_scene", "run_cell",
           "honesty", "fit_constants", "register", "run_cell_limited", "CELL_TIMEOUT_S"]

ANGLES_DEG = (0.0, 15.0, 35.0, 60.0)
SPEEDS_RPM = (1.0, 100.0, 2000.0, 10000.0)
FRICTIONS = (0.0, 0.05, 0.2, 0.6)
ERRORS = (False, True)
DRIVES = ("speed", "angle", "torque")
REFERENCE_TIGHT = {"quadrature_rtol": 1e-11, "ode_rtol": 1e-12, "ode_atol": 1e-12}
MOUNTING_ERRORS = {"joint.errors.a2": 0.2e-3, "joint.errors.alpha1": 0.3 * DEG}
COLUMNS = ["angle_deg", "rpm", "friction", "errors", "drive", "status", "steps_per_revolution",
           "mean_efficiency", "true_error", "estimate", "ratio", "met", "within_target", "cost_ratio"]


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


def honesty(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The grid's verdict: shares of cells within the target, with the estimate within a factor 3
    of the true error (either way, or as a bound: true <= 3 x estimate), and the estimate's cost."""
    done = [r for r in rows if "true_error" in r]
    friction = [r for r in done if r["true_error"] > 0 or (r["estimate"] or 0) > 0]
    ratios = np.array([r["ratio"] for r in friction], float)
    cost = np.array([r["cost_ratio"] for r in done if r["friction"] > 0], float)

    def share(mask: Any) -> float:
        return float(np.mean(mask)) if np.size(mask) else math.nan

    return {"cells": len(rows), "compared": len(done),
            "not_compared": [f"{r['angle_deg']:g}deg/{r['rpm']:g}rpm/f{r['friction']:g}/"
                             f"{'errors/' if r['errors'] else ''}{r['drive']}: {r.get('status')}"
                             for r in rows if "true_error" not in r],
            "within_target": share([r["within_target"] for r in done]),
            "within_target_of_all": share([r.get("within_target", False) for r in rows]),
            "met_when_within": share([r["met"] == r["within_target"] for r in done]),
            "estimate_within_3x": share((ratios <= 3.0) & (ratios >= 1.0 / 3.0)),
            "true_within_3x_estimate": share(ratios <= 3.0),
            "ratio_median": float(np.median(ratios)) if ratios.size else math.nan,
            "ratio_max": float(np.max(ratios)) if ratios.size else math.nan,
            "cost_ratio_median": float(np.median(cost)) if cost.size else math.nan,
            "cost_ratio_max": float(np.max(cost)) if cost.size else math.nan}


def fit_constants(rows: Sequence[dict[str, Any]]) -> dict[str, float]:
    """Envelopes of ``true_error / (r h)`` over the first-order cells (``lagged``; ``r`` the loss
    fraction) and ``true_error / ((1 - eta) h^2)`` over the
    second-order ones: the values ``EFFICIENCY_FIRST_ORDER`` and ``EFFICIENCY_SECOND_ORDER`` need
    (the first ignores the second-order part, the second includes ``K``: both bound from above)."""
    out = {"first_order": 0.0, "first_order_errors": 0.0, "second_order": 0.0}
    for r in rows:
        if "true_error" not in r or not r.get("loss_fraction") or not r.get("steps_per_revolution"):
            continue
        h = 2.0 * math.pi / r["steps_per_revolution"]
        if r["order"] == 1:
            key = "first_order_errors" if r["errors"] else "first_order"
            out[key] = max(out[key], r["true_error"] / (r["loss_fraction"] * h))
        else:
            out["second_order"] = max(out["second_order"], r["true_error"] / (r["loss_fraction"] * h * h))
    return out


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan accuracy`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("accuracy", help="is the reported mean-efficiency accuracy honest? "
                                               "(a grid against the reference engine)")
    p.add_argument("--cells", type=count("--cells"), metavar="N",
                   help=f"random cells of the grid (default: all {len(grid_cells())})")
    p.add_argument("--seed", type=count("--seed", minimum=0), default=0, help="seed of the cell draw")
    p.add_argument("--accuracy", type=number("-", positive=True), default=1e-3, metavar="E",
                   help="numerics.accuracy of every cell (default 1e-3)")
    p.add_argument("--timeout", type=number("s", positive=True), default=CELL_TIMEOUT_S,
                   metavar="S", help=f"wall-time limit of one cell [s] (default {CELL_TIMEOUT_S:g})")
    p.add_argument("--fit", action="store_true", help="print the model constants the cells measure")
    p.add_argument("--out", metavar="DIR", help="write rows.csv and accuracy.json here")
    p.add_argument("--json", action="store_true", help="print rows and verdict as JSON")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """``cardan accuracy``: exit 0 when the grid is honest (>= 95 % within target), else 3."""
    out_folder(args.out)
    cells = grid_cells(args.cells, args.seed)
    rows = []
    for i, cell in enumerate(cells):
        rows.append(run_cell_limited(cell, args.accuracy, args.timeout))
        r = rows[-1]
        print(f"[{i + 1}/{len(cells)}] {cell} {r.get('status')} true {r.get('true_error')} "
              f"estimate {r.get('estimate')} {r['wall_time_s']:.0f} s", file=sys.stderr, flush=True)
    verdict = {**honesty(rows), "accuracy": args.accuracy}
    if args.fit:
        verdict["fit"] = fit_constants(rows)
    if args.out:
        with atomic_directory(args.out) as tmp:
            _write(Path(tmp), rows, verdict)
    if args.json:
        print(dumps({"verdict": verdict, "rows": rows}))
    else:
        print(markdown_table(rows, COLUMNS), end="")
        print(" ".join(f"{k}={v:.3g}" if isinstance(v, float) else f"{k}={v}" for k, v in verdict.items()))
    return EXIT_OK if verdict["within_target"] >= 0.95 else EXIT_FAILED


def _write(folder: Path, rows: Sequence[dict[str, Any]], verdict: dict[str, Any]) -> None:
    import pandas as pd  # import cost: only when writing

    pd.DataFrame(rows).to_csv(folder / "rows.csv", index=False)
    (folder / "accuracy.json").write_text(dumps({"verdict": verdict, "rows": list(rows)}))
