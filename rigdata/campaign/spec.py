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
from rigdata.conditioning import Conditioning
from rigdata.montecarlo import check_draws
from rigdata.readers.table import FORMATS
from rigdata.record import SHAFTS
from rigdata.transducer import Transducer
from rigdata.validation import MODEL_ENGINES, as_scene

__all__ = ["USES", "DISTRIBUTIONS", "MEASURED_KEYS", "SHAFT_ANGLE_KEY", "CampaignError", "Parameter",
           "InputUncertainty", "RecordingSpec", "CampaignSpec", "load_campaign", "campaign_from_mapping",
           "with_values"]

USES = ("calibration", "validation")
"""What a recording is for: calibration recordings fit the parameters, validation recordings test them."""
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
_RECORDING_KEYS = {"file", "shaft_angle_deg", "use", "label", "format", "map", "unit", "sign",
                   "transducers"}
_CHANNELS = ("time", *(f"{q}_{s}" for q in ("torque", "speed", "angle") for s in SHAFTS))


class CampaignError(ValueError):
    """A campaign file or table that cannot run; the one-line message names the file and the key."""


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
class RecordingSpec:
    """One recording of the campaign and how to read it.

    Attributes
    ----------
    index : int
        Position in the campaign file, from 1.
    file : Path
        Absolute path.
    label : str
        Short name in tables and figures (default: ``file`` as written), unique in the campaign.
    shaft_angle_deg : float
        The rig's shaft angle for this recording [deg].
    use : {"calibration", "validation"}
    read : dict
        Keyword arguments of :func:`rigdata.readers.read` (``format``, ``mapping``, ``units``,
        ``sensitivity``, ``pulses_per_rev``).
    signs : dict of str to int
        Channels recorded with the opposite sign convention (-1).
    transducers : tuple of Transducer
        Input and output transducers.
    """

    index: int
    file: Path
    label: str
    shaft_angle_deg: float
    use: str
    read: dict[str, Any]
    signs: dict[str, int]
    transducers: tuple[Transducer, Transducer]

    @property
    def where(self) -> str:
        """``[[recording]] N (label)``, for messages."""
        return f"[[recording]] {self.index} ({self.label})"


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
    _known(data, _TOP_KEYS, "the campaign")
    scene_source = _text(data, "scene", "the campaign", default="rig")
    scene = _scene(scene_source, base)
    parameters = _parameters(_table(data, "parameters"), scene)
    inputs = _inputs(_table(data, "inputs"), scene, parameters)
    transducer = _transducer(_table(data, "transducers"), "[transducers]")
    recordings = _recordings(data.get("recording"), base, transducer)
    draws = _draws(data)
    if parameters and not any(r.use == "calibration" for r in recordings):
        raise CampaignError("[parameters] asks for a calibration but no [[recording]] has "
                            "use = \"calibration\"")
    return CampaignSpec(
        path=None, title=_text(data, "title", "the campaign", default=""), scene=scene,
        scene_source=scene_source, engines=_engines(data.get("engines", MODEL_ENGINES)),
        coverage=_coverage(data.get("coverage", 0.95)), parameters=parameters, inputs=inputs,
        recordings=recordings, conditioning=_conditioning(_table(data, "conditioning")),
        monte_carlo=draws[0], seed=draws[1], input_samples=_samples(data))


def _known(table: Mapping[str, Any], known: set[str], where: str) -> None:
    """CampaignError for a key of ``table`` that is not in ``known``."""
    unknown = sorted(set(table) - known)
    if unknown:
        raise CampaignError(f"{where}: unknown key {unknown[0]!r} (known: {', '.join(sorted(known))})")


def _table(data: Mapping[str, Any], key: str, where: str = "the campaign") -> Mapping[str, Any]:
    """``data[key]`` as a table (empty if absent)."""
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise CampaignError(f"{where}: `{key}` must be a table, got {value!r:.80}")
    return value


