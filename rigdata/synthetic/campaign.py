"""A synthetic validation campaign: labelled rig recordings at several operating points, half for
calibration and half for validation, and the ``campaign.toml`` that lists them.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.outputs import atomic_open
from reference.scene.joint import PAIR_NAMES
from rigdata.synthetic.rig import EXTENSIONS, FORMATS, RigSettings, write
from rigdata.transducer import Transducer

__all__ = ["CAMPAIGN_TRANSDUCER", "DEFAULT_POINTS", "POINT_KEYS", "USES", "write_campaign"]

CAMPAIGN_TRANSDUCER = Transducer(full_scale=5.0, accuracy_class=5e-4)
"""Assumption: a 5 N m in-line transducer of class 0.05 % on each shaft (zero drift, sensitivity and
pulses as :class:`Transducer`'s defaults), sized for loads of 1-3 N m, where the paper's 100 N m
transducer of class 0.1 % would not resolve an efficiency of 0.98-0.995."""

#: The keys of an operating point: required, then optional (with the :class:`RigSettings` default).
POINT_KEYS = ("shaft_angle_deg", "speed", "input_torque", "use", "format")
OPTIONAL_KEYS = ("speed_channel", "torque_out_sign")
USES = ("calibration", "validation")
"""What a recording is for in the campaign."""

DEFAULT_POINTS = (
    {"shaft_angle_deg": 15.0, "speed": 6.0, "input_torque": 2.0, "use": "calibration"},
    {"shaft_angle_deg": 10.0, "speed": 8.0, "input_torque": 3.0, "use": "validation"},
    {"shaft_angle_deg": 20.0, "speed": 4.0, "input_torque": 1.5, "use": "calibration"},
    {"shaft_angle_deg": 25.0, "speed": 10.0, "input_torque": 1.0, "use": "validation"},
    {"shaft_angle_deg": 25.0, "speed": 8.0, "input_torque": 2.5, "use": "calibration",
     "torque_out_sign": -1},
    {"shaft_angle_deg": 30.0, "speed": 5.0, "input_torque": 1.0, "use": "validation"},
    {"shaft_angle_deg": 30.0, "speed": 10.0, "input_torque": 2.0, "use": "calibration",
     "speed_channel": "rpm"},
    {"shaft_angle_deg": 20.0, "speed": 6.0, "input_torque": 3.0, "use": "validation"},
)
"""The default operating points (shaft angle [deg], mean input speed [rad/s], mean input torque [N m]),
a calibration and a validation point in turn: calibration at 1.5-2.5 N m, validation at 1 and 3 N m, so a
load-dependent model error (a drag the model lacks) shows at the validation points; the 1 N m points sit
at 25-30 deg where the loss (1.4-1.7 % at friction 0.12) is several times the measurement's uncertainty."""

#: What the campaign file asks of the model (read by ``cardan rig campaign``).
ENGINES = ("reference", "exudyn")
COVERAGE = 0.95
FRICTION_START = 0.2
FRICTION_BOUNDS = (0.0, 0.6)


def _points(points: Sequence[Mapping[str, Any]] | None, formats: Sequence[str]) -> list[dict[str, Any]]:
    """The operating points: ``points`` checked, or :data:`DEFAULT_POINTS` with formats assigned in pairs
    (a calibration and a validation point per format)."""
    if points is None:
        if isinstance(formats, str) or not formats or any(f not in FORMATS for f in formats):
            raise ValueError(f"`formats` must be a non-empty sequence of {FORMATS}, got {formats!r:.80}")
        return [{**p, "format": formats[(k // 2) % len(formats)]} for k, p in enumerate(DEFAULT_POINTS)]
    if isinstance(points, (str, Mapping)) or not isinstance(points, Sequence) or not points:
        raise ValueError(f"`points` must be a non-empty list of dicts, got {points!r:.80}")
    return [_point(k, p) for k, p in enumerate(points)]


def _point(k: int, point: object) -> dict[str, Any]:
    """Operating point ``k`` as a dict; ValueError naming the key that is missing, unknown or wrong."""
    if not isinstance(point, Mapping):
        raise ValueError(f"`points[{k}]` must be a dict, got {point!r:.80}")
    missing = [key for key in POINT_KEYS if key not in point]
    unknown = sorted(set(point) - set(POINT_KEYS) - set(OPTIONAL_KEYS))
    if missing or unknown:
        raise ValueError(f"`points[{k}]` needs the keys {POINT_KEYS} (optional {OPTIONAL_KEYS}); "
                         f"missing {missing}, unknown {unknown}")
    if point["use"] not in USES:
        raise ValueError(f"`points[{k}]['use']` must be one of {USES}, got {point['use']!r:.80}")
    if point["format"] not in FORMATS:
        raise ValueError(f"`points[{k}]['format']` must be one of {FORMATS}, got {point['format']!r:.80}")
    return dict(point)


def _seed(seed: int, k: int) -> int:
    """The seed of recording ``k``: independent draws per recording, all from the campaign's ``seed``."""
    return int(np.random.SeedSequence([seed, k]).generate_state(1)[0])


def _settings(k: int, point: Mapping[str, Any], common: Mapping[str, Any]) -> RigSettings:
    """The rig settings of recording ``k``; ValueError naming the point when they are refused."""
    seconds = common["seconds"]
    revolutions = seconds * point["speed"] / (2.0 * math.pi) - 0.25  # a file spans 0.25 more
    try:
        if revolutions < 1.6:
            raise ValueError(f"`seconds` {seconds:g} at {point['speed']:g} rad/s is {revolutions + 0.25:.3g} "
                             f"revolutions; at least 1.85 are needed (1.6 after settling)")
        extra = {key: point[key] for key in OPTIONAL_KEYS if key in point}
        return RigSettings(scene=common["scene"], shaft_angle_deg=point["shaft_angle_deg"],
                           speed=point["speed"], input_torque=point["input_torque"],
                           friction=common["friction"], drag_torque=common["drag_torque"],
                           rate=common["rate"], revolutions=revolutions, seed=_seed(common["seed"], k),
                           **extra)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`points[{k}]`: {exc}") from None


def _name(k: int, point: Mapping[str, Any]) -> str:
    """File name of recording ``k`` (numbered from 1): number, shaft angle [deg], speed [rad/s]."""
    return f"r{k + 1}_b{point['shaft_angle_deg']:g}_w{point['speed']:g}{EXTENSIONS[point['format']]}"


def _string(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(text)


def _inline(table: Mapping[str, Any]) -> str:
    """A TOML inline table of bare keys and numbers."""
    return "{ " + ", ".join(f"{k} = {v!r}" for k, v in table.items()) + " }"


def _recording(name: str, point: Mapping[str, Any]) -> list[str]:
    """The ``[[recording]]`` lines of one file: name, shaft angle, use and the output torque's sign."""
    lines = ["", "[[recording]]",
             f"# {point['format']}, {point['speed']:g} rad/s, {point['input_torque']:g} N m input torque",
             f"file = {_string(name)}", f"shaft_angle_deg = {float(point['shaft_angle_deg'])!r}",
             f"use = {_string(point['use'])}"]
    if point.get("torque_out_sign", 1) == -1:
        lines.append(f"sign = {_inline({'torque_out': -1})}")
    return lines


def _transducer_lines(transducer: Transducer) -> list[str]:
    """The ``[transducers]`` table: full scale and class, and every other field not at :class:`Transducer`'s
    default (the sensitivity and pulses read the files, the others state the uncertainty)."""
    lines = ["", "[transducers]", f"full_scale = {float(transducer.full_scale)!r}",
             f"accuracy_class = {float(transducer.accuracy_class)!r}"]
    default = Transducer()
    for key, value in transducer.as_dict().items():
        if key not in ("full_scale", "accuracy_class") and value != getattr(default, key):
            lines.append(f"{key} = {value!r}")
    return lines


def _toml(common: Mapping[str, Any], transducer: Transducer, recordings: list[list[str]]) -> str:
    """The text of ``campaign.toml``."""
    keys = [_string(f"joint.pairs.{p}.friction_coefficient") for p in PAIR_NAMES]
    lines = [f"# SYNTHETIC campaign written by rigdata.synthetic.write_campaign: truth friction "
             f"{common['friction']:g}, drag {common['drag_torque']:g} N m, seed {common['seed']}",
             f"scene = {_string(common['scene'])}",
             "engines = [" + ", ".join(map(_string, ENGINES)) + "]",
             f"coverage = {COVERAGE!r}", "", "[parameters.f]",
             "keys = [" + ", ".join(keys[:2]) + ",", "        " + ", ".join(keys[2:]) + "]",
             f"initial = {FRICTION_START!r}", f"bounds = [{FRICTION_BOUNDS[0]!r}, {FRICTION_BOUNDS[1]!r}]",
             *_transducer_lines(transducer)]
    return "\n".join(lines + [line for rec in recordings for line in rec]) + "\n"


def _common(friction: float, drag_torque: float, seed: int, seconds: float, rate: float,
            scene: str) -> dict[str, Any]:
    """The settings every recording shares; ValueError for a seed or length that is not one."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**63:
        raise ValueError(f"`seed` must be an integer in [0, 2**63), got {seed!r:.80}")
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not (
            math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"`seconds` must be a positive number [s], got {seconds!r:.80}")
    if isinstance(scene, str) and Path(scene).is_file():
        scene = str(Path(scene).resolve())  # the campaign file may be read from another folder
    return {"friction": friction, "drag_torque": drag_torque, "seed": int(seed), "seconds": float(seconds),
            "rate": rate, "scene": scene}


def write_campaign(folder: str | os.PathLike, *, friction: float = 0.12, drag_torque: float = 0.0,
                   seed: int = 0, seconds: float = 12.0, rate: float = 1000.0,
                   formats: Sequence[str] = ("csv", "lvm", "mdf", "mat"),
                   points: Sequence[Mapping[str, Any]] | None = None, scene: str = "rig",
                   transducer: Transducer | None = None) -> Path:
    """Write a synthetic validation campaign: one labelled recording per operating point and
    ``campaign.toml`` listing them (each file and the list replaced atomically, the list last).

    Parameters
    ----------
    folder : str or path-like
        Where the files go (created if missing).
    friction : float
        True friction coefficient of every pair [-].
    drag_torque : float
        Drag between joint and output transducer [N m] (:class:`RigSettings`): a model-form error.
    seed : int
        Seed of every recording's drawn errors and noise (each recording its own stream).
    seconds : float
        Length of each recording [s].
    rate : float
        Sampling rate [Hz].
    formats : sequence of str
        Formats of :data:`DEFAULT_POINTS`, each for a calibration and a validation point in turn
        (csv written with decimal commas); not used with ``points``.
    points : sequence of dict, optional
        Operating points instead of :data:`DEFAULT_POINTS`: ``shaft_angle_deg`` [deg], ``speed`` [rad/s],
        ``input_torque`` [N m], ``use`` (:data:`USES`), ``format``; optional ``speed_channel``,
        ``torque_out_sign``.
    scene : str
        Named scene or scene TOML file of the joint.
    transducer : Transducer, optional
        Both shafts' transducers; default :data:`CAMPAIGN_TRANSDUCER`.

    Returns
    -------
    Path
        ``campaign.toml`` in ``folder``.
    """
    if transducer is not None and not isinstance(transducer, Transducer):
        raise TypeError(f"`transducer` must be a Transducer or None, got {type(transducer).__name__}")
    transducer = transducer or CAMPAIGN_TRANSDUCER
    common = _common(friction, drag_torque, seed, seconds, rate, scene)
    chosen = _points(points, formats)
    settings = [_settings(k, p, common) for k, p in enumerate(chosen)]  # all refused before any is written
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    recordings = []
    for k, (point, rig) in enumerate(zip(chosen, settings, strict=True)):
        name = _name(k, point)
        write(folder / name, point["format"], rig, transducer,
              decimal="," if point["format"] == "csv" else None)
        recordings.append(_recording(name, point))
    path = folder / "campaign.toml"
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(_toml(common, transducer, recordings))
    return path
