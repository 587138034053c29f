"""The scene options of the ``cardan`` commands (``--name``, ``--angle``, ``--dt``, ...) and the
scene they describe: the named or loaded scene with the overrides applied, named after them."""

from __future__ import annotations

import argparse
import dataclasses
import re
from typing import Any

from cardan_exudyn.arguments import number
from reference.paper.scenes import named_scene
from reference.scene.files import load_scene
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM, SceneError

__all__ = ["DEFAULT_SCENE", "SCENE_OPTIONS", "LEAVE_OUT", "add_scene_options", "scene_from_args",
           "override_name"]

DEFAULT_SCENE = "paper-10deg-2000rpm"
"""The scene of ``cardan run`` without ``--name`` or ``--scene``: the paper's joint with friction
under the default (physical) parameter set."""
SCENE_OPTIONS = ("scene", "name", "angle", "rpm", "load_torque", "friction_spider", "friction_frame",
                 "coupling", "friction_law", "sign_band", "sign_band_relative", "no_gravity", "dt",
                 "accuracy", "revolutions")
"""Destinations of :func:`add_scene_options` (None or False when not given)."""
SPIDER_PAIRS = ("input_spider", "spider_output")
"""The pairs ``--friction-spider`` sets (the paper's f1)."""
FRAME_PAIRS = ("frame_input", "output_frame")
"""The pairs ``--friction-frame`` sets (the paper's f2)."""
_VALUE_OPTIONS = (("coupling", "friction.coupling", "coupling", ""),
                  ("friction_law", "friction.law", "friction_law", ""),
                  ("sign_band", "friction.sign_band", "sign_band", ""),
                  ("sign_band_relative", "friction.sign_band_relative", "sign_band_relative", ""),
                  ("dt", "numerics.dt", "dt", "s"),
                  ("accuracy", "numerics.accuracy", "accuracy", ""),
                  ("revolutions", "revolutions", "revolutions", ""))
"""Options that set one scene field as given: destination, scene path, label, unit in the label."""
_TOKENS = {"angle": re.compile(r"^\d+(?:\.\d+)?deg$"), "rpm": re.compile(r"^\d+(?:\.\d+)?rpm$")}


def _add_source_options(p: argparse.ArgumentParser, default: str) -> None:
    """``--scene FILE`` or ``--name NAME`` (``default``: what the command takes without one)."""
    src = p.add_mutually_exclusive_group()
    src.add_argument("--scene", metavar="FILE", help="scene TOML file")
    src.add_argument("--name", metavar="NAME",
                     help=f"named scene, e.g. paper-35deg, paper-literal-10deg-500rpm, rig-errors (parameter "
                          f"sets physical, literal, matched; default {default})")


def _add_friction_options(p: argparse.ArgumentParser, offered: set[str]) -> None:
    """The friction coefficients and coupling (those of ``offered``), law and sign band."""
    if "friction_spider" in offered:
        p.add_argument("--friction-spider", metavar="F", type=number("-", non_negative=True),
                       help="friction coefficient of the two spider pairs (the paper's f1)")
    if "friction_frame" in offered:
        p.add_argument("--friction-frame", metavar="F", type=number("-", non_negative=True),
                       help="friction coefficient of the two frame pairs (the paper's f2)")
    if "coupling" in offered:
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


LEAVE_OUT = ("angle", "rpm", "load_torque", "friction_spider", "friction_frame", "coupling", "dt",
             "accuracy", "revolutions")
"""Destinations of :data:`SCENE_OPTIONS` a command may set itself (:func:`add_scene_options`)."""


def add_scene_options(p: argparse.ArgumentParser, *, default: str | None = None,
                      leave_out: tuple[str, ...] = ()) -> None:
    """Add the scene options (:data:`SCENE_OPTIONS`) to parser ``p``; ``default`` is what ``--name``
    says the command takes without one; ``leave_out`` (of :data:`LEAVE_OUT`, else ``ValueError``)
    the options the command sets itself, not offered and None when parsed."""
    if not set(leave_out) <= set(LEAVE_OUT):
        raise ValueError(f"`leave_out` must name options of {list(LEAVE_OUT)}, got {leave_out!r}")
    offered = set(SCENE_OPTIONS) - set(leave_out)
    p.set_defaults(**{dest: None for dest in leave_out})
    _add_source_options(p, default or f"{DEFAULT_SCENE}, physical set")
    if "angle" in offered:
        p.add_argument("--angle", metavar="DEG", type=number("deg"), help="shaft angle [deg]")
    if "rpm" in offered:
        p.add_argument("--rpm", metavar="RPM", type=number("rpm"),
                       help="constant input speed [rpm] (makes the drive a constant-speed drive)")
    if "load_torque" in offered:
        p.add_argument("--load-torque", metavar="NM", type=number("N m"),
                       help="resisting torque on the output shaft [N m]")
    _add_friction_options(p, offered)
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off")
    _add_numerics_options(p, offered)


