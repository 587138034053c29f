"""The ``[[recording]]`` tables of a campaign file: each recording, how to read it and its transducers
(:class:`RecordingSpec`), each file once.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from rigdata.campaign.values import CampaignError, known, number, required, table_of, text
from rigdata.readers.table import FORMATS
from rigdata.record import SHAFTS
from rigdata.transducer import Transducer

__all__ = ["USES", "RecordingSpec", "parse_transducer", "parse_recordings"]

USES = ("calibration", "validation")
"""What a recording is for: calibration recordings fit the parameters, validation recordings test them."""
_RECORDING_KEYS = {"file", "shaft_angle_deg", "use", "label", "format", "map", "unit", "sign",
                   "transducers"}
_CHANNELS = ("time", *(f"{q}_{s}" for q in ("torque", "speed", "angle") for s in SHAFTS))


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


def parse_transducer(table: Mapping[str, Any], where: str, base: Transducer | None = None) -> Transducer:
    """A transducer from ``base`` (default: the paper's) with the table's fields."""
    names = {f.name for f in fields(Transducer)}
    known(table, names, where)
    start = {f.name: getattr(base, f.name) for f in fields(Transducer)} if base else {}
    try:
        return Transducer(**{**start, **table})
    except (TypeError, ValueError) as exc:
        raise CampaignError(f"{where}: {exc}") from None


def parse_recordings(value: Any, base: Path, transducer: Transducer) -> tuple[RecordingSpec, ...]:
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
    required(table, "file", where)
    name = text(table, "file", where, default="")
    file = (base / name).resolve()
    where = f"{where} ({name})"
    known(table, _RECORDING_KEYS, where)
    if not file.is_file():
        raise CampaignError(f"{where}: `file` {str(file)!r} does not exist or is not a file")
    angle = number(required(table, "shaft_angle_deg", where), f"{where} `shaft_angle_deg`")
    if not 0.0 <= angle < 90.0:
        raise CampaignError(f"{where}: `shaft_angle_deg` must be in [0, 90) deg, got {angle!r}")
    use = required(table, "use", where)
    if use not in USES:
        raise CampaignError(f"{where}: `use` must be \"calibration\" or \"validation\", got {use!r:.80}")
    own = parse_transducer(table_of(table, "transducers", where), f"{where} `transducers`", transducer)
    read = {"mapping": _channels(table, "map", where, str) or None,
            "units": _channels(table, "unit", where, str) or None,
            "sensitivity": own.sensitivity, "pulses_per_rev": own.pulses_per_rev}
    if "format" in table:
        read["format"] = _format(table, where)
    label = text(table, "label", where, default=name)
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
    value = table_of(table, key, where)
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
