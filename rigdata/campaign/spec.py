"""A validation campaign as validated data: the joint, the calibrated parameters, the stated input
uncertainties and the recordings (``CAMPAIGN.toml``; every key in ``docs/rigdata.md``).

Every problem is a :class:`CampaignError` naming the campaign file and the key, found before any
recording is read, so a bad campaign costs nothing.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from reference.scene.files import read_toml
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import SceneError
from rigdata.campaign.recordings import USES, RecordingSpec, parse_recordings, parse_transducer
from rigdata.campaign.values import CampaignError, count, known, number, required, table_of, text
from rigdata.conditioning import Conditioning
from rigdata.montecarlo import check_draws
from rigdata.validation import MODEL_ENGINES, as_scene

__all__ = ["USES", "DISTRIBUTIONS", "MEASURED_KEYS", "SHAFT_ANGLE_KEY", "CampaignError", "Parameter",
           "InputUncertainty", "RecordingSpec", "CampaignSpec", "load_campaign", "campaign_from_mapping",
           "with_values", "scene_value"]

DISTRIBUTIONS = ("normal", "uniform")
"""Distributions of a stated input uncertainty: ``normal`` (``std``) or ``uniform`` (``half_width``)."""
MEASURED_KEYS = ("drive", "load", "revolutions", "record")
"""Scene keys (and the keys under them) that each recording replaces with its measured drive and load: a
parameter or stated input there would change nothing."""
SHAFT_ANGLE_KEY = "joint.geometry.shaft_angle"
"""Each recording's ``shaft_angle_deg``: a stated input may perturb it, one calibrated value cannot be it."""

MAX_INPUT_SAMPLES = 10000
"""The most samples of the sampling check of ``u_input`` (each is one model run per recording)."""
_TOP_KEYS = {"scene", "engines", "coverage", "parameters", "inputs", "transducers", "conditioning",
             "recording", "monte_carlo", "seed", "input_samples", "title"}


@dataclass(frozen=True)
class Parameter:
    """One calibrated parameter: a single value written to every scene key it is tied to.

    Attributes
    ----------
    name : str
    keys : tuple of str
        Dotted scene paths (``joint.pairs.input_spider.friction_coefficient``), SI units.
    initial : float
        Start of the fit.
    bounds : tuple of float
        ``(low, high)``, ``low <= initial <= high``.
    """

    name: str
    keys: tuple[str, ...]
    initial: float
    bounds: tuple[float, float]


@dataclass(frozen=True)
class InputUncertainty:
    """A stated (not calibrated) uncertainty of one scene input.

    Attributes
    ----------
    key : str
        Dotted scene path.
    distribution : {"normal", "uniform"}
    std : float
        Standard uncertainty in the key's SI unit (``half_width / sqrt(3)`` for uniform).
    """

    key: str
    distribution: str
    std: float


@dataclass(frozen=True)
class CampaignSpec:
    """A whole campaign.

    Attributes
    ----------
    path : Path or None
        The campaign file (None when built from a mapping in memory).
    title : str
    scene : Scene
        The joint, friction and numerics; each recording's drive, load and shaft angle replace its own.
    scene_source : str
        The ``scene`` value as written.
    engines : tuple of str
        The first calibrates and propagates; each gives its own simulated efficiency.
    coverage : float
        Coverage probability of the expanded uncertainties (``k`` of a normal distribution).
    parameters : tuple of Parameter
    inputs : tuple of InputUncertainty
    recordings : tuple of RecordingSpec
    conditioning : Conditioning
    monte_carlo : int
        Monte Carlo draws of each measured efficiency (0: GUM only).
    seed : int
    input_samples : int
        Samples of the model inputs per recording to check the sensitivity-coefficient ``u_input``
        (0: sensitivity coefficients only).
    """

    path: Path | None
    title: str
    scene: Scene
    scene_source: str
    engines: tuple[str, ...]
    coverage: float
    parameters: tuple[Parameter, ...]
    inputs: tuple[InputUncertainty, ...]
    recordings: tuple[RecordingSpec, ...]
    conditioning: Conditioning
    monte_carlo: int = 2000
    seed: int = 0
    input_samples: int = 0

    @property
    def calibration(self) -> tuple[RecordingSpec, ...]:
        """The calibration recordings."""
        return tuple(r for r in self.recordings if r.use == "calibration")

    @property
    def initial(self) -> tuple[float, ...]:
        """The parameters' initial values."""
        return tuple(p.initial for p in self.parameters)


def with_values(scene: Scene, parameters: tuple[Parameter, ...], values: tuple[float, ...] | Any,
                changes: Mapping[str, float] | None = None) -> Scene:
    """``scene`` with each parameter's value written to its keys, then ``changes`` (dotted key -> value)."""
    edits = {key: float(value) for p, value in zip(parameters, values, strict=True) for key in p.keys}
    edits.update(changes or {})
    return replace(scene, **edits) if edits else scene


