"""``python tests/benchmarks longrun``: the long runs (:mod:`.runs`) into a report folder
(:mod:`.report`); the verdicts on their measurements are ``tests/benchmarks/test_longrun.py``."""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.environment import environment

__all__ = ["register", "handler"]


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add ``longrun`` (``name``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(
        name, help="drift over 2000 revolutions and energy conservation over 1000, measured",
        description="Exudyn's long runs: 2000 revolutions of the paper's scene with friction per "
                    "node type (constraint drift, rotation coordinates, per-revolution efficiency) "
                    "and 1000 free-spinning revolutions (energy against generalized-alpha's "
                    "damping). The verdicts are `pytest tests/benchmarks/test_longrun.py` (`-m slow` "
                    "for these variants).")
    p.add_argument("--out", metavar="DIR", default="reports/longrun",
                   help="report folder: report.md, longrun_drift.csv, longrun_energy.csv, "
                        "longrun_summary.json, three figures")
    p.add_argument("--quick", action="store_true", help="20 revolutions, two node types, one angle")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """Run the long runs and write the folder; exit 3 when a run raised in the harness."""
    from benchmarks.longrun.report import markdown, write_long  # import cost: Exudyn, matplotlib
    from benchmarks.longrun.runs import long_runs

    out_folder(args.out)
    result = long_runs(quick=args.quick, progress=None if args.json else _say)
    env = environment()
    with atomic_directory(args.out) as folder:
        write_long(result, folder)
        head = (f"# Long runs{' (--quick)' if args.quick else ''}\n\n{env['date']}, commit "
                f"`{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical CPUs), exudyn "
                f"{env['packages'].get('exudyn')}.\n\n")
        (folder / "report.md").write_text(head + markdown(result), encoding="utf-8")
    errors = result.errors()
    if args.json:
        print(dumps(result.summary))
    else:
        print(f"long runs: {result.status_line()}; report: {args.out}/report.md")
    for name, reason in errors:
        print(f"  {name} raised in the harness: {reason}", file=sys.stderr)
    return EXIT_FAILED if errors else EXIT_OK


def _say(text: str) -> None:
    """A progress line on stderr."""
    print(text, file=sys.stderr, flush=True)