def _add_numerics_options(p: argparse.ArgumentParser, offered: set[str]) -> None:
    """The step, the accuracy and the revolutions (those of ``offered``)."""
    if "dt" in offered:
        p.add_argument("--dt", metavar="S", type=number("s", positive=True),
                       help="time step [s] (default: chosen from the scene to meet --accuracy)")
    if "accuracy" in offered:
        p.add_argument("--accuracy", metavar="E", type=number("-", positive=True),
                       help="target absolute error of the mean efficiency (and relative error of "
                            "omega_out/omega_in; default 1e-3): the step is chosen to meet it, and a "
                            "run whose estimated error exceeds it says so (exit 5)")
    if "revolutions" in offered:
        p.add_argument("--revolutions", metavar="N", type=number("-", positive=True),
                       help="input revolutions to simulate")


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The scene named or loaded by the options with the overrides applied and named after them
    (``--angle 45`` on ``paper-10deg-2000rpm`` is ``paper-45deg-2000rpm``); ``SceneError`` if refused."""
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
    """The named scene built at the ``--angle``/``--rpm`` ``labels`` when it is one of the paper's, so its
    parameter set's choices (the load giving the case's mean input torque) fit that angle and speed."""
    scene = named_scene(name)
    tokens = [(k, text) for k, text in labels if k in ("angle", "rpm") and not text.startswith("-")]
    if not scene.parameter_set or not tokens:
        return scene
    try:
        return named_scene(override_name(scene.name, tokens))
    except SceneError:
        return scene  # not a name the paper's scenes take (e.g. 92 deg): the override will say why


def _drive_overrides(args: argparse.Namespace, changes: dict[str, Any],
                     labels: list[tuple[str, str]]) -> None:
    """Add the angle, speed and load overrides and their labels."""
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


def _overrides(args: argparse.Namespace) -> tuple[dict[str, Any], list[tuple[str, str]]]:
    """The scene changes (dotted path -> value) and their labels (key, value text) for the name."""
    changes: dict[str, Any] = {}
    labels: list[tuple[str, str]] = []
    _drive_overrides(args, changes, labels)
    for option, pairs in (("friction_spider", SPIDER_PAIRS), ("friction_frame", FRAME_PAIRS)):
        value = getattr(args, option)
        if value is not None:
            for pair in pairs:
                changes[f"joint.pairs.{pair}.friction_coefficient"] = value
    for option, key, label, unit in _VALUE_OPTIONS:
        value = getattr(args, option)
        if value is not None:
            changes[key] = value
            labels.append((label, value if isinstance(value, str) else f"{value:g}{unit}"))
    if args.no_gravity:
        changes["gravity"] = [0.0, 0.0, 0.0]
        labels.append(("no_gravity", ""))
    return changes, labels


def _friction_labels(scene: Scene) -> list[tuple[str, str]]:
    """Both groups' friction labels after an override: ``f_spider=0.42``, or ``0.1/0.2`` when the pairs
    of a group differ."""
    pairs = dict(scene.joint.pairs.items())
    out = []
    for label, names in (("f_spider", SPIDER_PAIRS), ("f_frame", FRAME_PAIRS)):
        values = [f"{pairs[n].friction_coefficient:g}" for n in names]
        out.append((label, values[0] if values[0] == values[1] else "/".join(values)))
    return out


def override_name(name: str, labels: list[tuple[str, str]], frictionless: bool | None = None) -> str:
    """``name`` with the overrides ``labels`` ((key, value text) pairs): an ``angle``/``rpm`` replaces
    its part (``paper-10deg-2000rpm`` -> ``paper-45deg-2000rpm``), ``frictionless`` False drops a
    ``frictionless`` part, other labels append as ``+key=value`` (``+load=3Nm``, ``+no_gravity``)."""
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
