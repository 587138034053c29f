"""From the table to the record: time axis, channels in SI units, provenance.

Time: the time column, else the channels' waveform timing, else a header rate or interval.
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Mapping
from typing import Any

import numpy as np

from rigdata.conversion import check_magnitudes, to_si
from rigdata.readers.channels import MAP_HINT, channel_unit, require_units
from rigdata.readers.table import RawTable
from rigdata.record import RATE_TOLERANCE, ChannelSource, RigDataError, RigRecord
from rigdata.units import normalise, parse_unit, split_header

__all__ = ["time_axis", "to_record"]

#: Header keys of a sample rate and interval (lower case, letters and digits only, accents removed):
#: English, German (HBM catman's ``Messrate``), Italian, French.
RATE_KEYS = {"samplerate", "samplingrate", "samplingfrequency", "samplefrequency", "fs", "rate", "scanrate",
             "messrate", "abtastrate", "abtastfrequenz", "frequenzadicampionamento",
             "frequencedechantillonnage"}
INTERVAL_KEYS = {"dt", "deltax", "sampleinterval", "samplinginterval", "timestep", "timeincrement",
                 "wfincrement", "sampleperiod", "samplingperiod", "interval", "abtastintervall"}
START_KEYS = {"t0", "x0", "starttime", "wfstartoffset"}
#: Rate units of a header's sample rate -> factor to Hz.
RATE_UNITS = {"": 1.0, "hz": 1.0, "1/s": 1.0, "s^-1": 1.0, "s-1": 1.0, "sps": 1.0, "s/s": 1.0,
              "samples/s": 1.0, "khz": 1e3, "ks/s": 1e3}
HEADER_NUMBER = re.compile(r"^\s*([-+]?(?:\d+[.,]?\d*|[.,]\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


def _header_number(meta: Mapping[str, str], keys: set[str]) -> tuple[str, float, str] | None:
    """A number from the header under one of ``keys`` (normalised): key, value, unit text."""
    for key, value in meta.items():
        bare, key_unit = split_header(key)
        plain = "".join(c for c in unicodedata.normalize("NFKD", bare) if not unicodedata.combining(c))
        if re.sub(r"[^a-z0-9]", "", plain.lower()) not in keys:
            continue
        m = HEADER_NUMBER.match(str(value))
        if m:
            number = m.group(1).replace(",", ".") if "." not in m.group(1) else m.group(1)
            return key, float(number), (m.group(2) or key_unit or "")
    return None


def _header_interval(raw: RawTable) -> tuple[float, str] | None:
    """Sampling interval [s] from the header's rate or interval, and where it came from."""
    rate = _header_number(raw.metadata, RATE_KEYS)
    if rate is not None:
        factor = RATE_UNITS.get(normalise(rate[2]))
        if factor is None:
            raise RigDataError(f"header key {rate[0]!r}: unknown rate unit {rate[2]!r}; accepted: Hz, kHz, "
                               f"S/s, 1/s", file=raw.file, channel="time")
        return 1.0 / (rate[1] * factor), f"header {rate[0]!r} = {raw.metadata[rate[0]]}"
    interval = _header_number(raw.metadata, INTERVAL_KEYS)
    if interval is None:
        return None
    factor = parse_unit(interval[2] or "s", kind="time", file=raw.file, channel="time").factor
    return interval[1] * factor, f"header {interval[0]!r} = {raw.metadata[interval[0]]}"


def _time_from_header(raw: RawTable, n: int) -> tuple[np.ndarray, dict[str, Any]] | None:
    start = _header_number(raw.metadata, START_KEYS)
    t0 = 0.0 if start is None else start[1] * parse_unit(start[2] or "s", kind="time", file=raw.file,
                                                        channel="time").factor
    found = _header_interval(raw)
    if found is None:
        return None
    dt, source = found
    if not (math.isfinite(dt) and dt > 0):
        raise RigDataError(f"sampling interval from the {source} is not positive", file=raw.file,
                           channel="time")
    return t0 + dt * np.arange(n), {"source": source, "dt": dt, "unit": "s"}


def _time_from_sampling(raw: RawTable, chosen: Mapping[str, str], n: int) -> tuple[np.ndarray, dict] | None:
    timing = {ch: raw.sampling[col] for ch, col in chosen.items() if col in raw.sampling}
    if not timing:
        return None
    ref_ch = next(iter(timing))
    t0, dt = timing[ref_ch]
    for ch, (s0, sdt) in timing.items():
        if not (sdt > 0 and abs(sdt / dt - 1.0) <= RATE_TOLERANCE):
            raise RigDataError(f"mixed sampling rates: {ch} ({chosen[ch]!r}) is sampled every {sdt:.6g} s, "
                               f"{ref_ch} ({chosen[ref_ch]!r}) every {dt:.6g} s (the conditioning needs one "
                               f"rate; resample or split the file)", file=raw.file, channel=ch)
        if abs(s0 - t0) > 0.5 * dt:
            raise RigDataError(f"starts at t = {s0:.6g} s, {ref_ch} ({chosen[ref_ch]!r}) at {t0:.6g} s: the "
                               f"channels are not sampled together", file=raw.file, channel=ch)
    return t0 + dt * np.arange(n), {"source": f"sampling of column {chosen[ref_ch]!r} (start {t0:g} s, "
                                              f"interval {dt:g} s)", "dt": dt, "unit": "s"}


