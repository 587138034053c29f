"""The ``cardan`` command line: the core commands (``run``, ``sweep``, ``scene``), the study modules'
(:data:`cardan_exudyn.studies.COMMANDS`) and those of the ``cardan.commands`` entry points.

Exit status: 0 success; 2 bad input (one line on stderr), an output another command is writing, or
a disk that refuses the output; 3 the run failed (summary ``status``); 4 a sweep stopped early
(rerun to resume); 5 ``cardan run`` ended ok but missed ``--accuracy``; 130 Ctrl-C, 143 SIGTERM
(previous output kept); 141 the output's reader went away.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from cardan_exudyn.arguments import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_INACCURATE,
    EXIT_INCOMPLETE,
    EXIT_OK,
    BadInput,
    cli_value,
    count,
    out_folder,
    path_value,
)
from cardan_exudyn.engines import ENGINES, EngineUnavailable, make_options, run
from cardan_exudyn.interrupts import Terminated, exit_status, terminate_raises
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import (
    WRITE_ERRORS,
    OutputError,
    output_lock,
    result_files,
    write_error,
    write_result,
)
from cardan_exudyn.report.format import number
from cardan_exudyn.scene_options import add_scene_options, scene_from_args
from cardan_exudyn.studies import COMMANDS
from reference.results.summary import OptionsError, Status, Summary
from reference.scene.mapping import scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

if TYPE_CHECKING:
    from cardan_exudyn.sweep import SweepSpec

__all__ = ["EXIT_BROKEN_PIPE", "CORE_COMMANDS", "cmd_run", "cmd_scene", "cmd_sweep", "sweep_spec_from_args",
           "build_parser", "add_run_parser", "add_sweep_parser", "add_scene_parser", "parse_args", "main"]

EXIT_BROKEN_PIPE = 141
"""128 + SIGPIPE: what a shell reports for a program whose reader went away."""


class _Parser(argparse.ArgumentParser):
    """argparse's errors as one line on stderr (no usage block), exit status 2."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def cmd_run(args: argparse.Namespace) -> int:
    """``cardan run``: exit 0 ok, 3 failed, 5 ok but the estimated error exceeds ``--accuracy``."""
    if args.engine not in ENGINES:
        raise BadInput(f"`--engine` must be one of {sorted(ENGINES)}, got {args.engine!r}")
    options = None
    if args.projection:
        try:
            options = make_options(args.engine, velocity_projection=True)
        except OptionsError:
            raise BadInput(f"--projection is an exudyn option, not one of {args.engine!r}") from None
    out_folder(args.out)
    scene = scene_from_args(args)
    if args.richardson:
        scene = dataclasses.replace(scene, numerics=dataclasses.replace(scene.numerics, richardson=True))
    _warn_given_step(scene)
    result = run(scene, args.engine, options)
    if args.out:
        write_result(result, args.out)
    if args.json:
        print(dumps(result.summary))
    else:
        _print_summary(result.summary, args.out, result_files(result))
    if result.success and result.summary.accuracy_met is False:
        return EXIT_INACCURATE
    return EXIT_OK if result.success else EXIT_FAILED


def _warn_given_step(scene: Scene) -> None:
    """Warn on stderr when Exudyn's a-priori error models predict more than the accuracy at ``--dt``."""
    if scene.numerics.dt is None:
        return
    from cardan_exudyn.model.stepsize import predicted_errors  # the Exudyn engine's step model

    over = [f"{what} error up to {error:.2g}" for what, error in (predicted_errors(scene) or {}).items()
            if error > scene.numerics.accuracy]
    if over:
        print(f"warning: dt {scene.numerics.dt:g} s may miss the accuracy (time-stepping engines) "
              f"{scene.numerics.accuracy:g}: predicted {' and '.join(over)}", file=sys.stderr)


def _no_work(s: Summary) -> str:
    """The text for an ok run's undefined efficiency (no work transmitted or lost), instead of 'nan'."""
    return f"undefined (input work {number(s.input_work, '.3g')} J)"


def _flow(s: Summary) -> str:
    """The direction of the power flow, when it is not the paper's (input to output)."""
    if s.power_flow in (None, "input_to_output"):
        return ""
    return f", power flow {s.power_flow}"


