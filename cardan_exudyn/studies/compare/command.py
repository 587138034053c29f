"""``cardan compare``: engines on one scene (:func:`cardan_exudyn.comparison.compare`), a report folder."""

from __future__ import annotations

import argparse

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, number, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.scene_options import add_scene_options, scene_from_args

__all__ = ["register", "handler", "engine_names"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan compare`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("compare", help="run several engines on one scene and compare them")
    add_scene_options(p)
    p.add_argument("--engines", default="exudyn,reference", metavar="A,B",
                   help="engines, the first is the base (default exudyn,reference; mujoco needs "
                        "the optional extra and a frictionless scene)")
    p.add_argument("--skip-revolutions", type=number("--skip-revolutions", non_negative=True),
                   default=0.0, metavar="N",
                   help="leave the first N revolutions out of the 'steady' statistics")
    p.add_argument("--out", metavar="DIR",
                   help="report folder: comparison.json, report.md, tables, overlay plots")
    p.add_argument("--json", action="store_true", help="print the comparison as JSON on stdout")
    p.set_defaults(func=handler)


def engine_names(text: str) -> list[str]:
    """The engines of ``--engines A,B``: at least two, none twice."""
    engines = [e.strip() for e in text.split(",") if e.strip()]
    if len(engines) < 2:
        raise BadInput(f"`--engines` needs at least two engines, got {engines!r}")
    if len(set(engines)) != len(engines):
        raise BadInput(f"`--engines` lists an engine twice: {engines!r}")
    return engines


def handler(args: argparse.Namespace) -> int:
    """``cardan compare``: exit 0 when every engine ran to status ok, 3 otherwise."""
    from cardan_exudyn.comparison import compare  # import cost: pandas, scipy: this command only
    from cardan_exudyn.studies.compare.report import report_markdown, write_report  # as above

    out_folder(args.out)
    scene = scene_from_args(args)
    engines = engine_names(args.engines)
    if args.skip_revolutions >= scene.revolutions:
        raise BadInput(f"--skip-revolutions {args.skip_revolutions:g} leaves nothing of the scene's "
                       f"{scene.revolutions:g} revolutions to compare: give fewer, or more --revolutions")
    progress = None if args.json else _say
    comparison = compare(scene, engines, skip_revolutions=args.skip_revolutions,
                         progress=progress)
    if args.out:
        write_report(comparison, args.out)
    if args.json:
        print(dumps(comparison.to_dict()))
    else:
        print(report_markdown(comparison))
        if args.out:
            print(f"report written to {args.out}")
    return EXIT_OK if comparison.success else EXIT_FAILED


def _say(message: str) -> None:
    """A progress line on stdout."""
    print(message, flush=True)
