"""``cardan bench``: run time against error of every engine configuration on a scene (the one of
``--scene``/``--name``, or the default :data:`~cardan_exudyn.studies.bench.configs.SCENES`);
definitions in ``docs/bench.md``.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from cardan_exudyn.arguments import EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.report.format import number
from cardan_exudyn.scene_options import SCENE_OPTIONS, add_scene_options, scene_from_args

__all__ = ["register", "handler", "names", "given_scene_options", "scenes_from_args", "summary_lines"]

SET_BY_CONFIGURATION = ("dt", "coupling")
"""Scene options every configuration sets itself (not offered): its step, and with friction its
coupling."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``bench`` subcommand to the ``cardan`` parser."""
    p = subparsers.add_parser(
        "bench", help="work-precision benchmark of the engines",
        description="Error against wall time for every engine configuration (each friction "
                    "coupling) on a scene (--scene or --name, with the other scene options as "
                    "`cardan run` takes them), or by default on the frictionless and friction "
                    "scenes at 10 and 35 deg and with sliding pairs, 2000 rpm; the cheapest run of "
                    "each configuration at the scene's accuracy.")
    p.add_argument("--out", metavar="DIR",
                   help="results folder: bench.csv, bench.json, report.md, work_precision.png")
    p.add_argument("--quick", action="store_true", help="short ladders, one repeat (< 1 min)")
    p.add_argument("--repeats", type=count("--repeats"), metavar="N",
                   help="timed runs per configuration, median reported (default 3, quick 1)")
    p.add_argument("--scenes", metavar="A,B", help="subset of frictionless-10deg, frictionless-35deg, "
                                                    "frictionless-errors-10deg, friction-10deg, "
                                                    "friction-35deg, friction-errors-10deg")
    p.add_argument("--engines", metavar="A,B", help="subset of exudyn, mujoco, reference")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    add_scene_options(p, default="the default scenes of --scenes", leave_out=SET_BY_CONFIGURATION)
    p.set_defaults(func=handler)


def names(text: str | None) -> list[str] | None:
    """The comma-separated names of an option, None when the option is not given."""
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


def given_scene_options(args: argparse.Namespace) -> list[str]:
    """The scene options given on the command line, as they would be typed again."""
    out = []
    for dest in SCENE_OPTIONS:
        value = getattr(args, dest, None)
        if value is None or value is False:
            continue
        option = f"--{dest.replace('_', '-')}"
        if value is True:
            out.append(option)
        else:
            out += [option, f"{value:g}" if isinstance(value, float) else str(value)]
    return out


def scenes_from_args(args: argparse.Namespace) -> dict[str, Any] | None:
    """``{name: scene}`` of ``--scene`` or ``--name`` with the other scene options, or None for the
    default set; BadInput for ``--scenes`` with either, or a scene option without either.
    """
    options = given_scene_options(args)
    if args.scene is None and args.name is None:
        if options:
            raise BadInput(f"{options[0]} applies to the scene of --scene or --name; the default "
                           f"scenes are fixed")
        return None
    if args.scenes is not None:
        raise BadInput("--scenes chooses among the default scenes; it does not apply with --scene "
                       "or --name")
    scene = scene_from_args(args)
    return {scene.name: scene}


def show_progress(text: str) -> None:
    """Progress lines on stderr (the terminal), never on stdout (the JSON)."""
    print(text, file=sys.stderr, flush=True)


def summary_lines(configurations: list[dict[str, Any]]) -> list[str]:
    """One line per scene and configuration: the cheapest step at the scene's accuracy."""
    lines = []
    scene_width = max((len(c["scene"]) for c in configurations), default=0)
    config_width = max((len(c["config"]) for c in configurations), default=0)
    for c in configurations:
        head = f"{c['scene']:{scene_width}s} {c['config']:{config_width}s}"
        if c["steps_per_revolution"] is None:
            lines.append(f"{head} no step on the ladder reaches {c['accuracy']:g}")
            continue
        lines.append(f"{head} {c['steps_per_revolution']:5d} steps/rev: error "
                     f"{number(c['error'], '8.2g')} <= {c['accuracy']:g} at "
                     f"{number(c['wall_per_simulated_s'], '.3g')} s per simulated s")
    return lines


def handler(args: argparse.Namespace) -> int:
    """Run ``cardan bench``: the bench, its ``--out`` folder and the cheapest run of each configuration
    at the scene's accuracy (or ``--json``).
    """
    # The bench's modules load Exudyn, pandas and matplotlib; `cardan` imports every study's
    # `register` to build its parser, so they are imported when the command runs.
    from cardan_exudyn.studies.bench.configs import ENGINE_NAMES, BenchError, fixed_scenes
    from cardan_exudyn.studies.bench.report import write_bench
    from cardan_exudyn.studies.bench.result import run_bench

    out_folder(args.out)
    engines = names(args.engines)
    try:
        scenes = scenes_from_args(args) or fixed_scenes(names(args.scenes))
        result = run_bench(scenes, quick=args.quick, repeats=args.repeats,
                           engines=ENGINE_NAMES if engines is None else engines,
                           progress=None if args.json or not sys.stderr.isatty() else show_progress,
                           scene_options=given_scene_options(args))
    except BenchError as exc:
        raise BadInput(str(exc)) from None
    if args.out:
        write_bench(result, args.out)
    summary = result.summary()
    if args.json:
        print(dumps(summary))
        return EXIT_OK
    print("\n".join(summary_lines(summary["configurations"])))
    if args.out:
        print(f"report: {args.out}/report.md")
    return EXIT_OK
