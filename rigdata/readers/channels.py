"""Which column is which channel: recognition by header words, the explicit mapping (``--map``, wins)
and each column's and channel's unit.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from rigdata.readers.table import RawTable
from rigdata.record import CHANNELS, SHAFTS, RigDataError
from rigdata.units import ACCEPTS, Unit, lookup, parse_unit, split_header

__all__ = ["TIME_WORDS", "TIME_NAMES", "KIND_WORDS", "SIDE_WORDS", "SIDE_NUMBERS", "HARDWARE_PREFIXES",
           "MAP_HINT", "recognise", "time_column", "column_unit", "channel_unit", "match_channels",
           "require_units"]

# Vocabulary of channel recognition (tokens of a header's bare name, lower case, accents removed).
TIME_WORDS = {"time", "t", "zeit", "elapsed", "timestamp", "timestamps", "seconds", "tempo", "temps"}
#: Time channels that vendor software names with a number and a rate group (bare name, whole match).
TIME_NAMES = {
    "HBM catman": re.compile(r"(?:zeit|time)\s+\d+\s+-\s+\S.*", re.I),  # "Zeit  1 - Standardmessrate"
}
KIND_WORDS = {
    "torque": {"torque", "trq", "tq", "moment", "drehmoment", "t", "m", "md", "coppia", "momento",
               "couple"},
    "speed": {"speed", "omega", "w", "n", "rpm", "velocity", "angvel", "drehzahl", "velocita", "giri",
              "vitesse"},
    "angle": {"angle", "phi", "theta", "pulses", "pulse", "counts", "count", "cnt", "encoder", "enc",
              "position", "pos", "winkel", "imp", "ticks", "angolo"},
}
SIDE_WORDS = {
    "in": {"in", "input", "drive", "driving", "driver", "motor", "antrieb", "primary", "an", "eingang",
           "ingresso", "entree"},
    "out": {"out", "output", "brake", "load", "driven", "abtrieb", "secondary", "ab", "ausgang", "uscita",
            "sortie"},
}
#: Shaft numbers ("Trq1", "n2"): a side only when the name has no side word.
SIDE_NUMBERS = {"in": {"1"}, "out": {"2"}}
#: Hardware-channel prefixes vendor software puts before a channel's name; dropped before recognition,
#: their number is a connector, never a side.
HARDWARE_PREFIXES = {
    "DEWESoft": re.compile(r"(?:ai|ao|di|do|cnt|can|acc|math)\s*\d+\s*/\s*", re.I),  # "CNT 1/Speed_Out"
}
#: Words that may stand next to a side word when the kind comes from the unit ("Drive [N m]").
FILLER = {"shaft", "side", "sensor", "transducer", "signal", "tmb", "magtrol", "measured", "meas"}
ALL_SIDES = set().union(*SIDE_WORDS.values(), *SIDE_NUMBERS.values())
#: Kind words that may be glued to a side word ("torquein", "speedout"), longest first.
COMPOUND_KINDS = sorted({k for ks in KIND_WORDS.values() for k in ks if len(k) >= 3}, key=len, reverse=True)
#: How to name a channel's column, for error messages (format with ``ch``).
MAP_HINT = "--map {ch}=COLUMN (read(..., mapping={{{ch!r}: COLUMN}}))"
#: Units to suggest when a channel's column states none.
UNIT_EXAMPLES = {"torque": ["N m", "V"], "speed": ["rad/s", "rpm", "pulses/s"],
                 "angle": ["rad", "deg", "counts"], "time": ["s", "ms"]}


def tokens(name: str) -> list[str]:
    """Words of a bare column name: camelCase, letters/digits and punctuation split, lower case, accents
    removed (``Velocità`` -> ``velocita``).
    """
    s = "".join(c for c in unicodedata.normalize("NFKD", name) if not unicodedata.combining(c))
    s = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", s)
    s = re.sub(r"(?<=[A-Za-z])(?=\d)|(?<=\d)(?=[A-Za-z])", " ", s)
    words = [t for t in re.split(r"[^0-9a-z]+", s.lower()) if t]
    out = []
    for w in words:
        for kind in COMPOUND_KINDS:
            if w.startswith(kind) and w[len(kind):] in ALL_SIDES:
                out += [kind, w[len(kind):]]
                break
        else:
            out.append(w)
    return out


def is_time(words: list[str]) -> bool:
    """True for the words of a time column's name (``time``, ``time ms``, ``x value``)."""
    if words in (["x", "value"], ["xvalue"]):
        return True
    if not words or words[0] not in TIME_WORDS:
        return False
    rest = words[1:]
    return not rest or rest in (["rel"], ["relative"]) or (
        len(rest) == 1 and lookup(rest[0]) is not None and lookup(rest[0]).quantity == "time")


