"""``python tests/benchmarks accuracy``: is the reported accuracy of the mean efficiency honest
over a grid that is not the paper's (:mod:`.grid`), and (``--fit``) the constants of the a-priori
model the cells measure (:mod:`.verdict`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchmarks.accuracy.grid import CELL_TIMEOUT_S, grid_cells, run_cell_limited
from benchmarks.accuracy.verdict import fit_constants, honesty
from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, count, number, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table

__all__ = ["COLUMNS", "register", "handler"]


COLUMNS = ["angle_deg", "rpm", "friction", "errors", "drive", "status", "steps_per_revolution",
           "mean_efficiency", "true_error", "estimate", "ratio", "met", "within_target", "cost_ratio"]


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add ``accuracy`` (``name``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(name, help="is the reported mean-efficiency accuracy honest? "
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
    """Run the grid: exit 0 when it is honest (>= 95 % within target), else 3."""
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
    """``rows.csv`` and ``accuracy.json`` (rows and verdict) into ``folder``."""
    import pandas as pd  # import cost: only when writing

    pd.DataFrame(rows).to_csv(folder / "rows.csv", index=False)
    (folder / "accuracy.json").write_text(dumps({"verdict": verdict, "rows": list(rows)}))
