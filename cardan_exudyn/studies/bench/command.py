"""``cardan bench``: work-precision runs of every engine on a small fixed set of scenes.

For each scene (frictionless and with the paper's friction, 10 and 35 deg, and 10 deg with the
paper's mounting tolerances so that pairs slide, at 2000 rpm) and each engine configuration
(Exudyn's step size, Newton settings, node type, friction coupling, velocity projection and
Richardson extrapolation; the reference engine's sampling and quadrature tolerance; MuJoCo with
its recommended settings and a shorter constraint time constant, frictionless scenes only) the
bench records the errors against the reference engine, the median wall time per simulated second
and the engine's cost counters. Then it times the paper's eleven scenes with both engines,
measures the import cost of ``cardan run`` and what each "skip" of the Exudyn build saves, and
evaluates the targets side by side from the same run. ``docs/bench.md`` has the definitions. The
modules, by concept:

- :mod:`~cardan_exudyn.studies.bench.configs`: the scenes and the engine configurations;
- :mod:`~cardan_exudyn.studies.bench.ladders`: the runs, their errors and wall times;
- :mod:`~cardan_exudyn.studies.bench.targets`: the targets and the paper scenes' timing;
- :mod:`~cardan_exudyn.studies.bench.startup`: the import cost of ``cardan run``;
- :mod:`~cardan_exudyn.studies.bench.audit`: the skip audit;
- :mod:`~cardan_exudyn.studies.bench.result`: the whole bench in one call, :func:`run_bench`;
- :mod:`~cardan_exudyn.studies.bench.report`: the results folder and ``report.md``;
- this module: the command (:func:`register`, :func:`handler`).
"""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.report.format import number

__all__ = ["register", "handler"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``bench`` subcommand to the ``cardan`` parser."""
    p = subparsers.add_parser(
        "bench", help="work-precision benchmark of the engines, targets, skip audit",
        description="Error against wall time for every engine configuration (each friction "
                    "coupling) on the frictionless and friction scenes at 10 and 35 deg and with "
                    "sliding pairs, 2000 rpm; the paper's eleven scenes timed; the import cost of "
                    "`cardan run`; what each skip of the Exudyn build saves; the targets side by "
                    "side from the same run.")
    p.add_argument("--out", metavar="DIR",
                   help="results folder: bench.csv, targets.csv, ladders.csv, audit.csv, bench.json, "
                        "report.md, work_precision.png")
    p.add_argument("--quick", action="store_true", help="short ladders, one repeat (< 1 min)")
    p.add_argument("--repeats", type=count("--repeats"), metavar="N",
                   help="timed runs per configuration, median reported (default 3, quick 1)")
    p.add_argument("--scenes", metavar="A,B", help="subset of frictionless-10deg, frictionless-35deg, "
                                                    "frictionless-errors-10deg, friction-10deg, "
                                                    "friction-35deg, friction-errors-10deg")
    p.add_argument("--engines", metavar="A,B", help="subset of exudyn, mujoco, reference")
    p.add_argument("--no-audit", action="store_true", help="leave out the skip audit")
    p.add_argument("--no-paper", action="store_true", help="leave out the paper's eleven scenes")
    p.add_argument("--no-startup", action="store_true",
                   help="leave out the import cost of `cardan run`")
    p.add_argument("--paper-steps", type=steps_or_auto, default=None, metavar="N|auto",
                   help="Exudyn's steps per revolution in the paper's eleven scenes (default auto: "
                        "each scene's own step for mean-efficiency accuracy 1e-4)")
    p.add_argument("--paper-coupling", metavar="NAME", default=None,
                   help="Exudyn's friction coupling in the paper's eleven scenes (default extrapolated)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.add_argument("--only", choices=("batch",),
                   help="batch: the batched reference engine alone (cost against batch size, the paper "
                        "scenes in one batch, memory, the Monte Carlo target, Dask against in-process)")
    p.add_argument("--sizes", type=sizes, metavar="A,B", help="--only batch: batch sizes (1,10,100,1000)")
    p.add_argument("--samples", type=count("--samples", minimum=0), metavar="N",
                   help="--only batch: Monte Carlo samples timed (10000, quick 20; 0: none)")
    p.add_argument("--dask-samples", type=count("--dask-samples", minimum=0), metavar="N",
                   help="--only batch: samples of the Dask comparison (1000, quick 8; 0: none)")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="--only batch: local processes of the Monte Carlo run (default: all cores)")
    p.set_defaults(func=handler)


BATCH_ONLY = ("sizes", "samples", "dask_samples", "workers")
"""Options of ``--only batch`` alone."""


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


def steps_or_auto(text: str) -> int | str:
    """``--paper-steps``: a positive integer or ``auto``."""
    return "auto" if text.strip().lower() == "auto" else count("--paper-steps")(text)


def names(text: str | None) -> list[str] | None:
    """The comma-separated names of an option, None when the option is not given."""
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


def show_progress(text: str) -> None:
    """Progress lines on stderr (the terminal), never on stdout (the JSON)."""
    print(text, file=sys.stderr, flush=True)


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan bench``: the bench, its folder (``--out``) and the targets (or ``--json``)."""
    # The bench's modules load Exudyn, pandas and matplotlib; `cardan` imports every study's
    # `register` to build its parser, so they are imported when the command runs.
    from cardan_exudyn.studies.bench.configs import ENGINE_NAMES, BenchError
    from cardan_exudyn.studies.bench.report import write_bench
    from cardan_exudyn.studies.bench.result import run_bench
    from cardan_exudyn.studies.bench.targets import PAPER_EXUDYN_COUPLING, PAPER_EXUDYN_STEPS

    out_folder(args.out)
    if args.only == "batch":
        from cardan_exudyn.studies.bench.batch import handler as batch_handler  # as above

        return batch_handler(args, None if args.json or not sys.stderr.isatty() else show_progress)
    given = [f"--{k.replace('_', '-')}" for k in BATCH_ONLY if getattr(args, k) is not None]
    if given:
        raise BadInput(f"{', '.join(given)} apply to `cardan bench --only batch` only")
    engines = names(args.engines)
    try:
        result = run_bench(quick=args.quick, repeats=args.repeats, scenes=names(args.scenes),
                           engines=ENGINE_NAMES if engines is None else engines,
                           audit=not args.no_audit, paper=not args.no_paper,
                           progress=None if args.json or not sys.stderr.isatty() else show_progress,
                           startup=not args.no_startup,
                           paper_steps=args.paper_steps or PAPER_EXUDYN_STEPS,
                           paper_coupling=args.paper_coupling or PAPER_EXUDYN_COUPLING)
    except BenchError as exc:
        raise BadInput(str(exc)) from None
    if args.out:
        write_bench(result, args.out)
    if args.json:
        print(dumps(result.summary()))
        return EXIT_OK
    for t in result.targets:
        print(f"{t['target']:16s} {t['scene']:22s} {t['variant']:38s} "
              f"{number(t['measured'], '8.3g', '  failed')} (limit {t['limit']:g}) "
              f"{'met' if t['met'] else 'MISSED'}")
    if args.out:
        print(f"report: {args.out}/report.md")
    return EXIT_OK
