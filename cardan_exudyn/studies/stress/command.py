"""``cardan stress``: the stability map of a joint's Exudyn model against the reference engine,
for the joint the scene options describe (default: the paper's). Details: ``docs/stress.md``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.scene_options import add_scene_options, scene_from_args
from cardan_exudyn.studies.stress.panels import BASE_SCENE

__all__ = ["register", "handler", "SET_BY_CELL", "summary_lines"]

DESCRIPTION = ("Stability map of Exudyn against the reference over shaft angle, friction, speed, "
               "step, coupling and node type (converged, drift, self-locking, integration failure), "
               "for a joint (the scene options, as `cardan run` takes them; default the paper's).")
SET_BY_CELL = ("angle", "rpm", "friction_spider", "friction_frame", "coupling", "dt", "accuracy",
               "revolutions")
"""Scene options each cell sets itself (not offered): shaft angle, constant input speed, friction
coefficients, coupling, step (hence no accuracy) and one revolution."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan stress`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("stress", help="stability map of a joint into a report folder",
                              description=DESCRIPTION)
    p.add_argument("--out", metavar="DIR", default="reports/stress",
                   help="report folder (report.md, map_cells.csv, stability_map.png, stress.json); "
                        "the map's runs are kept in OUT/runs")
    p.add_argument("--quick", action="store_true", help="coarse map (CI variant)")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes for the map (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the map's runs recorded in OUT/runs and run every cell again")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    add_scene_options(p, default=f"{BASE_SCENE}, literal set", leave_out=SET_BY_CELL)
    p.set_defaults(func=handler)


def _say(text: str) -> None:
    """A progress line on stderr."""
    print(text, file=sys.stderr, flush=True)


def summary_lines(counts: dict[str, Any], out: str | os.PathLike) -> list[str]:
    """What ``cardan stress`` prints at the end: ``counts`` (:meth:`~.map.StressMap.counts`), ``out``."""
    return ["map: " + ", ".join(f"{v} {k}" for k, v in counts["classes"].items())
            + f"; {counts['disagreements']} of {counts['cells']} cells disagree with the reference",
            f"report: {out}/report.md"]


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan stress``; exit 3 when a map cell raised in the harness."""
    # Imported here, not at the top: `cardan` imports this module to register the command, and the
    # map loads pandas, Exudyn and matplotlib (about 2 s) that no other command should wait for.
    from cardan_exudyn.jsonable import dumps
    from cardan_exudyn.outputs import check_output_folder
    from cardan_exudyn.studies.stress.map import run_map
    from cardan_exudyn.studies.stress.report import problems, summary, write_stress
    from cardan_exudyn.sweep import SweepError

    out_folder(args.out)
    if args.scene is None and args.name is None:
        args.name = BASE_SCENE
    scene = scene_from_args(args)
    out = check_output_folder(args.out)
    start = time.perf_counter()
    if not args.json:
        _say("stability map ...")
    try:
        stress = run_map(out / "runs", args.quick, scene=scene, workers=args.workers,
                         restart=args.restart, progress=False if args.json else None)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    wall = time.perf_counter() - start
    write_stress(stress, out, wall)
    print(dumps(summary(stress, wall)) if args.json else "\n".join(summary_lines(stress.counts(), args.out)))
    found = problems(stress)
    for problem in found:
        print(f"  {problem}", file=sys.stderr)
    return EXIT_FAILED if found else EXIT_OK
