"""Command-line argument parsing shared by every ``cardan`` subcommand (the CLI and the commands
that studies and ``rigdata`` register): number and count parsers that give one-line errors, the
scene options and the scene they describe, output-folder checks.

Exit status of every command: 0 success; 2 bad input (one line on stderr naming the argument, no
traceback); 3 the simulation failed or is physically meaningless (the reason is in the summary
``status``); 4 (``cardan sweep``) the sweep stopped before every case ran (rerun to resume); 5
(``cardan run``) the run ended ok but its estimated mean-efficiency error exceeds the target
``--accuracy`` (summary ``accuracy_met`` false; ``docs/accuracy.md``).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import sys
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

from cardan_exudyn.outputs import OutputError, check_output_folder
from reference.paper.scenes import named_scene
from reference.scene.files import load_scene
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM, SceneError

__all__ = ["EXIT_OK", "EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_INCOMPLETE", "EXIT_INACCURATE",
           "EXIT_INTERRUPTED",
           "DEFAULT_SCENE", "BadInput", "out_folder", "number", "count", "cli_value",
           "path_value", "add_scene_options", "scene_from_args", "override_name", "COUNT_LIMITS",
           "MAX_COUNT", "SCENE_OPTIONS", "refuse_options"]

EXIT_OK, EXIT_BAD_INPUT, EXIT_FAILED = 0, 2, 3
EXIT_INCOMPLETE = 4
EXIT_INACCURATE = 5
EXIT_INTERRUPTED = 130
DEFAULT_SCENE = "paper-10deg-2000rpm"
"""The scene of ``cardan run`` without ``--name`` or ``--scene``: the paper's joint with friction
under the default (physical) parameter set."""


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


def number(kind: str, *, positive: bool = False, non_negative: bool = False,
           maximum: float | None = None):
    """Parser of a finite number option (unit ``kind``), optionally positive, non-negative or at
    most ``maximum``."""
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
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"must be at most {maximum:g} ({kind}), got {text!r}")
        return value

    return parse


COUNT_LIMITS = {"--samples": 100_000, "--workers": 1024, "--repeats": 1000, "--mc": 100_000,
                "--pulses-per-rev": 1_000_000, "--cells": 1_000_000, "--seed": 2**63 - 1}
"""Largest value of each count option: a value above it would exhaust memory or run for weeks
(100 000 Monte Carlo samples or draws already pin a 95 % interval to about 1e-3 of its width;
no machine here has 1024 cores). Options not listed take at most :data:`MAX_COUNT`."""
MAX_COUNT = 1_000_000


def count(name: str, minimum: int = 1, maximum: int | None = None):
    """Parser of an integer option ``name`` in [``minimum``, ``maximum``] (default maximum: the
    option's :data:`COUNT_LIMITS` entry, else :data:`MAX_COUNT`); ``1e3`` is read as 1000."""
    top = maximum if maximum is not None else COUNT_LIMITS.get(name, MAX_COUNT)

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            try:
                as_float = float(text)
            except ValueError:
                as_float = math.nan
            if not (math.isfinite(as_float) and as_float.is_integer()):
                raise argparse.ArgumentTypeError(f"expected an integer ({name}), got {text!r}") from None
            value = int(as_float)
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum} ({name}), got {text!r}")
        if value > top:
            raise argparse.ArgumentTypeError(f"must be at most {top} ({name}), got {text!r}")
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


SCENE_OPTIONS = ("scene", "name", "angle", "rpm", "load_torque", "friction_spider", "friction_frame",
                 "coupling", "friction_law", "sign_band", "sign_band_relative", "no_gravity", "dt",
                 "accuracy", "revolutions")
"""Destinations of :func:`add_scene_options` (None or False when not given)."""


def refuse_options(args: argparse.Namespace, dests: tuple[str, ...] | list[str], why: str) -> None:
    """:class:`BadInput` naming the first option of ``dests`` that was given (not None, not
    False): an option the command would otherwise silently ignore; ``why`` ends the message."""
    for dest in dests:
        value = getattr(args, dest, None)
        if value is not None and value is not False:
            raise BadInput(f"--{dest.replace('_', '-')} does not apply {why}")