def load_campaign(path: str | os.PathLike) -> CampaignSpec:
    """The campaign of a TOML file; relative ``scene`` and ``file`` paths are relative to it."""
    data = read_toml(path, "campaign file", "a campaign", CampaignError)
    return campaign_from_mapping(data, Path(path).resolve().parent, path=Path(path))


def campaign_from_mapping(data: Mapping[str, Any], base_dir: str | os.PathLike = ".",
                          path: Path | None = None) -> CampaignSpec:
    """The campaign of a parsed table; :class:`CampaignError` naming the file and key of the first problem."""
    where = str(path) if path is not None else "campaign"
    try:
        spec = _campaign(data, Path(base_dir))
    except CampaignError as exc:
        raise CampaignError(f"{where}: {exc}") from None
    return dataclasses.replace(spec, path=path)


def _campaign(data: Mapping[str, Any], base: Path) -> CampaignSpec:
    """:func:`campaign_from_mapping` without the file name in messages."""
    known(data, _TOP_KEYS, "the campaign")
    scene_source = text(data, "scene", "the campaign", default="rig")
    scene = _scene(scene_source, base)
    parameters = _parameters(table_of(data, "parameters"), scene)
    inputs = _inputs(table_of(data, "inputs"), scene, parameters)
    transducer = parse_transducer(table_of(data, "transducers"), "[transducers]")
    recordings = parse_recordings(data.get("recording"), base, transducer)
    draws = _draws(data)
    if parameters and not any(r.use == "calibration" for r in recordings):
        raise CampaignError("[parameters] asks for a calibration but no [[recording]] has "
                            "use = \"calibration\"")
    return CampaignSpec(
        path=None, title=text(data, "title", "the campaign", default=""), scene=scene,
        scene_source=scene_source, engines=_engines(data.get("engines", MODEL_ENGINES)),
        coverage=_coverage(data.get("coverage", 0.95)), parameters=parameters, inputs=inputs,
        recordings=recordings, conditioning=_conditioning(table_of(data, "conditioning")),
        monte_carlo=draws[0], seed=draws[1], input_samples=_samples(data))


def _samples(data: Mapping[str, Any]) -> int:
    """``input_samples``: an integer in [0, MAX_INPUT_SAMPLES]."""
    value = count(data, "input_samples", 0)
    if value > MAX_INPUT_SAMPLES:
        raise CampaignError(f"`input_samples` must be at most {MAX_INPUT_SAMPLES} (each is a model run per "
                            f"recording), got {value}")
    return value


def _draws(data: Mapping[str, Any]) -> tuple[int, int]:
    """``monte_carlo`` and ``seed``, within what the measurement's Monte Carlo takes."""
    monte_carlo = count(data, "monte_carlo", 2000)
    seed = count(data, "seed", 0)
    try:
        check_draws(monte_carlo, seed)
    except ValueError as exc:
        raise CampaignError(str(exc)) from None
    return monte_carlo, seed


def _scene(source: str, base: Path) -> Scene:
    """The campaign's joint: a scene file (relative to the campaign) or a named scene."""
    candidate = base / source
    target = candidate if (source.endswith(".toml") or candidate.is_file()) else source
    try:
        return as_scene(target)
    except (SceneError, KeyError, ValueError, TypeError) as exc:
        raise CampaignError(f"`scene` {source!r}: {exc}") from None


def _engines(value: Any) -> tuple[str, ...]:
    """The engines: a non-empty list of distinct names that take a measured drive and load."""
    if isinstance(value, str) or not isinstance(value, (list, tuple)) or not value:
        raise CampaignError(f"`engines` must be a list of engine names such as {list(MODEL_ENGINES)}, "
                            f"got {value!r:.80}")
    for name in value:
        if name not in MODEL_ENGINES:
            raise CampaignError(f"`engines`: {name!r} cannot be driven by a measurement; use "
                                f"{' and/or '.join(MODEL_ENGINES)}")
    if len(set(value)) != len(value):
        raise CampaignError(f"`engines` names an engine twice: {value!r}")
    return tuple(value)


def _coverage(value: Any) -> float:
    """The coverage probability, in (0, 1)."""
    p = number(value, "`coverage`")
    if not 0.5 <= p < 1.0:
        raise CampaignError(f"`coverage` must be a probability in [0.5, 1), got {value!r}")
    return p


def _scene_key(scene: Scene, key: Any, value: float, where: str, what: str = "is not a number of the scene"
               ) -> None:
    """CampaignError unless ``key`` is a dotted scene path that takes ``value`` (``what``: the complaint)."""
    if not isinstance(key, str) or not key.strip():
        raise CampaignError(f"{where}: a key must be a dotted scene path, got {key!r:.80}")
    if key.split(".")[0] in MEASURED_KEYS:
        raise CampaignError(f"{where}: key {key!r} is replaced by each recording's measured drive and load, "
                            f"as is every key under {', '.join(MEASURED_KEYS)}")
    try:
        replace(scene, **{key: value})
    except (SceneError, TypeError, ValueError, KeyError) as exc:
        raise CampaignError(f"{where}: key {key!r} {what} ({exc})") from None


