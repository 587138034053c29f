"""``cardan calibrate``: refit a parameter set's open values on its fit cases, or (``--envelope``)
bound what the plausible box can give for each of the paper's numbers.
"""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.studies.calibrate.envelope import envelope_study
from cardan_exudyn.studies.calibrate.fit import FIT_SETS, calibrate
from cardan_exudyn.studies.calibrate.fitting import FIT_ENGINES
from cardan_exudyn.studies.calibrate.report import envelope_text, fit_text, write_result

__all__ = ["register", "handler"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan calibrate`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("calibrate", help="fit a parameter set to a subset of the paper's results, "
                                                "or bound the paper's numbers over the plausible box")
    p.add_argument("--set", dest="parameter_set", default="physical", metavar="NAME",
                   help=f"parameter set to refit: {', '.join(FIT_SETS)} (default physical)")
    p.add_argument("--engine", default="reference", metavar="NAME",
                   help=f"engine of every run: {', '.join(FIT_ENGINES)} (default reference)")
    p.add_argument("--envelope", action="store_true",
                   help="instead of a fit: the lowest and highest value of each of the paper's "
                        "numbers over the plausible box")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    p.add_argument("--out", metavar="DIR", help="write the result (JSON) and the report (markdown) here")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """``cardan calibrate``: exit 0 when every case ran to status ok, 3 otherwise."""
    if args.parameter_set not in FIT_SETS:
        hint = " (the literal set has nothing fitted)" if args.parameter_set == "literal" else ""
        raise BadInput(f"--set must be one of {list(FIT_SETS)}, got {args.parameter_set!r}{hint}")
    if args.engine not in FIT_ENGINES:
        raise BadInput(f"--engine must be one of {list(FIT_ENGINES)}, got {args.engine!r}")
    out_folder(args.out)
    if args.envelope:
        result = envelope_study(args.engine, progress=_say)
        text = envelope_text(result)
        failed = result["failed_runs"]
    else:
        result = calibrate(args.parameter_set, args.engine, progress=_say)
        text = fit_text(result)
        failed = [r for r in result["rows"] if r.get("status", "ok") != "ok"]
        for r in failed:
            print(f"status: {r['case']}: {r['status']}: {r['reason']}", file=sys.stderr)
    if args.out:
        write_result(args.out, "envelope.json" if args.envelope else "calibrate.json", result, text)
        _say(f"wrote {args.out}")
    print(dumps(result) if args.json else text, end="" if not args.json else "\n")
    return EXIT_FAILED if failed else EXIT_OK


def _say(message: str) -> None:
    print(f"  {message}", file=sys.stderr, flush=True)
