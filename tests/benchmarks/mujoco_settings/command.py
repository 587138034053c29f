"""``python tests/benchmarks mujoco-settings``: the MuJoCo settings study
(:mod:`benchmarks.mujoco_settings.study`) as a table; registering needs no MuJoCo."""

from __future__ import annotations

import argparse
import sys

from cardan_exudyn.arguments import EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table

__all__ = ["PRINTED", "PRINTED_FORMATS", "register", "handler"]

PRINTED = ["scene", "case", "steps_per_revolution", "status", "speed_ratio_error", "torque_in_error",
           "mean_torque_in_error", "bearing_drift_m", "wall_time_s"]
PRINTED_FORMATS = {"steps_per_revolution": ".0f", "speed_ratio_error": ".2e", "torque_in_error": ".2e",
                   "mean_torque_in_error": ".2e", "bearing_drift_m": ".2e", "wall_time_s": ".3f"}


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add ``mujoco-settings`` (``name``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(name, help="MuJoCo's settings: error and cost (docs/mujoco.md, tables A-E)",
                              description="Error and cost of MuJoCo's integrators and constraint "
                                          "settings on the frictionless 10 and 30 deg scenes at 2000 "
                                          "rpm (tables A-D), or on the slow rig scene (--rig, table E).")
    p.add_argument("--rig", action="store_true", help="table E: the rig scene at low speed")
    p.add_argument("--repeats", type=count("--repeats"), default=3, metavar="N",
                   help="runs per case, median wall time (default 3)")
    p.add_argument("--out", metavar="DIR", help="write settings.csv here")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """Run the study and print its table (markdown); ``--out``: ``settings.csv``."""
    try:
        from benchmarks.mujoco_settings.study import low_speed_cases, settings_study
    except ImportError as exc:  # MuJoCo is an optional extra
        raise BadInput(f"MuJoCo is not installed (pip install mujoco): {exc}") from None
    out_folder(args.out)
    if args.rig:
        table = settings_study(scenes=("rig-frictionless",), cases=low_speed_cases(), repeats=args.repeats)
    else:
        table = settings_study(repeats=args.repeats)
    if args.out:
        with atomic_directory(args.out) as tmp:
            table.to_csv(tmp / "settings.csv", index=False)
    print(markdown_table(table, PRINTED, PRINTED_FORMATS), end="")
    if args.out:
        print(f"wrote {args.out}/settings.csv", file=sys.stderr)
    return EXIT_OK
