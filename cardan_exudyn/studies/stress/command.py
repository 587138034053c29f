"""``cardan stress``: the stability map of Exudyn against the reference, and the long runs.

The command registers here (:func:`register`); the parts are :mod:`.stress_map` (where the Exudyn
model stops giving the right answer, and why) and :mod:`.longrun` (drift over thousands of
revolutions, energy conservation), run and written by :mod:`.stress_report`. Their verdicts are
tests: ``pytest tests/test_longrun.py`` for the long runs' tolerances and ``pytest
tests/test_hardening.py`` for bad input at every entry point. Details: ``docs/stress.md``.
"""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, count, out_folder

DESCRIPTION = ("Stability map of Exudyn against the reference over shaft angle, friction, speed, "
               "step, coupling and node type (converged, drift, self-locking, integration failure); "
               "2000-revolution drift and 1000-revolution energy runs, measured and reported. The "
               "verdicts on the long runs are `pytest tests/test_longrun.py`; bad input at every "
               "entry point is `pytest tests/test_hardening.py` (both from a source checkout).")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan stress`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("stress", help="stability map and long runs into a report folder",
                              description=DESCRIPTION)
    p.add_argument("--out", metavar="DIR", default="reports/stress",
                   help="report folder (report.md, map_cells.csv, stability_map.png, long-run "
                        "files, stress.json); the map's runs are kept in OUT/runs")
    p.add_argument("--quick", action="store_true", help="coarse map, short long runs (CI variant)")
    p.add_argument("--only", metavar="A,B", help="subset of map, long (default both)")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes for the map (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the map's runs recorded in OUT/runs and run every cell again")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=handler)


def _say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan stress``; exit 3 when a map cell or a long run raised in the harness."""
    # Imported here, not at the top: `cardan` imports this module to register the command, and the
    # parts load pandas, Exudyn and matplotlib (about 2 s) that no other command should wait for.
    from cardan_exudyn.jsonable import dumps
    from cardan_exudyn.studies.stress.report import StressError, parse_parts, run_stress, summary_lines
    from cardan_exudyn.sweep import SweepError

    out_folder(args.out)
    try:
        parts = parse_parts(args.only)
        report = run_stress(args.out, quick=args.quick, parts=parts, workers=args.workers,
                            restart=args.restart, progress=False if args.json else None,
                            say=None if args.json else _say)
    except (StressError, SweepError) as exc:
        raise BadInput(str(exc)) from None
    print(dumps(report.summary()) if args.json else "\n".join(summary_lines(report, args.out)))
    problems = report.problems()
    for problem in problems:
        print(f"  {problem}", file=sys.stderr)
    return EXIT_FAILED if problems else EXIT_OK