def recognise(header: str, unit: str | None = None) -> str | None:
    """The record channel a column header names, ``"time"``, or None.

    Case, accents, separators, camelCase and a unit annotation do not matter; a hardware-channel
    prefix (:data:`HARDWARE_PREFIXES`, ``CNT 1/``) is dropped. The words are those of
    :data:`TIME_WORDS`, :data:`KIND_WORDS` and :data:`SIDE_WORDS` (English, German, Italian, French),
    and the vendor time names of :data:`TIME_NAMES`.

    Exactly one side and one kind (``Trq1``, ``Brake torque``, ``Drehzahl_Ab``); a side word outranks
    a shaft number (:data:`SIDE_NUMBERS`); with a side and no or two kinds, ``unit`` (or the header's)
    decides (``Drive [N m]``).
    """
    bare, annotated = split_header(header)
    if any(p.fullmatch(bare.strip()) for p in TIME_NAMES.values()):
        return "time"
    for prefix in HARDWARE_PREFIXES.values():
        bare = prefix.sub("", bare.strip(), count=1) if prefix.match(bare.strip()) else bare
    words_list = tokens(bare)
    if is_time(words_list):
        return "time"
    words = set(words_list)
    sides = [s for s, w in SIDE_WORDS.items() if w & words] or [
        s for s, w in SIDE_NUMBERS.items() if w & words]
    if len(sides) != 1:
        return None
    kinds = {k for k, w in KIND_WORDS.items() if w & words}
    found = lookup(annotated or unit or "")
    by_unit = {k for k, q in ACCEPTS.items() if found is not None and found.quantity in q} - {"time"}
    if len(kinds) > 1:
        kinds &= by_unit
    elif not kinds and not (words - SIDE_WORDS[sides[0]] - SIDE_NUMBERS[sides[0]] - FILLER):
        kinds = by_unit
    return f"{kinds.pop()}_{sides[0]}" if len(kinds) == 1 else None


def time_column(columns: Mapping[str, np.ndarray]) -> str | None:
    """The one column recognised as time, None when there is none or more than one."""
    found = [c for c in columns if recognise(c) == "time"]
    return found[0] if len(found) == 1 else None


def column_unit(header: str, stated: str | None) -> str | None:
    """Unit of a column as written: header annotation, else ``stated``, else a time name's suffix
    (``time_s``); None if none.
    """
    bare, unit = split_header(header)
    if unit is None:
        unit = stated
    if unit is None:
        words = tokens(bare)
        suffix = lookup(words[1]) if len(words) == 2 and words[0] in TIME_WORDS else None
        if suffix is not None and suffix.quantity == "time":
            unit = words[1]
    return unit


def channel_unit(raw: RawTable, column: str, channel: str, units: Mapping[str, str]) -> Unit:
    """Unit of ``channel`` read from ``column``: from ``units`` by channel or column name, else the file's.

    RigDataError for a missing unit or one unknown, ambiguous or of another quantity.
    """
    kind = "time" if channel == "time" else channel.split("_")[0]
    given = units.get(channel, units.get(column))
    if given is not None:
        return parse_unit(given, kind=kind, column=column, file=raw.file, channel=channel)
    stated = raw.units.get(column)
    if stated is None:
        raise RigDataError(f"no unit: column {column!r} states none; give it with --unit {channel}=UNIT "
                           f"(read(..., units={{{channel!r}: UNIT}})), e.g. "
                           f"{', '.join(UNIT_EXAMPLES[kind])}", file=raw.file, channel=channel)
    return parse_unit(stated, kind=kind, column=column, file=raw.file, channel=channel)


def require_units(raw: RawTable, chosen: Mapping[str, str], units: Mapping[str, str]) -> None:
    """RigDataError naming every chosen channel (time aside: seconds assumed) whose column states no unit
    and that ``units`` does not give, with the options that give them all.
    """
    missing = {ch: col for ch, col in chosen.items() if ch != "time" and raw.units.get(col) is None
               and units.get(ch, units.get(col)) is None}
    if len(missing) == 1:
        ch, col = next(iter(missing.items()))
        channel_unit(raw, col, ch, units)  # its one-channel message
    if not missing:
        return
    columns = ", ".join(f"{col!r} ({ch})" for ch, col in missing.items())
    options = " ".join(f"--unit {ch}=UNIT" for ch in missing)
    given = ", ".join(f"{ch!r}: UNIT" for ch in missing)
    kinds = dict.fromkeys(ch.split("_")[0] for ch in missing)
    examples = "; ".join(f"{k}: {', '.join(UNIT_EXAMPLES[k])}" for k in kinds)
    raise RigDataError(f"no unit: columns {columns} state none; give them with {options} "
                       f"(read(..., units={{{given}}})), e.g. {examples}", file=raw.file)


