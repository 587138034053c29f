"""``python tests/benchmarks batch``: the batched reference engine measured
(:mod:`.measure`), its targets (:mod:`.targets`) and folder (:mod:`.report`)."""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_OK, count, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.studies.bench.command import show_progress
from cardan_exudyn.studies.bench.configs import quiet

__all__ = ["register", "handler", "sizes"]


def sizes(text: str) -> list[int]:
    """``--sizes``: comma-separated batch sizes, each from 1 to 100000."""
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or any(not 1 <= v <= 100_000 for v in values):
        raise argparse.ArgumentTypeError(f"--sizes must be integers in [1, 100000] like 1,10,100, "
                                         f"got {text!r}")
    return values


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add ``batch`` (``name``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(
        name, help="the batched reference engine: cost against batch size, Monte Carlo, Dask",
        description="The batched reference engine alone: cost against batch size, the paper "
                    "scenes in one batch, memory, the Monte Carlo target, Dask against in-process, "
                    "a torque-driven scene.")
    p.add_argument("--out", metavar="DIR",
                   help="results folder: batch.csv, batch_targets.csv, batch.json, report.md")
    p.add_argument("--quick", action="store_true",
                   help="a smaller study, batches of 1 and 10 (about a minute)")
    p.add_argument("--sizes", type=sizes, metavar="A,B", help="batch sizes (1,10,100,1000)")
    p.add_argument("--samples", type=count("--samples", minimum=0), metavar="N",
                   help="Monte Carlo samples timed (10000, quick 40; 0: none)")
    p.add_argument("--dask-samples", type=count("--dask-samples", minimum=0), metavar="N",
                   help="samples of the Dask comparison (1000, quick 16; 0: none)")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes of the Monte Carlo run (default: all cores)")
    p.add_argument("--json", action="store_true", help="print the measurements as JSON on stdout")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """The measurements, the folder (``--out``), the report (or ``--json``) on stdout."""
    from benchmarks.batch.measure import run_batch_bench  # import cost: the engines, pandas
    from benchmarks.batch.report import report_markdown, write_batch_bench

    out_folder(args.out)
    result = run_batch_bench(quick=args.quick, sizes=args.sizes, samples=args.samples,
                             dask_samples=args.dask_samples, workers=args.workers,
                             progress=quiet if args.json or not sys.stderr.isatty() else show_progress)
    if args.out:
        write_batch_bench(result, args.out)
    print(dumps(result) if args.json else report_markdown(result))
    return EXIT_OK
