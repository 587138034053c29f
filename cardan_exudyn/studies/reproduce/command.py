"""``cardan reproduce``: the paper's results with friction under its three parameter sets, as a
report folder.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.report.format import number

if TYPE_CHECKING:
    from cardan_exudyn.studies.reproduce.compute import Reproduction

__all__ = ["register", "handler", "reproduce", "outcome_lines"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan reproduce`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("reproduce", help="reproduce the paper's studies into a report folder")
    p.add_argument("--out", metavar="DIR", default="reports/reproduce", help="report folder")
    p.add_argument("--quick", action="store_true", help="fewer scenes and a coarser accuracy")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the runs recorded in OUT/runs and run every case again")
    p.add_argument("--retry-failed", action="store_true", help="rerun the cases recorded as failed")
    p.set_defaults(func=handler)


def reproduce(out: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
              restart: bool = False, retry_failed: bool = False,
              progress: bool | None = None) -> Reproduction:
    """``cardan reproduce`` without its printing: :func:`~.compute.run_cases` (same arguments) into
    ``out``, then the report folder, replaced atomically; returns the :class:`~.compute.Reproduction`.
    """
    # import cost: the runs load the engines, the report pandas and matplotlib; `cardan` imports
    # this module to register the command
    from cardan_exudyn.studies.reproduce.compute import run_cases
    from cardan_exudyn.studies.reproduce.report import write_reproduction

    result = run_cases(out, quick, workers=workers, restart=restart, retry_failed=retry_failed,
                       progress=progress)
    write_reproduction(result)
    return result


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan reproduce``; exit 3 when a run failed (the report covers the others)."""
    from cardan_exudyn.sweep import SweepError  # import cost, as above

    out_folder(args.out)
    try:
        result = reproduce(args.out, quick=args.quick, workers=args.workers, restart=args.restart,
                           retry_failed=args.retry_failed)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    for line in outcome_lines(result):
        print(line, file=sys.stderr)
    return EXIT_OK if result.success else EXIT_FAILED


def outcome_lines(result: Reproduction) -> list[str]:
    """What ``cardan reproduce`` says at the end: each failed run, then where the report is."""
    from cardan_exudyn.studies.reproduce.compute import RUNS_DIR  # loaded by the run already

    lines = [f"  {run.id}: {result.records[run.id]['status']}: {result.records[run.id].get('reason')}"
             for run in result.failed]
    sweep = result.sweep
    out = result.out
    executor = sweep["executor"]
    how = (f" in {number(sweep['wall_time_s'], '.1f')} s, {executor['kind']}"
           + (f", {executor['workers']} workers" if executor.get("workers", 1) > 1 else "")
           if sweep["run_now"] else "")
    earlier = (f"; {result.reused} from earlier records in {out}/{RUNS_DIR}, --restart runs them again"
               if result.reused else "")
    lines.append(f"wrote {out}/report.md ({len(result.runs)} runs, "
                 f"{len(result.runs) - len(result.failed)} ok; {sweep['run_now']} run now{how}"
                 f"{earlier})")
    return lines