def _key(text: str) -> str:
    return re.sub(r"\s+", " ", text.strip().casefold())


def _find_column(wanted: str, columns: list[str], channel: str, path: Path) -> str:
    """The column a mapping names: exact, else ignoring case and blanks, else by bare name."""
    if wanted in columns:
        return wanted
    for pick in (_key, lambda c: _key(split_header(c)[0])):
        hits = [c for c in columns if pick(c) == _key(wanted)]
        if len(hits) == 1:
            return hits[0]
        if len(hits) > 1:
            raise RigDataError(f"mapping {wanted!r} is ambiguous: columns {hits} match", file=path,
                               channel=channel)
    raise RigDataError(f"mapped to column {wanted!r}, which the file does not have; columns found: "
                       f"{columns}", file=path, channel=channel)


def _recognised_time(names: list[str], chosen: Mapping[str, str], path: Path) -> str | None:
    candidates = [c for c in names if recognise(c) == "time" and c not in chosen.values()]
    if len(candidates) > 1:
        raise RigDataError(f"ambiguous: columns {candidates} all look like time; choose one with "
                           f"{MAP_HINT.format(ch='time')}", file=path, channel="time")
    return candidates[0] if candidates else None


def _recognised_channels(raw: RawTable, chosen: Mapping[str, str], mapping: Mapping[str, str | None],
                         path: Path) -> dict[str, str]:
    found: dict[str, list[str]] = {}
    for col in raw.columns:
        if col in chosen.values():
            continue
        ch = recognise(col, raw.units.get(col))
        if ch in CHANNELS and ch not in mapping:
            found.setdefault(ch, []).append(col)
    for ch, cols in found.items():
        if len(cols) > 1:
            raise RigDataError(f"ambiguous: columns {cols} both match; choose one with "
                               f"{MAP_HINT.format(ch=ch)}", file=path, channel=ch)
    return {ch: cols[0] for ch, cols in found.items()}


def match_channels(raw: RawTable, mapping: Mapping[str, str | None] | None = None) -> dict[str, str]:
    """Columns of the record channels and of time: ``mapping`` first, recognition for the rest.

    Parameters
    ----------
    raw : RawTable
    mapping : mapping of str to str or None, optional
        Channel (key of :data:`rigdata.record.CHANNELS` or ``"time"``) -> column (exact, ignoring case
        and blanks, or without unit); None leaves a channel out.

    Returns
    -------
    dict of str to str
        Channel -> column; ``"time"`` only when the file has a time column.

    Raises
    ------
    RigDataError
        Unknown channel, missing mapped column, two columns for one channel, a required channel missing.
    """
    path = Path(raw.file)
    mapping = dict(mapping or {})
    unknown = set(mapping) - set(CHANNELS) - {"time"}
    if unknown:
        raise ValueError(f"`mapping` keys must be 'time' or one of {sorted(CHANNELS)}, got {sorted(unknown)}")
    names = list(raw.columns)
    chosen = {ch: _find_column(col, names, ch, path) for ch, col in mapping.items() if col is not None}
    if "time" not in mapping:
        time = _recognised_time(names, chosen, path)
        if time is not None:
            chosen["time"] = time
    chosen.update(_recognised_channels(raw, chosen, mapping, path))
    _require(chosen, names, path)
    return chosen


def _require(chosen: Mapping[str, str], names: list[str], path: Path) -> None:
    for ch in ("torque_in", "torque_out"):
        if ch not in chosen:
            raise RigDataError(f"missing: no column recognised as {ch}; columns found: {names}; name it "
                               f"with {MAP_HINT.format(ch=ch)}", file=path, channel=ch)
    for shaft in SHAFTS:
        if f"speed_{shaft}" not in chosen and f"angle_{shaft}" not in chosen:
            raise RigDataError(f"missing: no column recognised as speed_{shaft} or angle_{shaft}; columns "
                               f"found: {names}; name one with {MAP_HINT.format(ch=f'speed_{shaft}')}",
                               file=path, channel=f"speed_{shaft}")
