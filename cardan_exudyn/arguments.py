"""Command-line argument parsing shared by every ``cardan`` subcommand (the CLI and the commands
that studies and ``rigdata`` register): number and count parsers that give one-line errors, the
scene options and the scene they describe, output-folder checks.

Exit status of every command: 0 success; 2 bad input (one line on stderr naming the argument, no
traceback); 3 the simulation failed or is physically meaningless (the reason is in the summary
``status``); 4 (``cardan sweep``) the sweep stopped before every case ran (rerun to resume).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

from cardan_exudyn.io import OutputError, check_output_folder
from reference.paper import named_scene
from reference.scene import Scene, replace
from reference.scene_files import load_scene
from reference.validation import DEG, RPM, SceneError

__all__ = ["EXIT_OK", "EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_INCOMPLETE", "EXIT_INTERRUPTED",
           "DEFAULT_SCENE", "BadInput", "out_folder", "number", "count", "cli_value",
           "path_value", "add_scene_options", "scene_from_args"]

EXIT_OK, EXIT_BAD_INPUT, EXIT_FAILED = 0, 2, 3
EXIT_INCOMPLETE = 4
EXIT_INTERRUPTED = 130
DEFAULT_SCENE = "paper-10deg-frictionless"


class BadInput(Exception):
    """Raised for invalid command-line input; printed as one line, exit status 2."""


def out_folder(path: str | None, option: str = "--out", replace: bool = True) -> None:
    """Refuse an output folder that cannot be one before anything runs (exit 2); ``replace``: the
    command replaces the folder as a whole (not a sweep, which writes into it)."""
    if path is not None and not path.strip():
        raise BadInput(f"{option} is empty: give a folder")
    if path:
        try:
            check_output_folder(path, replace=replace)
        except OutputError as exc:
            raise BadInput(f"{option}: {exc}") from None


def number(kind: str, *, positive: bool = False, non_negative: bool = False):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number ({kind}), got {text!r}") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"expected a finite number ({kind}), got {text!r}")
        if positive and value <= 0:
            raise argparse.ArgumentTypeError(f"must be positive ({kind}), got {text!r}")
        if non_negative and value < 0:
            raise argparse.ArgumentTypeError(f"must be >= 0 ({kind}), got {text!r}")
        return value

    return parse


def count(name: str, minimum: int = 1):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer ({name}), got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum} ({name}), got {text!r}")
        return value

    return parse


def cli_value(text: str) -> Any:
    """A TOML value (number, boolean, quoted string, array), else the text itself."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def path_value(option: str, text: str, form: str) -> tuple[str, str]:
    path, sep, value = text.partition("=")
    if not sep or not path.strip() or not value.strip():
        raise BadInput(f"{option} must look like {form}, got {text!r}")
    return path.strip(), value


def add_scene_options(p: argparse.ArgumentParser) -> None:
    src = p.add_mutually_exclusive_group()
    src.add_argument("--scene", metavar="FILE", help="scene TOML file")
    src.add_argument("--name", metavar="NAME",
                     help=f"named scene, e.g. paper-10deg-2000rpm, rig (default {DEFAULT_SCENE})")
    p.add_argument("--angle", metavar="DEG", type=number("deg"), help="shaft angle [deg]")
    p.add_argument("--rpm", metavar="RPM", type=number("rpm"),
                   help="constant input speed [rpm] (makes the drive a constant-speed drive)")
    p.add_argument("--load-torque", metavar="NM", type=number("N m"),
                   help="resisting torque on the output shaft [N m]")
    p.add_argument("--friction-spider", metavar="F", type=number("-", non_negative=True),
                   help="friction coefficient of the two spider pairs (the paper's f1)")
    p.add_argument("--friction-frame", metavar="F", type=number("-", non_negative=True),
                   help="friction coefficient of the two frame pairs (the paper's f2)")
    p.add_argument("--coupling", choices=("converged", "lagged"),
                   help="friction coupling: converged per step (default) or lagged one step "
                        "(the paper's)")
    p.add_argument("--sign-band", metavar="M_S", type=number("m/s", non_negative=True),
                   help="surface speed [m/s] below which sign() of eqs. (3), (5) is a linear ramp")
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off")
    p.add_argument("--dt", metavar="S", type=number("s", positive=True),
                   help="time step [s] (default: chosen from the scene to meet --accuracy)")
    p.add_argument("--accuracy", metavar="E", type=number("-", positive=True),
                   help="target max error of omega_out/omega_in when --dt is not given")
    p.add_argument("--revolutions", metavar="N", type=number("-", positive=True),
                   help="input revolutions to simulate")


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The scene named or loaded by the options, with the command-line overrides applied."""
    if args.scene is not None:
        scene = load_scene(args.scene)
    else:
        scene = named_scene(DEFAULT_SCENE if args.name is None else args.name)
    changes: dict[str, Any] = {}
    if args.angle is not None:
        changes["joint.geometry.shaft_angle"] = args.angle * DEG
    if args.rpm is not None:
        changes["drive"] = {"kind": "speed", "speed": args.rpm * RPM}
    if args.load_torque is not None:
        changes["load.torque"] = args.load_torque
        changes["load.time"] = None  # a constant torque replaces any history
    for option, pairs in (("friction_spider", ("input_spider", "spider_output")),
                          ("friction_frame", ("frame_input", "output_frame"))):
        value = getattr(args, option)
        if value is not None:
            for pair in pairs:
                changes[f"joint.pairs.{pair}.friction_coefficient"] = value
    if args.coupling is not None:
        changes["friction.coupling"] = args.coupling
    if args.sign_band is not None:
        changes["friction.sign_band"] = args.sign_band
    if args.no_gravity:
        changes["gravity"] = [0.0, 0.0, 0.0]
    if args.dt is not None:
        changes["numerics.dt"] = args.dt
    if args.accuracy is not None:
        changes["numerics.accuracy"] = args.accuracy
    if args.revolutions is not None:
        changes["revolutions"] = args.revolutions
    if not changes:
        return scene
    try:
        return replace(scene, **changes)
    except SceneError as exc:
        raise SceneError(f"{exc} (after the command-line overrides)") from None
