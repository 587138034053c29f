"""``cardan tolerance``: mounting-error studies, the paper's case (``paper``) and Monte Carlo
(``montecarlo``), each into a report folder.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from cardan_exudyn.arguments import (
    COUNT_LIMITS,
    EXIT_FAILED,
    EXIT_OK,
    BadInput,
    count,
    out_folder,
    path_value,
    refuse_options,
)
from cardan_exudyn.engines import ENGINES
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.report.format import number
from cardan_exudyn.scene_options import SCENE_OPTIONS, add_scene_options, scene_from_args
from cardan_exudyn.sweep import Distribution, SweepError
from reference.results.summary import Status
from reference.scene.scene import Scene

__all__ = ["register", "handler", "MONTE_CARLO_ONLY", "PAPER_ONLY", "error_distribution",
           "monte_carlo", "paper_report", "monte_carlo_line"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan tolerance`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("tolerance", help="mounting-error studies: the paper's case, Monte Carlo",
                              description="`paper`: the rig case with and without the paper's tolerances "
                                          "(every parameter set, friction law and coupling). "
                                          "`montecarlo`: errors drawn from distributions (default: the "
                                          "paper's tolerances, uniform with both signs), resumable.")
    p.add_argument("study", choices=("paper", "montecarlo"))
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--engines", help="paper: engines to compare (default reference,exudyn)")
    p.add_argument("--engine", help="montecarlo: engine (default reference)")
    p.add_argument("--samples", type=count("--samples"),
                   help=f"montecarlo: N (default 1000, at most {COUNT_LIMITS['--samples']})")
    p.add_argument("--seed", type=count("--seed", minimum=0), help="montecarlo: seed of the draws (1)")
    p.add_argument("--method", choices=("lhs", "random"),
                   help="montecarlo: Latin hypercube (default) or independent draws")
    p.add_argument("--error", action="append", metavar="PATH=DIST:...",
                   help="montecarlo: e.g. joint.errors.a1_mm=uniform:-0.5:0.5, "
                        "joint.errors.alpha2_deg=normal:0:0.002:-0.006:0.006; repeatable")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=count("--workers"), metavar="N",
                       help="local processes (default: all cores; 1 runs in this process)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="Dask scheduler to run on")
    p.add_argument("--restart", action="store_true", help="montecarlo: discard earlier samples in --out")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    add_scene_options(p)
    p.set_defaults(func=handler)


MONTE_CARLO_ONLY = {"engine": "reference", "samples": 1000, "seed": 1, "method": "lhs", "error": None,
                    "workers": None, "scheduler": None, "restart": False}
"""Options of ``cardan tolerance montecarlo`` only (``paper`` runs its fixed cases), and defaults."""
PAPER_ONLY = {"engines": "reference,exudyn"}
"""Options of ``cardan tolerance paper`` only, and defaults."""


def error_distribution(text: str) -> tuple[str, dict[str, Any]]:
    """The scene path and distribution table of an ``--error`` ``PATH=uniform:LOW:HIGH`` or
    ``PATH=normal:MEAN:STD[:LOW:HIGH]``.
    """
    path, spec = path_value("--error", text, "PATH=uniform:LOW:HIGH or PATH=normal:MEAN:STD[:LOW:HIGH]")
    kind, *numbers = spec.split(":")
    names = {"uniform": ("low", "high"), "normal": ("mean", "std", "low", "high")}.get(kind)
    if names is None or not (2 <= len(numbers) <= len(names)) or (kind == "normal" and len(numbers) == 3):
        raise BadInput(f"--error {text!r}: give uniform:LOW:HIGH or normal:MEAN:STD[:LOW:HIGH]")
    try:
        table = {"dist": kind, **{n: float(v) for n, v in zip(names, numbers, strict=False)}}
        Distribution(**table)
    except (ValueError, SweepError) as exc:
        raise BadInput(f"--error {text!r}: {exc}") from None
    return path, table


def handler(args: argparse.Namespace) -> int:
    """``cardan tolerance``: exit 0 when every run ended ok, 3 otherwise."""
    if args.study == "paper":
        refuse_options(args, [*MONTE_CARLO_ONLY, *SCENE_OPTIONS],
                       "to `cardan tolerance paper` (it runs the paper's rig case; use montecarlo)")
    else:
        refuse_options(args, list(PAPER_ONLY), "to `cardan tolerance montecarlo` (use --engine)")
    for key, default in {**MONTE_CARLO_ONLY, **PAPER_ONLY}.items():
        if getattr(args, key) is None or getattr(args, key) is False:
            setattr(args, key, default)
    if args.study == "montecarlo" and args.name is None and args.scene is None:
        args.name = "rig-matched"
    out_folder(args.out, replace=args.study == "paper")
    if args.study == "paper":
        return paper_handler(args)
    return monte_carlo_handler(args)


def paper_handler(args: argparse.Namespace) -> int:
    """``cardan tolerance paper``: the report folder, a line per case on stderr as it finishes."""
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    unknown = [e for e in engines if e not in ENGINES]
    if not engines or unknown:
        raise BadInput(f"--engines must name engines of {sorted(ENGINES)}, got {args.engines!r}")
    summary = paper_report(args.out, engines, progress=None if args.json else _show_row)
    from cardan_exudyn.studies.tolerance.report import verdict_line  # loaded by the report

    if args.json:
        print(dumps(summary))
    else:
        for v in summary["verdicts"]:
            print(verdict_line(v, summary["paper_change"]), file=sys.stderr)
        print(f"wrote {args.out}/report.md", file=sys.stderr)
    failed = [c for c in summary["cases"]
              if c["status_ideal"] != Status.OK or c["status_errors"] != Status.OK]
    return EXIT_FAILED if failed else EXIT_OK


def _show_row(row: Mapping[str, Any]) -> None:
    print(f"  {row['parameters']:10s} {row['law']:9s} {row['coupling']:9s} {row['engine']:9s} "
          f"{row['status_errors']:12s} change {number(row['relative_change'], '+.3%')}",
          file=sys.stderr)


def monte_carlo_handler(args: argparse.Namespace) -> int:
    """``cardan tolerance montecarlo``: the study folder, a closing line on stderr."""
    scene = scene_from_args(args)
    from cardan_exudyn.studies.tolerance.montecarlo import default_distributions  # as above

    distributions = (dict(error_distribution(t) for t in args.error) if args.error
                     else default_distributions())
    try:
        summary = monte_carlo(scene, args.engine, args.samples, args.seed, distributions, out=args.out,
                              method=args.method, workers=args.workers, scheduler=args.scheduler,
                              restart=args.restart, progress=False if args.json else None)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    if args.json:
        print(dumps(summary))
    else:
        print(monte_carlo_line(summary, args.out), file=sys.stderr)
    every_ok = (summary["status_counts"].get(Status.OK.value, 0) == summary["samples"]
                and summary["ideal_status"] == Status.OK)
    return EXIT_OK if every_ok else EXIT_FAILED


def monte_carlo_line(summary: Mapping[str, Any], out: str) -> str:
    """Statuses, ideal efficiency and 5/50/95 percentiles of ``summary``, and folder ``out``, in one line."""
    m = summary["mean_efficiency"]
    ideal = (number(summary["ideal_mean_efficiency"], ".6f") if summary["ideal_status"] == Status.OK
             else f"{summary['ideal_status']}: {summary.get('ideal_reason', '')}")
    return (f"{summary['status_counts']}; ideal {ideal}; "
            f"p5/p50/p95 {number(m.get('p5'), '.6f')} / {number(m.get('p50'), '.6f')} / "
            f"{number(m.get('p95'), '.6f')}; wrote {out}/study/report.md")


def monte_carlo(scene: Scene, engine: str, samples: int, seed: int,
                distributions: Mapping[str, Mapping[str, Any]] | None = None, *,
                out: str | Path, method: str = "lhs", workers: int | None = None,
                scheduler: Any = None, restart: bool = False,
                progress: bool | None = None) -> dict[str, Any]:
    """``cardan tolerance montecarlo`` without its printing: the samples as a sweep in ``out/cases``
    (arguments as :func:`~.montecarlo.run_monte_carlo`), then ``out/study``; returns the summary.
    """
    # import cost: pandas, scipy and matplotlib for this study only
    from cardan_exudyn.studies.tolerance.montecarlo import run_monte_carlo
    from cardan_exudyn.studies.tolerance.report import write_monte_carlo

    study = run_monte_carlo(scene, engine, samples, seed, distributions, out=out, method=method,
                            workers=workers, scheduler=scheduler, restart=restart, progress=progress)
    write_monte_carlo(study, Path(out) / "study")
    return study.summary


def paper_report(out: str | Path, engines: tuple[str, ...] | list[str] = ("reference", "exudyn"),
                 progress: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """``cardan tolerance paper`` without its printing: the study with ``engines`` (``progress`` called
    per row), then folder ``out``; returns what ``paper_case.json`` holds.
    """
    from cardan_exudyn.studies.tolerance.paper_case import paper_study  # import cost, as above
    from cardan_exudyn.studies.tolerance.report import write_paper_case

    return write_paper_case(paper_study(engines, progress), out)