def _error_text(s: Summary) -> str:
    """`` +- 2.1e-04 (estimated, accuracy met)`` after the mean efficiency; empty without one."""
    if s.efficiency_error_estimate is None:
        return ""
    met = {True: "accuracy met", False: "ACCURACY NOT MET"}.get(s.accuracy_met, "no target")
    return f" +- {s.efficiency_error_estimate:.2g} (estimated, {met})"


def _set_text(s: Summary) -> str:
    """`` (physical parameter set)`` after the scene name; empty for a scene not the paper's."""
    label = s.scene.get("parameter_set", "")
    if not label:
        return ""
    return " (custom parameter values)" if label == "custom" else f" ({label} parameter set)"


def _print_summary(s: Summary, out: str | None, files: list[str]) -> None:
    """``cardan run``'s report: one line on stdout (warnings and files written on stderr/stdout), or the
    status and reason on stderr for a failed run."""
    if s.status != Status.OK:
        print(f"status: {s.status}: {s.reason}", file=sys.stderr)
        return
    print(f"scene {s.scene['name']}{_set_text(s)} with {s.engine} {s.engine_version}: "
          f"mean efficiency {number(s.mean_efficiency, '.6f', _no_work(s))}{_error_text(s)}{_flow(s)} "
          f"(time average of eq. (18): {number(s.mean_instantaneous_efficiency, '.6f', 'undefined')}) "
          f"over {s.revolutions} revolutions; dt {number(s.dt, '.3g')} s, "
          f"{s.steps} steps, {s.wall_time_s:.3g} s wall")
    for warning in s.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    if out:
        print("wrote " + " and ".join(f"{out}/{name}" for name in files))


def cmd_scene(args: argparse.Namespace) -> int:
    """``cardan scene``: the resolved scene as TOML on stdout."""
    import tomli_w  # import cost: only this command writes TOML

    scene = scene_from_args(args)
    print(tomli_w.dumps(scene_to_dict(scene)), end="")
    return EXIT_OK


def sweep_spec_from_args(args: argparse.Namespace) -> SweepSpec:
    """The sweep spec of ``cardan sweep``: the SPEC file with the command-line options applied;
    ``SweepError`` for a bad spec, :class:`BadInput` for a ``--grid``/``--set`` not ``PATH=VALUE``."""
    # import cost: the sweep package (process pools, Dask hooks) loads for `cardan sweep` only
    from cardan_exudyn.sweep import SweepError, looks_like_path, read_spec_file, spec_from_mapping

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
    """``cardan sweep``: exit 0 when no case failed, 3 when one did, 4 when the sweep stopped."""
    from cardan_exudyn.sweep import SweepError, SweepIncomplete, run_sweep  # as above

    out_folder(args.out, replace=False)
    try:
        spec = sweep_spec_from_args(args)
        summary = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                            restart=args.restart, retry_failed=args.retry_failed,
                            progress=False if args.quiet else None, batch_size=args.batch_size)
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


CORE_COMMANDS = ("run", "sweep", "scene")
"""The commands this module defines; the studies' and other packages' are registered after them."""


def build_parser(core_only: bool = False) -> argparse.ArgumentParser:
    """The ``cardan`` parser: core commands, then (unless ``core_only``) the studies' and other
    packages' commands."""
    parser = _Parser(
        prog="cardan", description="Mechanical efficiency of Cardan joints with Exudyn.")
    sub = parser.add_subparsers(dest="command", required=True)
    add_run_parser(sub)
    add_sweep_parser(sub)
    add_scene_parser(sub)
    if not core_only:
        _add_study_commands(sub)
        _add_plugin_commands(sub)
    return parser


def add_run_parser(sub: argparse._SubParsersAction) -> None:
    """``cardan run``."""
    p = sub.add_parser("run", help="simulate one scene")
    add_scene_options(p)
    p.add_argument("--engine", default="exudyn",
                   help="exudyn (default), reference, or mujoco (frictionless; optional extra)")
    p.add_argument("--richardson", action="store_true",
                   help="run at the step and at half of it and report the Richardson-extrapolated "
                        "histories (frictionless scenes; scene field numerics.richardson)")
    p.add_argument("--projection", action="store_true",
                   help="exudyn: velocities projected onto the velocity constraints (exact speed "
                        "ratio; option velocity_projection)")
    p.add_argument("--out", metavar="DIR", help="write timeseries.csv and summary.json here")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.set_defaults(func=cmd_run)