def _time_from_column(raw: RawTable, chosen: Mapping[str, str], units: Mapping[str, str],
                      n: int) -> tuple[np.ndarray, dict[str, Any], list[str]]:
    column = chosen["time"]
    assumed = []
    if units.get("time", units.get(column)) is None and raw.units.get(column) is None:
        unit = parse_unit("s", kind="time")
        assumed.append(f"time column {column!r} states no unit: assumed s")
    else:
        unit = channel_unit(raw, column, "time", units)
    if raw.sampling:  # the channels' own timing must still agree among themselves
        _time_from_sampling(raw, {k: v for k, v in chosen.items() if k != "time"}, n)
    t = raw.values(column, "time") * unit.factor
    return t, {"column": column, "unit": unit.spelling, "source": "column"}, assumed


def time_axis(raw: RawTable, chosen: Mapping[str, str], units: Mapping[str, str],
              n: int) -> tuple[np.ndarray, dict[str, Any], list[str]]:
    """Sample times [s] of ``n`` samples, where they came from, and the assumptions made.

    ``chosen``: channel (and ``"time"``) -> column; ``units``: by channel or column name.
    """
    if chosen.get("time") is not None:
        return _time_from_column(raw, chosen, units, n)
    for build in (_time_from_sampling(raw, chosen, n), _time_from_header(raw, n)):
        if build is not None:
            return build[0], build[1], []
    raise RigDataError("no time: no time column (names like 'time', 't', 'Time [s]', 'X_Value'), no "
                       "waveform timing and no sample rate or interval in the header (keys like "
                       f"'sample_rate: 1000 Hz', 'dt: 0.001 s'); columns found: {list(raw.columns)}; name "
                       f"the time column with {MAP_HINT.format(ch='time')}", file=raw.file, channel="time")


def _lengths(raw: RawTable, chosen: Mapping[str, str]) -> int:
    sizes = {ch: raw.columns[col].size for ch, col in chosen.items()}
    first = next(iter(sizes))
    for ch, size in sizes.items():
        if size != sizes[first]:
            raise RigDataError(f"has {size} samples, {first} ({chosen[first]!r}) has {sizes[first]} (mixed "
                               f"sampling rates or a channel cut short)", file=raw.file, channel=ch)
    return sizes[first]


def _synthetic(meta: Mapping[str, str]) -> dict[str, str] | None:
    lower = {k.strip().lower(): v for k, v in meta.items()}
    if "synthetic" not in lower:
        return None
    return {k: lower[k] for k in ("synthetic", "generator", "settings") if k in lower}


def to_record(raw: RawTable, chosen: Mapping[str, str], units: Mapping[str, str], sensitivity: float,
              pulses_per_rev: int) -> RigRecord:
    """Record of ``raw``'s ``chosen`` columns in SI units with provenance; ``sensitivity`` [V/(N m)],
    ``pulses_per_rev`` [-]. RigDataError for a missing or wrong unit, bad time axis, absurd values.
    """
    n = _lengths(raw, chosen)
    require_units(raw, chosen, units)
    time, time_info, assumptions = time_axis(raw, chosen, units, n)
    channels = {}
    sources = {}
    notes = list(raw.notes)
    for ch, col in chosen.items():
        if ch == "time":
            continue
        values = raw.values(col, ch)
        unit = channel_unit(raw, col, ch, units)
        conv = to_si(values, unit, sensitivity=sensitivity, pulses_per_rev=pulses_per_rev)
        channels[ch] = conv.values
        sources[ch] = ChannelSource(col, unit.spelling, conv.conversion, conv.quantum)
        notes += [f"{ch} ({col!r}): {note}" for note in conv.notes]
    provenance = {"file": raw.file, "format": raw.format, "reader": dict(raw.reader), "sha256": raw.sha256,
                  "header": dict(raw.metadata), "time": time_info,
                  "conversion": {"sensitivity_V_per_Nm": float(sensitivity),
                                 "pulses_per_rev": int(pulses_per_rev)},
                  "notes": notes, "assumptions": assumptions}
    synthetic = _synthetic(raw.metadata)
    if synthetic is not None:
        provenance["synthetic"] = synthetic
    record = RigRecord(time, channels, sources, provenance)  # its own checks first: NaN, time order
    check_magnitudes(record.time, record.channels, file=raw.file)
    return record
