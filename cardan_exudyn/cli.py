"""The ``cardan`` command line.

Exit status: 0 success; 2 bad input (one line on stderr naming the argument, no traceback);
3 the simulation failed or is physically meaningless (the reason is in the summary ``status``);
4 (``cardan sweep``) the sweep stopped before every case ran (rerun the command to resume).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from cardan_exudyn.arguments import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_INCOMPLETE,
    EXIT_OK,
    BadInput,
    add_scene_options,
    cli_value,
    count,
    number,
    out_folder,
    path_value,
    scene_from_args,
)
from reference.scene import SceneError
from reference.schema import OptionsError


class _Parser(argparse.ArgumentParser):
    """argparse's errors as one line on stderr (no usage block), exit status 2."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def cmd_run(args: argparse.Namespace) -> int:
    from cardan_exudyn.engines import ENGINES, run
    from cardan_exudyn.io import dumps, write_result

    if args.engine not in ENGINES:
        raise BadInput(f"`--engine` must be one of {sorted(ENGINES)}, got {args.engine!r}")
    out_folder(args.out)
    scene = scene_from_args(args)
    result = run(scene, args.engine)
    if args.out:
        write_result(result, args.out)
    if args.json:
        print(dumps(result.summary))
    else:
        _print_summary(result.summary, args.out)
    return EXIT_OK if result.success else EXIT_FAILED