def add_sweep_parser(sub: argparse._SubParsersAction) -> None:
    """``cardan sweep``."""
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
    p.add_argument("--batch-size", type=count("--batch-size"), metavar="N",
                   help="most cases per batch of an engine with a batched pass (the reference engine; "
                        "default 1000, fewer when each worker would get under four batches; 1: every "
                        "case on its own)")
    p.add_argument("--restart", action="store_true", help="discard the records in --out and start over")
    p.add_argument("--retry-failed", action="store_true", help="rerun the cases recorded as failed")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no closing line")
    p.add_argument("--json", action="store_true", help="print the sweep summary as JSON on stdout")
    p.set_defaults(func=cmd_sweep)


def add_scene_parser(sub: argparse._SubParsersAction) -> None:
    """``cardan scene``."""
    p = sub.add_parser("scene", help="print the fully resolved scene as TOML")
    add_scene_options(p)
    p.set_defaults(func=cmd_scene)


def _add_study_commands(sub: argparse._SubParsersAction) -> None:
    """The subcommands the study modules register (:data:`cardan_exudyn.studies.COMMANDS`)."""
    for module in COMMANDS.values():
        importlib.import_module(f"cardan_exudyn.studies.{module}").register(sub)


def _add_plugin_commands(sub: argparse._SubParsersAction) -> None:
    """Commands of the ``cardan.commands`` entry points (``cardan rig``); this package never imports them."""
    from importlib.metadata import entry_points  # import cost: ~30 ms, for these commands only

    for entry in sorted(entry_points(group="cardan.commands"), key=lambda e: e.name):
        entry.load()(sub)


def main(argv: list[str] | None = None) -> int:
    """Run the ``cardan`` command ``argv`` (default: the process's arguments); the exit status.
    SIGTERM raises :class:`cardan_exudyn.interrupts.Terminated` (exit 143), so it stops as Ctrl-C does."""
    args = parse_args(argv)
    with terminate_raises():
        return _run_command(args)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The parsed command line ``argv``, itself kept as ``argv`` (for reports); a core command is parsed
    without the study modules and entry points (import cost)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(core_only=bool(argv) and argv[0] in CORE_COMMANDS).parse_args(argv)
    args.argv = argv
    return args


def _run_command(args: argparse.Namespace) -> int:
    """Run the parsed command; its exit status, every expected error reported in one line."""
    try:
        with _holding_output(args):
            status = args.func(args)
            sys.stdout.flush()  # a reader that went away shows here, not at interpreter exit
        return status
    except (SceneError, OptionsError, EngineUnavailable, BadInput, OutputError) as exc:
        print(f"cardan {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM (Terminated), a sweep's SweepInterrupted
        what = "terminated" if isinstance(exc, Terminated) or exit_status(exc) != 130 else "interrupted"
        print(f"cardan {args.command}: {what}" + (f": {exc}" if str(exc) else ""), file=sys.stderr)
        return exit_status(exc)  # 128 + the signal: 130 Ctrl-C, 143 SIGTERM
    except BrokenPipeError:
        _discard_stdout()
        return EXIT_BROKEN_PIPE
    except OSError as exc:
        if exc.errno not in WRITE_ERRORS:
            raise
        print(f"cardan {args.command}: error: {write_error(exc, exc.filename or 'the output')}",
              file=sys.stderr)
        return EXIT_BAD_INPUT


@contextlib.contextmanager
def _holding_output(args: argparse.Namespace) -> Iterator[None]:
    """Hold the command's ``--out`` lock from its start, so a second writer is refused at once (a folder
    not made yet is locked by its writer; a path the command refuses is left to it)."""
    out = getattr(args, "out", None)
    if not isinstance(out, str) or not out.strip() or Path(out).name in ("", ".", "..") \
            or not Path(out).parent.is_dir():
        yield
        return
    with output_lock(out):
        yield


def _discard_stdout() -> None:
    """Point stdout at the null device so the last flush after a closed pipe raises no second
    BrokenPipeError (the recipe of Python's ``signal`` docs)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)


if __name__ == "__main__":
    sys.exit(main())