def _text(data: Mapping[str, Any], key: str, where: str, default: str) -> str:
    """``data[key]`` as a non-empty string."""
    value = data.get(key, default)
    if not isinstance(value, str) or (key != "title" and not value.strip()):
        raise CampaignError(f"{where}: `{key}` must be a string, got {value!r:.80}")
    return value


def _required(table: Mapping[str, Any], key: str, where: str) -> Any:
    """``table[key]``; CampaignError naming ``where`` when it is missing."""
    if key not in table:
        raise CampaignError(f"{where}: `{key}` is missing")
    return table[key]


def _number(value: Any, where: str) -> float:
    """``value`` as a finite float; CampaignError naming ``where`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CampaignError(f"{where} must be a finite number, got {value!r:.80}")
    return float(value)


def _samples(data: Mapping[str, Any]) -> int:
    """``input_samples``: an integer in [0, MAX_INPUT_SAMPLES]."""
    value = _count(data, "input_samples", 0)
    if value > MAX_INPUT_SAMPLES:
        raise CampaignError(f"`input_samples` must be at most {MAX_INPUT_SAMPLES} (each is a model run per "
                            f"recording), got {value}")
    return value


def _count(data: Mapping[str, Any], key: str, default: int) -> int:
    """``data[key]`` as an integer >= 0."""
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise CampaignError(f"`{key}` must be an integer >= 0, got {value!r:.80}")
    return value


def _draws(data: Mapping[str, Any]) -> tuple[int, int]:
    """``monte_carlo`` and ``seed``, within what the measurement's Monte Carlo takes."""
    monte_carlo = _count(data, "monte_carlo", 2000)
    seed = _count(data, "seed", 0)
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
    p = _number(value, "`coverage`")
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
        _known(spec, {"keys", "initial", "bounds"}, where)
        keys = _required(spec, "keys", where)
        if isinstance(keys, str):
            keys = [keys]
        if not isinstance(keys, list) or not keys:
            raise CampaignError(f"{where}: `keys` must be a non-empty list of scene paths, got {keys!r:.80}")
        initial = _number(_required(spec, "initial", where), f"{where} `initial`")
        bounds = _bounds(_required(spec, "bounds", where), initial, where)
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
    low = _number(value[0], f"{where} `bounds` low")
    high = _number(value[1], f"{where} `bounds` high")
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
        _known(spec, {"distribution", "std", "half_width"}, where)
        if key in calibrated:
            raise CampaignError(f"{where}: {key!r} is calibrated ([parameters]); state it in one place")
        distribution = spec.get("distribution", "normal")
        if distribution not in DISTRIBUTIONS:
            raise CampaignError(f"{where}: `distribution` must be one of {DISTRIBUTIONS}, got "
                                f"{distribution!r:.80}")
        width = "std" if distribution == "normal" else "half_width"
        value = _number(spec.get(width), f"{where} `{width}`")
        if value <= 0:
            raise CampaignError(f"{where}: `{width}` must be > 0, got {value!r}")
        _scene_key(scene, key, _current(scene, key) + value, where)
        std = value if distribution == "normal" else value / math.sqrt(3.0)
        out.append(InputUncertainty(key, distribution, std))
    return tuple(out)


def _current(scene: Scene, key: str) -> float:
    """The scene's value at dotted ``key`` (CampaignError if it is not a number)."""
    node: Any = scene
    for part in key.split("."):
        node = getattr(node, part, None)
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise CampaignError(f'[inputs."{key}"]: key {key!r} is not a number of the scene')
    return float(node)


def _transducer(table: Mapping[str, Any], where: str, base: Transducer | None = None) -> Transducer:
    """A transducer from ``base`` (default: the paper's) with the table's fields."""
    known = {f.name for f in fields(Transducer)}
    _known(table, known, where)
    start = {f.name: getattr(base, f.name) for f in fields(Transducer)} if base else {}
    try:
        return Transducer(**{**start, **table})
    except (TypeError, ValueError) as exc:
        raise CampaignError(f"{where}: {exc}") from None


