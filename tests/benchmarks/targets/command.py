"""``python tests/benchmarks targets``: the project's speed targets measured side by side from one
run (:mod:`.run`): ``cardan bench``'s work-precision runs of its default scenes, the paper's
eleven scenes timed, the import cost of ``cardan run`` and the skip audit; the folder:
:mod:`.report`; the targets: :mod:`.targets`."""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.report.format import number
from cardan_exudyn.studies.bench.command import names, show_progress

__all__ = ["register", "handler", "steps_or_auto"]


def steps_or_auto(text: str) -> int | str:
    """``--paper-steps``: a positive integer or ``auto``."""
    return "auto" if text.strip().lower() == "auto" else count("--paper-steps")(text)


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add ``targets`` (``name``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(
        name, help="the speed targets: work precision, the paper's scenes, start-up, skip audit",
        description="Error against wall time for every engine configuration on cardan bench's "
                    "default scenes (each friction scene with its frictionless twin); the paper's "
                    "eleven scenes timed; the import cost of `cardan run`; what each skip of the "
                    "Exudyn build saves; the targets side by side from the same run.")
    p.add_argument("--out", metavar="DIR",
                   help="results folder: bench.csv, targets.csv, ladders.csv, audit.csv, "
                        "targets.json, report.md, work_precision.png")
    p.add_argument("--quick", action="store_true", help="short ladders, one repeat (< 1 min)")
    p.add_argument("--repeats", type=count("--repeats"), metavar="N",
                   help="timed runs per configuration, median reported (default 3, quick 1)")
    p.add_argument("--scenes", metavar="A,B", help="subset of frictionless-10deg, frictionless-35deg, "
                                                    "frictionless-errors-10deg, friction-10deg, "
                                                    "friction-35deg, friction-errors-10deg; a friction "
                                                    "scene brings its frictionless twin")
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
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """Run the targets: the measurements, the folder (``--out``) and the targets (or ``--json``)."""
    from benchmarks.targets.paper import PAPER_EXUDYN_COUPLING, PAPER_EXUDYN_STEPS  # import cost
    from benchmarks.targets.report import write_targets
    from benchmarks.targets.run import run_targets
    from cardan_exudyn.studies.bench.configs import ENGINE_NAMES, BenchError

    out_folder(args.out)
    engines = names(args.engines)
    try:
        result = run_targets(quick=args.quick, repeats=args.repeats, scenes=names(args.scenes),
                             engines=ENGINE_NAMES if engines is None else engines,
                             audit=not args.no_audit, paper=not args.no_paper,
                             progress=None if args.json or not sys.stderr.isatty() else show_progress,
                             startup=not args.no_startup,
                             paper_steps=args.paper_steps or PAPER_EXUDYN_STEPS,
                             paper_coupling=args.paper_coupling or PAPER_EXUDYN_COUPLING)
    except BenchError as exc:
        raise BadInput(str(exc)) from None
    if args.out:
        write_targets(result, args.out)
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