def add_scene_options(p: argparse.ArgumentParser) -> None:
    src = p.add_mutually_exclusive_group()
    src.add_argument("--scene", metavar="FILE", help="scene TOML file")
    src.add_argument("--name", metavar="NAME",
                     help=f"named scene, e.g. paper-35deg, paper-literal-10deg-500rpm, rig-errors (parameter "
                          f"sets physical, literal, matched; default {DEFAULT_SCENE}, physical set)")
    p.add_argument("--angle", metavar="DEG", type=number("deg"), help="shaft angle [deg]")
    p.add_argument("--rpm", metavar="RPM", type=number("rpm"),
                   help="constant input speed [rpm] (makes the drive a constant-speed drive)")
    p.add_argument("--load-torque", metavar="NM", type=number("N m"),
                   help="resisting torque on the output shaft [N m]")
    p.add_argument("--friction-spider", metavar="F", type=number("-", non_negative=True),
                   help="friction coefficient of the two spider pairs (the paper's f1)")
    p.add_argument("--friction-frame", metavar="F", type=number("-", non_negative=True),
                   help="friction coefficient of the two frame pairs (the paper's f2)")
    p.add_argument("--coupling", choices=("extrapolated", "converged", "lagged"),
                   help="friction coupling: one Newton solve per step on extrapolated law inputs "
                        "(default), iterated to the fixed point per step, or lagged one step "
                        "(the paper's)")
    p.add_argument("--friction-law", choices=("paper", "resultant"),
                   help="friction of a pair that rotates and slides: the paper's eqs. (3), (5), "
                        "a full Coulomb load in each direction (default), or one Coulomb force "
                        "against the resultant slip velocity")
    band = p.add_mutually_exclusive_group()
    band.add_argument("--sign-band", metavar="M_S", type=number("m/s", non_negative=True),
                      help="one absolute surface speed [m/s] below which sign() of eqs. (3), (5) "
                           "is a linear ramp, for every pair (0: exact sign)")
    band.add_argument("--sign-band-relative", metavar="R", type=number("-", non_negative=True),
                      help="each pair's ramp as a fraction of its own RMS speed (default 1e-3; "
                           "0: exact sign)")
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off")
    p.add_argument("--dt", metavar="S", type=number("s", positive=True),
                   help="time step [s] (default: chosen from the scene to meet --accuracy)")
    p.add_argument("--accuracy", metavar="E", type=number("-", positive=True),
                   help="target absolute error of the mean efficiency (and relative error of "
                        "omega_out/omega_in; default 1e-3): the step is chosen to meet it, and a "
                        "run whose estimated error exceeds it says so (exit 5)")
    p.add_argument("--revolutions", metavar="N", type=number("-", positive=True),
                   help="input revolutions to simulate")


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The scene named or loaded by the options, with the command-line overrides applied and
    named after them (:func:`override_name`): ``--angle 45`` on ``paper-10deg-2000rpm`` is
    ``paper-45deg-2000rpm``, ``--load-torque 3`` adds ``+load=3Nm``."""
    changes, labels = _overrides(args)
    if args.scene is not None:
        scene = load_scene(args.scene)
    else:
        scene = _named(DEFAULT_SCENE if args.name is None else args.name, labels)
    if not changes:
        return scene
    try:
        changed = replace(scene, **changes)
    except SceneError as exc:
        raise SceneError(f"{exc} (after the command-line overrides)") from None
    if args.friction_spider is not None or args.friction_frame is not None:
        labels += _friction_labels(changed)
    name = override_name(scene.name, labels, frictionless=not changed.has_friction)
    described = ", ".join(f"{k}={v}" if v else k for k, v in labels)
    description = f"{scene.description}; command-line overrides: {described}".lstrip("; ")
    return dataclasses.replace(changed, name=name, description=description)


def _named(name: str, labels: list[tuple[str, str]]) -> Scene:
    """The named scene, built at the ``--angle`` and ``--rpm`` asked for (their ``labels``) when it
    is one of the paper's (so that its parameter set's choices, such as the load that gives the
    case's mean input torque, are made for that angle and speed; the override then changes
    nothing)."""
    scene = named_scene(name)
    tokens = [(k, text) for k, text in labels if k in ("angle", "rpm") and not text.startswith("-")]
    if not scene.parameter_set or not tokens:
        return scene
    try:
        return named_scene(override_name(scene.name, tokens))
    except SceneError:
        return scene  # not a name the paper's scenes take (e.g. 92 deg): the override will say why


def _overrides(args: argparse.Namespace) -> tuple[dict[str, Any], list[tuple[str, str]]]:
    """The scene changes the options ask for, and their labels (key, value text) for the name."""
    changes: dict[str, Any] = {}
    labels: list[tuple[str, str]] = []
    if args.angle is not None:
        changes["joint.geometry.shaft_angle"] = args.angle * DEG
        labels.append(("angle", f"{args.angle:g}deg"))
    if args.rpm is not None:
        changes["drive"] = {"kind": "speed", "speed": args.rpm * RPM}
        labels.append(("rpm", f"{args.rpm:g}rpm"))
    if args.load_torque is not None:
        changes["load.torque"] = args.load_torque
        changes["load.time"] = None  # a constant torque replaces any history
        labels.append(("load", f"{args.load_torque:g}Nm"))
    for option, pairs in (("friction_spider", ("input_spider", "spider_output")),
                          ("friction_frame", ("frame_input", "output_frame"))):
        value = getattr(args, option)
        if value is not None:
            for pair in pairs:
                changes[f"joint.pairs.{pair}.friction_coefficient"] = value
    for option, key, label, unit in (("coupling", "friction.coupling", "coupling", ""),
                                     ("friction_law", "friction.law", "friction_law", ""),
                                     ("sign_band", "friction.sign_band", "sign_band", ""),
                                     ("sign_band_relative", "friction.sign_band_relative",
                                      "sign_band_relative", ""),
                                     ("dt", "numerics.dt", "dt", "s"),
                                     ("accuracy", "numerics.accuracy", "accuracy", ""),
                                     ("revolutions", "revolutions", "revolutions", "")):
        value = getattr(args, option)
        if value is not None:
            changes[key] = value
            labels.append((label, value if isinstance(value, str) else f"{value:g}{unit}"))
    if args.no_gravity:
        changes["gravity"] = [0.0, 0.0, 0.0]
        labels.append(("no_gravity", ""))
    return changes, labels


def _friction_labels(scene: Scene) -> list[tuple[str, str]]:
    """The friction coefficients of the spider and frame pairs after an override (both, so that
    the name says what the other group has): ``f_spider=0.42``, or ``0.1/0.2`` when the two
    pairs of a group differ."""
    pairs = dict(scene.joint.pairs.items())
    out = []
    for label, names in (("f_spider", ("input_spider", "spider_output")),
                         ("f_frame", ("frame_input", "output_frame"))):
        values = [f"{pairs[n].friction_coefficient:g}" for n in names]
        out.append((label, values[0] if values[0] == values[1] else "/".join(values)))
    return out


_TOKENS = {"angle": re.compile(r"^\d+(?:\.\d+)?deg$"), "rpm": re.compile(r"^\d+(?:\.\d+)?rpm$")}


def override_name(name: str, labels: list[tuple[str, str]], frictionless: bool | None = None) -> str:
    """A scene name that says what was overridden: a shaft angle (``angle``) or speed (``rpm``)
    replaces the one part of ``name`` that gives it (``paper-10deg-2000rpm`` -> ``paper-45deg-
    2000rpm``); a ``frictionless`` part goes when the scene has friction after all
    (``frictionless`` False); every other label is appended as ``+key=value`` (``+load=3Nm``,
    ``+f_spider=0.42``, ``+no_gravity``).

    Parameters
    ----------
    name : str
        The base scene's name.
    labels : list of (str, str)
        Override key and its value with unit (empty for a flag), in order.
    frictionless : bool, optional
        Whether the scene is frictionless after the overrides (None: not changed).
    """
    parts = name.split("-")
    extra = []
    for key, text in labels:
        token = _TOKENS.get(key)
        where = [i for i, p in enumerate(parts) if token is not None and token.match(p)]
        if len(where) == 1:  # a negative value in brackets, not read as a separator
            parts[where[0]] = f"({text})" if text.startswith("-") else text
        else:
            extra.append(text if token is not None else f"{key}={text}" if text else key)
    if frictionless is False and "frictionless" in parts:
        parts.remove("frictionless")
    return "-".join(parts) + "".join(f"+{e}" for e in extra)