def _fmt(value: Any, spec: str, missing: str = "-") -> str:
    """``value`` formatted, or ``missing`` when it is not a finite number (never 'nan')."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    return format(value, spec) if ok else missing


def _no_work(s: dict[str, Any]) -> str:
    """What a run with status ok prints for an efficiency that is 0/0 (no input work, e.g. a joint
    spinning free), instead of 'nan'."""
    return f"undefined (input work {_fmt(s.get('input_work'), '.3g')} J)"


def _print_summary(s: dict[str, Any], out: str | None) -> None:
    err = sys.stderr
    if s.get("status") != "ok":
        print(f"status: {s.get('status')}: {s.get('reason')}", file=err)
        return
    print(f"scene {s['scene']['name']} with {s['engine']} {s['engine_version']}: "
          f"mean efficiency {_fmt(s.get('mean_efficiency'), '.6f', _no_work(s))} "
          f"(time average of eq. (18): "
          f"{_fmt(s.get('mean_instantaneous_efficiency'), '.6f', 'undefined, P_in = 0 at some instant')}) "
          f"over {s['revolutions']} revolutions; dt {_fmt(s.get('dt'), '.3g')} s, "
          f"{s.get('steps')} steps, {s['wall_time_s']:.3g} s wall")
    if out:
        print(f"wrote {out}/timeseries.csv and {out}/summary.json")


def cmd_reproduce(args: argparse.Namespace) -> int:
    from cardan_exudyn.studies.reproduce import reproduce
    from cardan_exudyn.sweep.runner import SweepError

    out_folder(args.out)
    try:
        return reproduce(args.out, quick=args.quick, workers=args.workers, restart=args.restart,
                         retry_failed=args.retry_failed)
    except SweepError as exc:
        raise BadInput(str(exc)) from None


def cmd_bench(args: argparse.Namespace) -> int:
    from cardan_exudyn.studies.bench import SCENES, BenchError, run_bench, write_bench

    def names(text: str | None, default: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(n.strip() for n in text.split(",") if n.strip()) if text else default

    out_folder(args.out)
    try:
        result = run_bench(quick=args.quick, repeats=args.repeats,
                           scenes=names(args.scenes, tuple(SCENES)),
                           engines=names(args.engines, ("exudyn", "mujoco", "reference")),
                           audit=not args.no_audit, paper=not args.no_paper,
                           progress=not args.json and sys.stderr.isatty())
    except BenchError as exc:
        raise BadInput(str(exc)) from None
    if args.out:
        write_bench(result, args.out)
    if args.json:
        from cardan_exudyn.io import dumps

        print(dumps(result.summary()))
    else:
        for t in result.targets:
            met = "met" if t["met"] else "MISSED"
            print(f"{t['target']:16s} {t['scene']:20s} {t['variant']:28s} "
                  f"{_fmt(t['measured'], '8.3g', '  failed')} "
                  f"(limit {t['limit']:g}) {met}")
        if args.out:
            print(f"report: {args.out}/report.md")
    return 0


def cmd_stress(args: argparse.Namespace) -> int:
    from cardan_exudyn.studies.stress import StressError, parse_parts, print_summary, run_stress
    from cardan_exudyn.sweep.runner import SweepError

    try:
        parts = parse_parts(args.only)
        say = (lambda text: print(text, file=sys.stderr, flush=True)) if not args.json else None
        report = run_stress(args.out, quick=args.quick, parts=parts, workers=args.workers,
                            restart=args.restart, progress=None if not args.json else False,
                            say=say)
    except (StressError, SweepError) as exc:
        raise BadInput(str(exc)) from None
    if args.json:
        from cardan_exudyn.io import dumps

        print(dumps(report.summary()))
    else:
        print_summary(report, args.out)
    problems = report.problems()
    for problem in problems:
        print(f"  {problem}", file=sys.stderr)
    return EXIT_FAILED if problems else EXIT_OK


def cmd_study(args: argparse.Namespace) -> int:
    from cardan_exudyn.studies.coupling import main_study

    out_folder(args.out)
    return main_study(args.kind, args.out, args.quick, args.json)


def cmd_calibrate(args: argparse.Namespace) -> int:
    from cardan_exudyn.studies.calibrate import main_calibrate
    from reference.paper import CALIBRATION_PARAMETERS

    names = None
    if args.parameters is not None:
        names = [n.strip() for n in args.parameters.split(",") if n.strip()]
    if names == []:
        raise BadInput(f"--parameters names no parameter, got {args.parameters!r}; choose from "
                       f"{list(CALIBRATION_PARAMETERS)}")
    unknown = [n for n in names or [] if n not in CALIBRATION_PARAMETERS]
    if unknown:
        raise BadInput(f"--parameters: unknown {unknown}; choose from {list(CALIBRATION_PARAMETERS)}")
    return main_calibrate(names, args.json)


def cmd_compare(args: argparse.Namespace) -> int:
    from cardan_exudyn.compare import main_compare

    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    out_folder(args.out)
    try:
        return main_compare(scene_from_args(args), engines, args.skip_revolutions, args.out,
                            args.json)
    except ValueError as exc:
        if isinstance(exc, SceneError):
            raise
        raise BadInput(str(exc)) from None


def cmd_scene(args: argparse.Namespace) -> int:
    import tomli_w

    from reference.scene import scene_to_dict

    scene = scene_from_args(args)
    print(tomli_w.dumps(scene_to_dict(scene)), end="")
    return EXIT_OK


def sweep_spec_from_args(args: argparse.Namespace) -> Any:
    """The sweep spec of ``cardan sweep``: the SPEC file, with the command-line options applied."""
    import os

    from cardan_exudyn.sweep.runner import SweepError, looks_like_path, read_spec_file, spec_from_mapping

    data = read_spec_file(args.spec) if args.spec else {}
    if args.scene is not None:
        scene = args.scene
        data["scene"] = os.path.abspath(scene) if looks_like_path(scene) or os.path.isfile(scene) else scene
    for key in ("engine", "function"):
        if getattr(args, key) is not None:
            data[key] = getattr(args, key)
    for option, key, items, form in (("--grid", "grid", args.grid, "PATH=V1,V2,..."),
                                     ("--set", "fixed", args.set, "PATH=VALUE")):
        for text in items or ():
            path, value = path_value(option, text, form)
            table = data.setdefault(key, {})
            table[path] = [cli_value(v) for v in value.split(",")] if key == "grid" else cli_value(value)
    data.setdefault("scene", None)
    if not args.spec:
        return spec_from_mapping(data)
    try:
        return spec_from_mapping(data, base_dir=os.path.dirname(os.path.abspath(args.spec)))
    except SweepError as exc:
        raise SweepError(f"{args.spec}: {exc}") from None


def cmd_sweep(args: argparse.Namespace) -> int:
    from cardan_exudyn.io import dumps
    from cardan_exudyn.sweep.runner import SweepError, SweepIncomplete, run_sweep

    out_folder(args.out, replace=False)
    try:
        spec = sweep_spec_from_args(args)
        summary = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                            restart=args.restart, retry_failed=args.retry_failed,
                            progress=False if args.quiet else None)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    except SweepIncomplete as exc:
        print(f"cardan sweep: {exc}", file=sys.stderr)
        return EXIT_INCOMPLETE
    if args.json:
        print(dumps(summary))
    elif not args.quiet:
        counts = ", ".join(f"{n} {status}" for status, n in summary["status_counts"].items())
        print(f"sweep {args.out}: {summary['done']} cases ({counts}), {summary['run_now']} run now in "
              f"{summary['wall_time_s']:.3g} s ({summary['executor']['kind']}); wrote "
              f"{args.out}/results.csv and {args.out}/sweep.json", file=sys.stderr)
    return EXIT_OK if summary["failed"] == 0 else EXIT_FAILED


def _distribution(text: str) -> tuple[str, dict[str, Any]]:
    """``PATH=uniform:LOW:HIGH`` or ``PATH=normal:MEAN:STD[:LOW:HIGH]`` for ``--error``."""
    from cardan_exudyn.sweep.runner import Distribution, SweepError

    path, value = path_value("--error", text, "PATH=uniform:LOW:HIGH or PATH=normal:MEAN:STD[:LOW:HIGH]")
    kind, *numbers = value.split(":")
    names = {"uniform": ("low", "high"), "normal": ("mean", "std", "low", "high")}.get(kind)
    if names is None or not (2 <= len(numbers) <= len(names)) or (kind == "normal" and len(numbers) == 3):
        raise BadInput(f"--error {text!r}: give uniform:LOW:HIGH or normal:MEAN:STD[:LOW:HIGH]")
    try:
        table = {"dist": kind, **{n: float(v) for n, v in zip(names, numbers, strict=False)}}
        Distribution(**table)
    except (ValueError, SweepError) as exc:
        raise BadInput(f"--error {text!r}: {exc}") from None
    return path, table


def cmd_tolerance(args: argparse.Namespace) -> int:
    from cardan_exudyn.engines import ENGINES
    from cardan_exudyn.io import dumps
    from cardan_exudyn.sweep.runner import SweepError

    out_folder(args.out, replace=args.study == "paper")
    if args.study == "paper":
        engines = [e.strip() for e in args.engines.split(",") if e.strip()]
        unknown = [e for e in engines if e not in ENGINES]
        if not engines or unknown:
            raise BadInput(f"--engines must name engines of {sorted(ENGINES)}, got {args.engines!r}")
        from cardan_exudyn.studies.tolerance import paper_report

        def show(row: dict) -> None:
            if not args.json:
                print(f"  {row['parameters']:10s} {row['coupling']:9s} {row['engine']:9s} "
                      f"{row['status_errors']:12s} change {_fmt(row['relative_change'], '+.3%')}",
                      file=sys.stderr)

        summary = paper_report(args.out, engines, progress=show)
        if args.json:
            print(dumps(summary))
        else:
            print(f"wrote {args.out}/report.md", file=sys.stderr)
        failed = [c for c in summary["cases"] if "ok" != c["status_ideal"] or "ok" != c["status_errors"]]
        return EXIT_FAILED if failed else EXIT_OK
    from cardan_exudyn.studies.tolerance import default_distributions, monte_carlo

    scene = scene_from_args(args)
    distributions = dict(_distribution(t) for t in args.error) if args.error else default_distributions()
    try:
        summary = monte_carlo(scene, args.engine, args.samples, args.seed, distributions, out=args.out,
                              method=args.method, workers=args.workers, scheduler=args.scheduler,
                              restart=args.restart, progress=False if args.json else None)
    except SweepError as exc:
        raise BadInput(str(exc)) from None
    if args.json:
        print(dumps(summary))
    else:
        m = summary["mean_efficiency"]
        ideal = (_fmt(summary["ideal_mean_efficiency"], ".6f") if summary["ideal_status"] == "ok"
                 else f"{summary['ideal_status']}: {summary.get('ideal_reason', '')}")
        print(f"{summary['status_counts']}; ideal {ideal}; "
              f"p5/p50/p95 {_fmt(m.get('p5'), '.6f')} / {_fmt(m.get('p50'), '.6f')} / "
              f"{_fmt(m.get('p95'), '.6f')}; wrote {args.out}/study/report.md", file=sys.stderr)
    every_ok = summary["status_counts"].get("ok", 0) == summary["samples"] and summary["ideal_status"] == "ok"
    return EXIT_OK if every_ok else EXIT_FAILED


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="cardan", description="Mechanical efficiency of Cardan joints with Exudyn.")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("run", help="simulate one scene")
    add_scene_options(p)
    p.add_argument("--engine", default="exudyn",
                   help="exudyn (default), reference, or mujoco (frictionless; optional extra)")
    p.add_argument("--out", metavar="DIR", help="write timeseries.csv and summary.json here")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("reproduce", help="reproduce the paper's studies into a report folder")
    p.add_argument("--out", metavar="DIR", default="reports/reproduce", help="report folder")
    p.add_argument("--quick", action="store_true", help="fewer scenes and a coarser accuracy")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the runs recorded in OUT/runs and run every case again")
    p.add_argument("--retry-failed", action="store_true", help="rerun the cases recorded as failed")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("bench", help="work-precision benchmark of the engines, targets, skip audit",
                       description="Error against wall time for every engine configuration on the "
                                   "frictionless and friction scenes at 10 and 35 deg, 2000 rpm; "
                                   "the speed targets as ratios from the same run; the paper's "
                                   "eleven scenes timed; what each skip of the Exudyn build saves.")
    p.add_argument("--out", metavar="DIR",
                   help="results folder: bench.csv, targets.csv, audit.csv, bench.json, report.md, "
                        "work_precision.png")
    p.add_argument("--quick", action="store_true", help="short ladders, one repeat (< 1 min)")
    p.add_argument("--repeats", type=count("--repeats"), metavar="N",
                   help="timed runs per configuration, median reported (default 3, quick 1)")
    p.add_argument("--scenes", metavar="A,B", help="subset of frictionless-10deg, frictionless-35deg, "
                                                    "friction-10deg, friction-35deg")
    p.add_argument("--engines", metavar="A,B", help="subset of exudyn, mujoco, reference")
    p.add_argument("--no-audit", action="store_true", help="leave out the skip audit")
    p.add_argument("--no-paper", action="store_true", help="leave out the paper's eleven scenes")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser("stress", help="stability map, long runs, bad-input table into a report folder",
                       description="Stability map of Exudyn against the reference over shaft angle, "
                                   "friction, speed, step, coupling and node type (converged, drift, "
                                   "self-locking, integration failure); 2000-revolution drift and "
                                   "1000-revolution energy runs; every entry point fed bad input.")
    p.add_argument("--out", metavar="DIR", default="reports/stress",
                   help="report folder (report.md, map_cells.csv, stability_map.png, long-run and "
                        "bad-input files, stress.json); the map's runs are kept in OUT/runs")
    p.add_argument("--quick", action="store_true", help="coarse map, short long runs (CI variant)")
    p.add_argument("--only", metavar="A,B", help="subset of map, long, inputs (default all)")
    p.add_argument("--workers", type=count("--workers"), metavar="N",
                   help="local processes for the map (default: all cores; 1 runs in this process)")
    p.add_argument("--restart", action="store_true",
                   help="discard the map's runs recorded in OUT/runs and run every cell again")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=cmd_stress)

    p = sub.add_parser("study", help="numerical studies of the friction model")
    p.add_argument("kind", choices=("coupling", "sign-band"),
                   help="coupling: error of mean efficiency against step size for the lagged and "
                        "converged schemes; sign-band: mean efficiency against the sign band")
    p.add_argument("--out", metavar="DIR", help="write CSV, JSON, markdown and a plot here")
    p.add_argument("--quick", action="store_true", help="one scene, a short ladder")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=cmd_study)

    p = sub.add_parser("calibrate", help="fit the paper's open parameters to a subset of its results")
    p.add_argument("--parameters", metavar="A,B",
                   help="parameters to fit (default spider_lever,frame_lever,input_eccentricity)")
    p.add_argument("--json", action="store_true", help="print the fit as JSON on stdout")
    p.set_defaults(func=cmd_calibrate)

    p = sub.add_parser("compare", help="run several engines on one scene and compare them")
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
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("sweep", help="run a scene over a grid or random samples of its parameters",
                       description="Run a sweep (docs/sweep.md). Records go to OUT/cases.jsonl as "
                                   "cases finish; rerunning the same command resumes.")
    p.add_argument("spec", nargs="?", metavar="SPEC.toml", help="sweep spec (scene, engine, grid, random)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder: plan.json, cases.jsonl, results.csv, sweep.json")
    p.add_argument("--scene", metavar="NAME|FILE", help="named scene or scene TOML (overrides the spec)")
    p.add_argument("--engine", help="engine (overrides the spec; default exudyn)")
    p.add_argument("--function", metavar="MODULE:NAME",
                   help="case function fn(scene, engine) -> dict (default: the summary's scalars)")
    p.add_argument("--grid", action="append", metavar="PATH=V1,V2,...",
                   help="grid parameter (dotted scene path), repeatable; adds to the spec's grid")
    p.add_argument("--set", action="append", metavar="PATH=VALUE",
                   help="override applied to every case, repeatable")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=count("--workers"), metavar="N",
                       help="local processes (default: all cores; 1 runs in this process)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                       help="run on this Dask distributed scheduler instead")
    p.add_argument("--restart", action="store_true", help="discard the records in --out and start over")
    p.add_argument("--retry-failed", action="store_true", help="rerun the cases recorded as failed")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no closing line")
    p.add_argument("--json", action="store_true", help="print the sweep summary as JSON on stdout")
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("tolerance", help="mounting-error studies: the paper's case, Monte Carlo",
                       description="`paper`: the rig case with and without the paper's tolerances "
                                   "(both parameter sets and couplings, per-pair breakdown). "
                                   "`montecarlo`: errors drawn from distributions (default: the "
                                   "paper's tolerances, uniform with both signs), resumable.")
    p.add_argument("study", choices=("paper", "montecarlo"))
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--engines", default="reference,exudyn", help="paper: engines to compare")
    p.add_argument("--engine", default="reference", help="montecarlo: engine (default reference)")
    p.add_argument("--samples", type=count("--samples"), default=1000, help="montecarlo: N (1000)")
    p.add_argument("--seed", type=count("--seed", minimum=0), default=1,
                   help="montecarlo: seed of the draws (1)")
    p.add_argument("--method", choices=("lhs", "random"), default="lhs",
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
    p.set_defaults(func=cmd_tolerance, name="rig-calibrated")

    p = sub.add_parser("scene", help="print the fully resolved scene as TOML")
    add_scene_options(p)
    p.set_defaults(func=cmd_scene)
    _add_study_commands(sub)
    _add_plugin_commands(sub)
    return parser


def _add_study_commands(sub: argparse._SubParsersAction) -> None:
    """The subcommands the study modules register (:data:`cardan_exudyn.studies.COMMANDS`)."""
    import importlib

    from cardan_exudyn.studies import COMMANDS

    for name in COMMANDS:
        importlib.import_module(f"cardan_exudyn.studies.{name}").register(sub)


def _add_plugin_commands(sub: argparse._SubParsersAction) -> None:
    """Commands other packages register under the ``cardan.commands`` entry-point group (``cardan
    rig`` from ``rigdata``): imports keep pointing one way, this package never imports them."""
    from importlib.metadata import entry_points

    for entry in sorted(entry_points(group="cardan.commands"), key=lambda e: e.name):
        entry.load()(sub)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from cardan_exudyn.engines import EngineUnavailable
    from cardan_exudyn.io import OutputError

    try:
        return args.func(args)
    except (SceneError, OptionsError, EngineUnavailable, BadInput, OutputError) as exc:
        print(f"cardan {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"cardan {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