def _conditioning(table: Mapping[str, Any]) -> Conditioning:
    """The conditioning settings of every recording."""
    _known(table, {f.name for f in fields(Conditioning)}, "[conditioning]")
    try:
        return Conditioning(**table)
    except (TypeError, ValueError) as exc:
        raise CampaignError(f"[conditioning]: {exc}") from None


def _recordings(value: Any, base: Path, transducer: Transducer) -> tuple[RecordingSpec, ...]:
    """Every ``[[recording]]``: at least one, each file once."""
    if not isinstance(value, list) or not value:
        raise CampaignError("the campaign has no [[recording]] tables")
    out = []
    seen: dict[Path, int] = {}
    for index, table in enumerate(value, start=1):
        rec = _recording(index, table, base, transducer)
        if rec.file in seen:
            raise CampaignError(f"[[recording]] {index} ({table['file']}): `file` is {str(rec.file)!r}, "
                                f"the file of [[recording]] {seen[rec.file]} already")
        seen[rec.file] = index
        if any(r.label == rec.label for r in out):
            raise CampaignError(f"{rec.where}: `label` {rec.label!r} is already another recording's")
        out.append(rec)
    return tuple(out)


def _recording(index: int, table: Any, base: Path, transducer: Transducer) -> RecordingSpec:
    """One ``[[recording]]`` table."""
    where = f"[[recording]] {index}"
    if not isinstance(table, Mapping):
        raise CampaignError(f"{where} must be a table")
    _required(table, "file", where)
    name = _text(table, "file", where, default="")
    file = (base / name).resolve()
    where = f"{where} ({name})"
    _known(table, _RECORDING_KEYS, where)
    if not file.is_file():
        raise CampaignError(f"{where}: `file` {str(file)!r} does not exist or is not a file")
    angle = _number(_required(table, "shaft_angle_deg", where), f"{where} `shaft_angle_deg`")
    if not 0.0 <= angle < 90.0:
        raise CampaignError(f"{where}: `shaft_angle_deg` must be in [0, 90) deg, got {angle!r}")
    use = _required(table, "use", where)
    if use not in USES:
        raise CampaignError(f"{where}: `use` must be \"calibration\" or \"validation\", got {use!r:.80}")
    own = _transducer(_table(table, "transducers", where), f"{where} `transducers`", transducer)
    read = {"mapping": _channels(table, "map", where, str) or None,
            "units": _channels(table, "unit", where, str) or None,
            "sensitivity": own.sensitivity, "pulses_per_rev": own.pulses_per_rev}
    if "format" in table:
        read["format"] = _format(table, where)
    label = _text(table, "label", where, default=name)
    return RecordingSpec(index, file, label, angle, use, read, _signs(table, where), (own, own))


def _format(table: Mapping[str, Any], where: str) -> str:
    """``format``: ``auto`` or a reader's format name."""
    value = table["format"]
    if value != "auto" and value not in FORMATS:
        raise CampaignError(f"{where}: `format` must be \"auto\" or one of {', '.join(FORMATS)}, "
                            f"got {value!r:.80}")
    return value


def _channels(table: Mapping[str, Any], key: str, where: str, kind: type) -> dict[str, Any]:
    """``table[key]``: a table from channel names to ``kind`` values."""
    value = _table(table, key, where)
    for channel, item in value.items():
        if key == "map" and channel not in _CHANNELS:
            raise CampaignError(f"{where}: `{key}` names an unknown channel {channel!r} "
                                f"(channels: {', '.join(_CHANNELS)})")
        if not isinstance(item, kind):
            raise CampaignError(f"{where}: `{key}.{channel}` must be a {kind.__name__}, got {item!r:.80}")
    return dict(value)


def _signs(table: Mapping[str, Any], where: str) -> dict[str, int]:
    """``sign``: channel -> +1 or -1."""
    signs = _channels(table, "sign", where, int)
    for channel, sign in signs.items():
        if sign not in (1, -1) or isinstance(sign, bool):
            raise CampaignError(f"{where}: `sign.{channel}` must be 1 or -1, got {sign!r}")
    return signs