def _parameters(table: Mapping[str, Any], scene: Scene) -> tuple[Parameter, ...]:
    """The calibrated parameters, each checked against the scene."""
    out = []
    tied: dict[str, str] = {}
    for name, spec in table.items():
        where = f"[parameters.{name}]"
        if not isinstance(spec, Mapping):
            raise CampaignError(f"{where} must be a table with keys, initial and bounds")
        known(spec, {"keys", "initial", "bounds"}, where)
        keys = required(spec, "keys", where)
        if isinstance(keys, str):
            keys = [keys]
        if not isinstance(keys, list) or not keys:
            raise CampaignError(f"{where}: `keys` must be a non-empty list of scene paths, got {keys!r:.80}")
        initial = number(required(spec, "initial", where), f"{where} `initial`")
        bounds = _bounds(required(spec, "bounds", where), initial, where)
        for key in keys:
            if key in tied:
                raise CampaignError(f"{where}: key {key!r} is already tied to [parameters.{tied[key]}]")
            tied[key] = name
            _parameter_key(scene, key, initial, bounds, where)
        out.append(Parameter(name, tuple(keys), initial, bounds))
    return tuple(out)


def _parameter_key(scene: Scene, key: Any, initial: float, bounds: tuple[float, float], where: str) -> None:
    """CampaignError unless the scene takes ``initial`` and both bounds at ``key``."""
    if key == SHAFT_ANGLE_KEY:
        raise CampaignError(f"{where}: key {key!r} is each recording's `shaft_angle_deg`; it cannot be one "
                            "calibrated value")
    _scene_key(scene, key, initial, where)
    for side, value in zip(("low", "high"), bounds, strict=True):
        _scene_key(scene, key, value, where, f"does not take `bounds` {side} {value:g}")


def _bounds(value: Any, initial: float, where: str) -> tuple[float, float]:
    """``(low, high)`` with ``low < high`` around ``initial``."""
    if not isinstance(value, list) or len(value) != 2:
        raise CampaignError(f"{where}: `bounds` must be [low, high], got {value!r:.80}")
    low = number(value[0], f"{where} `bounds` low")
    high = number(value[1], f"{where} `bounds` high")
    if not low < high:
        raise CampaignError(f"{where}: `bounds` must have low < high, got {value!r}")
    if not low <= initial <= high:
        raise CampaignError(f"{where}: `initial` {initial:g} is outside `bounds` [{low:g}, {high:g}]")
    return (low, high)


def _inputs(table: Mapping[str, Any], scene: Scene, parameters: tuple[Parameter, ...]) -> tuple:
    """The stated input uncertainties; a key may not also be calibrated."""
    calibrated = {key for p in parameters for key in p.keys}
    out = []
    for key, spec in table.items():
        where = f'[inputs."{key}"]'
        if not isinstance(spec, Mapping):
            raise CampaignError(f"{where} must be a table with distribution and std or half_width")
        known(spec, {"distribution", "std", "half_width"}, where)
        if key in calibrated:
            raise CampaignError(f"{where}: {key!r} is calibrated ([parameters]); state it in one place")
        distribution = spec.get("distribution", "normal")
        if distribution not in DISTRIBUTIONS:
            raise CampaignError(f"{where}: `distribution` must be one of {DISTRIBUTIONS}, got "
                                f"{distribution!r:.80}")
        width = "std" if distribution == "normal" else "half_width"
        value = number(spec.get(width), f"{where} `{width}`")
        if value <= 0:
            raise CampaignError(f"{where}: `{width}` must be > 0, got {value!r}")
        _scene_key(scene, key, scene_value(scene, key) + value, where)
        std = value if distribution == "normal" else value / math.sqrt(3.0)
        out.append(InputUncertainty(key, distribution, std))
    return tuple(out)


def scene_value(scene: Scene, key: str) -> float:
    """The scene's value at dotted ``key`` (CampaignError if it is not a number)."""
    node: Any = scene
    for part in key.split("."):
        node = getattr(node, part, None)
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise CampaignError(f'[inputs."{key}"]: key {key!r} is not a number of the scene')
    return float(node)


def _conditioning(table: Mapping[str, Any]) -> Conditioning:
    """The conditioning settings of every recording."""
    known(table, {f.name for f in fields(Conditioning)}, "[conditioning]")
    try:
        return Conditioning(**table)
    except (TypeError, ValueError) as exc:
        raise CampaignError(f"[conditioning]: {exc}") from None
