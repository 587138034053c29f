"""Readers of measured rig files: delimited text, LabVIEW Measurement (.lvm), NI TDMS.

:func:`read_table` returns what a file holds (:class:`RawTable`: columns as floats, units and
header as written); :func:`read` goes on to the record: it picks the time axis and the four
transducer channels (explicit ``mapping`` or recognition by name), converts them to SI with
:mod:`rigdata.units` and returns a validated :class:`~rigdata.record.RigRecord` whose
``provenance`` says where every number came from.

Every problem with a file is one :class:`~rigdata.record.RigDataError` naming the file, the
channel or column, and the problem; errors of pandas, lvm_read and npTDMS are wrapped the same
way. The record's own validation (time increasing and uniform, no NaN) is not repeated here.

Assumptions
-----------
* A time column without a unit (header ``time`` or ``t``) is in seconds; the record's
  provenance lists this under ``assumptions``. LVM X values and TDMS waveform timing are seconds
  by the formats' definitions.
* Pulse counts are a cumulative counter (:func:`rigdata.units.unwrap_counter`); a speed given as
  a pulse frequency must say ``pulses/s``, ``Hz`` is refused as ambiguous.
* Raw conversions default to the paper's Magtrol TMB 210: 0.1 V/(N m), 60 pulses per revolution.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import logging
import math
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rigdata.record import CHANNELS, RATE_TOLERANCE, SHAFTS, ChannelSource, RigDataError, RigRecord
from rigdata.units import (
    ACCEPTS,
    PULSES_PER_REV,
    SENSITIVITY,
    Unit,
    lookup,
    normalise,
    parse_unit,
    split_header,
    to_si,
)

FORMATS = ("csv", "lvm", "tdms")
#: How many non-numeric cells of a column a RawTable keeps the text of.
_KEEP_TEXT = 5
_NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?$|^[+-]?(?:nan|inf|infinity)$", re.I)
_COMMA_NUMBER = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")
_MISSING = {"", "nan", "-nan", "+nan", "na", "n/a", "nat", "null", "none", "#n/a"}

# Vocabulary of channel recognition (tokens of a header's bare name, lower case).
TIME_WORDS = {"time", "t", "zeit", "elapsed", "timestamp", "seconds"}
KIND_WORDS = {
    "torque": {"torque", "trq", "tq", "moment", "drehmoment", "t", "m", "md"},
    "speed": {"speed", "omega", "w", "n", "rpm", "velocity", "angvel", "drehzahl"},
    "angle": {"angle", "phi", "theta", "pulses", "pulse", "counts", "count", "cnt", "encoder", "enc",
              "position", "pos", "winkel", "imp", "ticks"},
}
SIDE_WORDS = {
    "in": {"in", "input", "1", "drive", "driving", "driver", "motor", "antrieb", "primary"},
    "out": {"out", "output", "2", "brake", "load", "driven", "abtrieb", "secondary"},
}
#: Words that may stand next to a side word when the kind comes from the unit ("Drive [N m]").
_FILLER = {"shaft", "side", "sensor", "transducer", "signal", "tmb", "magtrol", "measured", "meas"}
_RATE_KEYS = {"samplerate", "samplingrate", "samplingfrequency", "samplefrequency", "fs", "rate", "scanrate"}
_INTERVAL_KEYS = {"dt", "deltax", "sampleinterval", "samplinginterval", "timestep", "timeincrement",
                  "wfincrement", "sampleperiod", "samplingperiod", "interval"}
_START_KEYS = {"t0", "x0", "starttime", "wfstartoffset"}
_RATE_UNITS = {"": 1.0, "hz": 1.0, "1/s": 1.0, "s^-1": 1.0, "s-1": 1.0, "sps": 1.0, "s/s": 1.0,
               "samples/s": 1.0, "khz": 1e3, "ks/s": 1e3}
_ALL_SIDES = set().union(*SIDE_WORDS.values())
#: Kind words that may be glued to a side word ("torquein", "speedout"), longest first.
_COMPOUND_KINDS = sorted({k for ks in KIND_WORDS.values() for k in ks if len(k) >= 3}, key=len, reverse=True)
_MAP_HINT = "--map {ch}=COLUMN (read(..., mapping={{{ch!r}: COLUMN}}))"


@dataclass(frozen=True)
class TextCells:
    """Non-numeric cells of one column (their values are NaN in :attr:`RawTable.columns`).

    Attributes
    ----------
    count : int
        How many cells of the column hold text.
    first : tuple of (int, int or None, str)
        Sample row (0-based), file line (1-based, None when unknown) and text of the first few.
    """

    count: int
    first: tuple[tuple[int, int | None, str], ...]

    def describe(self) -> str:
        row, line, text = self.first[0]
        where = f"row {row}" + (f" (line {line})" if line is not None else "")
        more = f" and {self.count - 1} more" if self.count > 1 else ""
        return f"non-numeric cell {text!r} at {where}{more}"


@dataclass(frozen=True)
class RawTable:
    """The contents of a rig file, before channels are chosen and converted.

    Attributes
    ----------
    file : str
        Path of the file.
    format : {"csv", "lvm", "tdms"}
        Format read.
    time : str or None
        Name of the time column, None when the file has none (time then comes from
        :attr:`sampling` or the header's sample rate).
    columns : dict of str to ndarray
        Every column as floats, keyed by its name in the file (the whole header, units included,
        for text files; ``group/channel`` for TDMS channels whose name repeats across groups).
        Non-numeric cells are NaN and listed in :attr:`text_cells`. TDMS channels may differ in
        length.
    units : dict of str to str or None
        Unit of each column as the file states it (header annotation, units row, LVM
        ``Y_Unit_Label``, TDMS ``unit_string``), None when it states none.
    metadata : dict of str to str
        Header key/value pairs: preamble ``key: value`` lines, LVM file header tags, TDMS file
        properties.
    text_cells : dict of str to TextCells
        Columns with non-numeric cells.
    sampling : dict of str to (float, float)
        Start time [s] and sampling interval [s] of each channel, from LVM ``X0``/``Delta_X``
        or TDMS ``wf_start_offset``/``wf_increment``; empty for text files.
    reader : dict of str to str
        Library that parsed the file: ``name`` and ``version``.
    sha256 : str
        Hash of the file's bytes.
    notes : tuple of str
        What the reader decided (separator, decimal mark, header line, segments joined).
    """

    file: str
    format: str
    time: str | None
    columns: Mapping[str, np.ndarray]
    units: Mapping[str, str | None]
    metadata: Mapping[str, str] = field(default_factory=dict)
    text_cells: Mapping[str, TextCells] = field(default_factory=dict)
    sampling: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    reader: Mapping[str, str] = field(default_factory=dict)
    sha256: str = ""
    notes: tuple[str, ...] = ()


# ---------------------------------------------------------------------------------------------
# files, formats, text


def _file_bytes(path: Path) -> bytes:
    if not path.exists():
        raise RigDataError("file not found", file=path)
    if path.is_dir():
        raise RigDataError("is a directory, not a file", file=path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise RigDataError(f"cannot read the file: {exc.strerror or exc}", file=path) from exc
    if not data.strip():
        raise RigDataError("empty file" if not data else "empty file (only blank space)", file=path)
    return data


def _content_format(head: bytes) -> str | None:
    """Format the first bytes show: "tdms", "lvm", or None (text of some other kind)."""
    if head.startswith(b"TDSm"):
        return "tdms"
    text = head.lstrip(b"\xef\xbb\xbf")
    if text.startswith(b"\xff\xfe") or text.startswith(b"\xfe\xff"):
        text = text.decode("utf-16", errors="ignore").encode()
    return "lvm" if text.lstrip().startswith(b"LabVIEW Measurement") else None


_FORMAT_ALIASES = {"auto": "auto", "csv": "csv", "text": "csv", "txt": "csv", "tsv": "csv", "dat": "csv",
                   "lvm": "lvm", "tdms": "tdms"}


def _choose_format(path: Path, format: str, head: bytes) -> str:
    """The format to read, checked against the file's first bytes."""
    suffix = path.suffix.lower()
    if suffix == ".tdms_index":
        raise RigDataError("is a TDMS index file; read the .tdms file next to it", file=path)
    wanted = _FORMAT_ALIASES[format]
    said = "format" if wanted != "auto" else f"extension {path.suffix or '(none)'!r}"
    if wanted == "auto":
        wanted = {".lvm": "lvm", ".tdms": "tdms"}.get(suffix, "csv")
    found = _content_format(head)
    if found is not None and found != wanted:
        name = {"tdms": "a TDMS file", "lvm": "a LabVIEW Measurement (LVM) file"}[found]
        raise RigDataError(f"content is {name} but the {said} says {wanted}; rename the file or pass "
                           f"format={found!r}", file=path)
    if wanted == "tdms" and found != "tdms":
        raise RigDataError(f"not a TDMS file: it does not start with 'TDSm' (the {said} says TDMS; "
                           f"{len(head)} bytes read: {head[:16]!r})", file=path)
    if wanted == "lvm" and found != "lvm":
        raise RigDataError(f"not a LabVIEW Measurement file: the first line is not 'LabVIEW Measurement' "
                           f"(the {said} says LVM; for delimited text pass format='csv')", file=path)
    return wanted


def _decode(data: bytes, path: Path) -> str:
    """Text of a file: UTF-8 (BOM or not), UTF-16 with BOM, else Latin-1; binary refused."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise RigDataError(f"unreadable UTF-16 text: {exc}", file=path) from exc
    head = data[:8192]
    controls = sum(head.count(bytes([b])) for b in range(32) if b not in (9, 10, 12, 13, 26))
    if b"\x00" in head or controls > 0.02 * len(head):
        raise RigDataError(f"not a text file (binary content: {head[:16]!r}...); expected delimited "
                           f"text, LVM or TDMS", file=path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def read_table(path: str | Path, format: str = "auto") -> RawTable:
    """Read a rig file's columns, units and header as they are, without choosing channels.

    Parameters
    ----------
    path : str or Path
        File to read.
    format : {"auto", "csv", "lvm", "tdms"}
        ``"auto"`` goes by the extension (``.lvm``, ``.tdms``, anything else delimited text);
        content that contradicts the extension or the given format is an error.

    Returns
    -------
    RawTable

    Raises
    ------
    RigDataError
        File missing, empty, binary where text is expected, of another format than stated,
        truncated, without a header line, with rows of the wrong number of fields, or that the
        format's library cannot parse.
    """
    if format not in _FORMAT_ALIASES:
        raise ValueError(f"`format` must be 'auto' or one of {FORMATS}, got {format!r}")
    path = Path(path)
    data = _file_bytes(path)
    fmt = _choose_format(path, format, data[:64])
    sha = hashlib.sha256(data).hexdigest()
    if fmt == "tdms":
        return _read_tdms(path, data, sha)
    text = _decode(data, path)
    return _read_lvm(path, text, sha) if fmt == "lvm" else _read_delimited(path, text, sha)


# ---------------------------------------------------------------------------------------------
# delimited text


@dataclass(frozen=True)
class _Layout:
    sep: str | None          # None: runs of blanks
    decimal: str
    header: int              # line index of the column names
    units_row: int | None    # line index of a units row, if any
    first: int               # line index of the first data row
    width: int               # fields per data row


def _split(line: str, sep: str | None) -> list[str]:
    return line.split() if sep is None else [f.strip().strip('"').strip() for f in line.split(sep)]


def _is_number(text: str) -> bool:
    return bool(_NUMBER.match(text.strip().strip('"')))


def _numeric_row(fields: list[str]) -> bool:
    """Two or more fields, most of them numbers, none holding a tab or semicolon (which would
    mean the line was split at the wrong separator)."""
    return (len(fields) >= 2 and 2 * sum(map(_is_number, fields)) > len(fields)
            and not any("\t" in f or ";" in f for f in fields))


def _data_start(lines: list[str], sep: str | None, limit: int = 2000) -> tuple[int, int] | None:
    """First line that opens a block of numeric rows of one width, with the width."""
    body = [i for i, line in enumerate(lines[:limit]) if line.strip()]
    for pos, i in enumerate(body):
        fields = _split(lines[i], sep)
        if not _numeric_row(fields):
            continue
        following = [_split(lines[j], sep) for j in body[pos + 1:pos + 3]]
        if all(_numeric_row(f) and len(f) == len(fields) for f in following[:-1]) and (
                not following or _numeric_row(following[-1])):
            return i, len(fields)
    return None


def _units_row(fields: list[str]) -> bool:
    """A row of unit names under the header: no numbers, at least half of them known units."""
    names = [f.strip("[](){} ") for f in fields]
    known = sum(lookup(f) is not None for f in names if f)
    return not any(map(_is_number, fields)) and known > 0 and 2 * known >= sum(1 for f in names if f)


def _layout(lines: list[str], path: Path) -> _Layout:
    best = None
    for order, sep in enumerate(("\t", ";", ",", "|", None)):
        found = _data_start(lines, sep)
        if found and found[1] >= 2 and (best is None or (found[1], -found[0]) > (best[2], -best[1])):
            best = (sep, *found, order)
    if best is None:
        raise RigDataError("no data rows: no block of numeric rows with two or more columns found "
                           "(separators tried: tab, ';', ',', '|', blanks)", file=path)
    sep, first, width, _ = best
    sample = [f for line in lines[first:first + 50] for f in _split(line, sep)]
    decimal = "," if sep != "," and any(_COMMA_NUMBER.match(f) for f in sample) else "."
    above = [i for i in range(first) if lines[i].strip()]
    if not above:
        raise RigDataError(f"no header line with column names above the data (line {first + 1})", file=path)
    header, units_row = above[-1], None
    if len(above) > 1 and _units_row(_header_fields(lines[header], sep, width)):
        candidate = _header_fields(lines[above[-2]], sep, width)
        if len(candidate) == width and not any(map(_is_number, candidate)):
            header, units_row = above[-2], above[-1]
    names = _header_fields(lines[header], sep, width)
    if len(names) != width or any(map(_is_number, names)):
        raise RigDataError(f"no header line with column names above the data: line {header + 1} "
                           f"({lines[header].strip()[:60]!r}) has {len(names)} fields, the data rows "
                           f"{width} (separator {_sep_name(sep)})", file=path)
    return _Layout(sep, decimal, header, units_row, first, width)


def _sep_name(sep: str | None) -> str:
    return {"\t": "tab", None: "blanks"}.get(sep, repr(sep))


def _header_fields(line: str, sep: str | None, width: int) -> list[str]:
    fields = _split(line, sep)
    if sep is None and len(fields) != width:
        # blank-separated files may have names with single blanks, columns apart by two or more
        fields = [f for f in re.split(r"\t|\s{2,}", line.strip()) if f]
    return fields


def _preamble(lines: list[str], sep: str | None) -> dict[str, str]:
    """Key/value pairs of the lines above the header: ``key: value``, ``key = value`` (with or
    without a leading ``#``), or two fields apart by the separator. Free text is skipped."""
    meta = {}
    for line in lines:
        text = line.strip().lstrip("#%;/").strip()
        if not text:
            continue
        cut = [i for i in (text.find(":"), text.find("=")) if i > 0]
        if cut:
            key, value = text[:min(cut)].strip(), text[min(cut) + 1:].strip()
        else:
            parts = [p for p in _split(text, sep if sep else "\t") if p]
            if len(parts) != 2:
                continue
            key, value = parts
        if key and len(key) <= 80:
            meta[key] = value
    return meta


def _check_widths(lines: list[str], rows: list[int], lay: _Layout, path: Path, ends_clean: bool) -> None:
    if lay.sep is None:
        counts = [len(lines[i].split()) for i in rows]
    else:
        counts = [lines[i].count(lay.sep) + 1 for i in rows]
    bad = [k for k, c in enumerate(counts) if c != lay.width]
    if not bad:
        return
    k = bad[0]
    line, n = rows[k] + 1, counts[k]
    if k == len(rows) - 1 and n < lay.width:
        cut = "" if ends_clean else " and no line end"
        raise RigDataError(f"truncated: the last line ({line}) has {n} of {lay.width} fields{cut}; "
                           f"the file seems cut short", file=path)
    raise RigDataError(f"line {line} has {n} fields, the header has {lay.width} "
                       f"(separator {_sep_name(lay.sep)})", file=path)


def _text_cells(raw: Any, numbers: np.ndarray, lines: list[int] | None) -> TextCells | None:
    """Cells whose text is neither a number nor a missing-value mark."""
    strings = np.asarray(raw, dtype=object)
    nan = np.flatnonzero(np.isnan(numbers))
    hits = [k for k in nan if isinstance(strings[k], str) and strings[k].strip().lower() not in _MISSING]
    if not hits:
        return None
    first = tuple((int(k), None if lines is None else lines[k], strings[k].strip())
                  for k in hits[:_KEEP_TEXT])
    return TextCells(len(hits), first)


def _read_delimited(path: Path, text: str, sha: str) -> RawTable:
    import pandas as pd

    lines = text.splitlines()
    lay = _layout(lines, path)
    rows = [i for i in range(lay.first, len(lines)) if lines[i].strip()]
    _check_widths(lines, rows, lay, path, text.endswith(("\n", "\r")))
    headers = _header_fields(lines[lay.header], lay.sep, lay.width)
    names = [h or f"column {i + 1}" for i, h in enumerate(headers)]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise RigDataError(f"duplicate column names {dup} in the header (line {lay.header + 1})", file=path)
    row_units = (_header_fields(lines[lay.units_row], lay.sep, lay.width) if lay.units_row is not None
                 else [""] * lay.width)
    try:
        frame = pd.read_csv(io.StringIO("\n".join(lines[i] for i in rows)), sep=lay.sep or r"\s+",
                            decimal=lay.decimal, header=None, names=list(range(lay.width)),
                            skip_blank_lines=False, engine="c")
    except Exception as exc:  # pandas' parser errors carry no file name
        raise RigDataError(f"cannot parse the data rows: {exc}", file=path) from exc
    columns, units, text_cells = {}, {}, {}
    file_lines = [i + 1 for i in rows]
    for i, name in enumerate(names):
        series = frame[i]
        if series.dtype.kind in "biuf":
            values = series.to_numpy(dtype=float)
        else:
            cleaned = series.astype(object).where(series.notna(), None)
            if lay.decimal == ",":
                cleaned = cleaned.map(lambda s: s.replace(",", ".") if isinstance(s, str) else s)
            values = pd.to_numeric(cleaned, errors="coerce").to_numpy(dtype=float)
            cells = _text_cells(series.to_numpy(dtype=object), values, file_lines)
            if cells:
                text_cells[name] = cells
        if not headers[i] and np.all(np.isnan(values)) and name not in text_cells:
            continue  # an empty column after a trailing separator
        columns[name] = values
        units[name] = _column_unit(name, row_units[i].strip("[](){} ") or None)
    meta = _preamble(lines[:lay.header], lay.sep)
    notes = (f"separator {_sep_name(lay.sep)}, decimal mark {lay.decimal!r}, header on line {lay.header + 1}"
             + (f", units on line {lay.units_row + 1}" if lay.units_row is not None else "")
             + f", data from line {lay.first + 1}",)
    return RawTable(str(path), "csv", _time_column(columns), columns, units, meta, text_cells,
                    {}, {"name": "pandas", "version": pd.__version__}, sha, notes)


def _column_unit(header: str, stated: str | None) -> str | None:
    """Unit of a column: the header annotation, else a unit stated elsewhere (units row, LVM
    label, TDMS property), else a unit suffix of a time column name (``time_s``)."""
    bare, unit = split_header(header)
    if unit is None:
        unit = stated
    if unit is None:
        tokens = _tokens(bare)
        suffix = lookup(tokens[1]) if len(tokens) == 2 and tokens[0] in TIME_WORDS else None
        if suffix is not None and suffix.quantity == "time":
            unit = tokens[1]
    return unit


# ---------------------------------------------------------------------------------------------
# recognition of columns


def _tokens(name: str) -> list[str]:
    """Words of a bare column name: camelCase, letters/digits and punctuation split, lower case."""
    s = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name)
    s = re.sub(r"(?<=[A-Za-z])(?=\d)|(?<=\d)(?=[A-Za-z])", " ", s)
    words = [t for t in re.split(r"[^0-9a-z]+", s.lower()) if t]
    out = []
    for w in words:
        for kind in _COMPOUND_KINDS:
            if w.startswith(kind) and w[len(kind):] in _ALL_SIDES:
                out += [kind, w[len(kind):]]
                break
        else:
            out.append(w)
    return out


def _is_time(tokens: list[str]) -> bool:
    if tokens in (["x", "value"], ["xvalue"]):
        return True
    if not tokens or tokens[0] not in TIME_WORDS:
        return False
    rest = tokens[1:]
    return not rest or rest in (["rel"], ["relative"]) or (
        len(rest) == 1 and lookup(rest[0]) is not None and lookup(rest[0]).quantity == "time")


def recognise(header: str, unit: str | None = None) -> str | None:
    """The record channel a column header names, ``"time"``, or None.

    Recognised (case, separators and camelCase do not matter; a unit annotation is ignored):

    * time: ``time``, ``t``, ``Time [s]``, ``time_ms``, ``X_Value``, ``Zeit``, ``elapsed``;
    * kind: torque (``torque``, ``trq``, ``tq``, ``T``, ``M``, ``moment``), speed (``speed``,
      ``omega``, ``w``, ``n``, ``rpm``, ``velocity``), angle (``angle``, ``phi``, ``theta``,
      ``pulses``, ``counts``, ``cnt``, ``encoder``, ``position``);
    * side: input (``in``, ``input``, ``1``, ``drive``, ``motor``), output (``out``,
      ``output``, ``2``, ``brake``, ``load``, ``driven``).

    A header needs exactly one side and one kind (``torque_in``, ``Torque In``, ``T_in``,
    ``Trq1``, ``Brake torque``, ``omega_out``, ``n2``, ``Encoder 1``). When the name has a side
    and no kind word, or two kinds, the unit decides (``Drive [N m]``, ``Encoder speed [rpm]``).

    Parameters
    ----------
    header : str
        Column header as in the file.
    unit : str, optional
        Unit of the column when it is not in the header.

    Returns
    -------
    str or None
        A key of :data:`rigdata.record.CHANNELS`, ``"time"``, or None.
    """
    bare, annotated = split_header(header)
    tokens = _tokens(bare)
    if _is_time(tokens):
        return "time"
    words = set(tokens)
    sides = [s for s, w in SIDE_WORDS.items() if w & words]
    if len(sides) != 1:
        return None
    kinds = {k for k, w in KIND_WORDS.items() if w & words}
    found = lookup(annotated or unit or "")
    by_unit = {k for k, q in ACCEPTS.items() if found is not None and found.quantity in q} - {"time"}
    if len(kinds) > 1:
        kinds &= by_unit
    elif not kinds and not (words - SIDE_WORDS[sides[0]] - _FILLER):
        kinds = by_unit
    return f"{kinds.pop()}_{sides[0]}" if len(kinds) == 1 else None


def _time_column(columns: Mapping[str, np.ndarray]) -> str | None:
    found = [c for c in columns if recognise(c) == "time"]
    return found[0] if len(found) == 1 else None


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


def match_channels(raw: RawTable, mapping: Mapping[str, str | None] | None = None) -> dict[str, str]:
    """Columns of the record channels and of time: ``mapping`` first, recognition for the rest.

    Parameters
    ----------
    raw : RawTable
        From :func:`read_table`.
    mapping : mapping of str to str or None, optional
        Record channel (key of :data:`rigdata.record.CHANNELS`, or ``"time"``) -> column name
        (exact, or ignoring case and blanks, or without its unit annotation). None leaves a
        channel out that recognition would otherwise add.

    Returns
    -------
    dict of str to str
        Channel -> column; ``"time"`` only when the file has a time column.

    Raises
    ------
    RigDataError
        Unknown channel in ``mapping``, a mapped column missing, two columns recognised as one
        channel, a required channel with no column.
    """
    path = Path(raw.file)
    mapping = dict(mapping or {})
    unknown = set(mapping) - set(CHANNELS) - {"time"}
    if unknown:
        raise ValueError(f"`mapping` keys must be 'time' or one of {sorted(CHANNELS)}, got {sorted(unknown)}")
    names = list(raw.columns)
    chosen = {ch: _find_column(col, names, ch, path) for ch, col in mapping.items() if col is not None}
    if "time" not in mapping:
        candidates = [c for c in names if recognise(c) == "time" and c not in chosen.values()]
        if len(candidates) > 1:
            raise RigDataError(f"ambiguous: columns {candidates} all look like time; choose one with "
                               f"{_MAP_HINT.format(ch='time')}", file=path, channel="time")
        if candidates:
            chosen["time"] = candidates[0]
    found: dict[str, list[str]] = {}
    for col in names:
        if col in chosen.values():
            continue
        ch = recognise(col, raw.units.get(col))
        if ch in CHANNELS and ch not in mapping:
            found.setdefault(ch, []).append(col)
    for ch, cols in found.items():
        if len(cols) > 1:
            raise RigDataError(f"ambiguous: columns {cols} both match; choose one with "
                               f"{_MAP_HINT.format(ch=ch)}", file=path, channel=ch)
        chosen[ch] = cols[0]
    _require(chosen, names, path)
    return chosen


def _require(chosen: Mapping[str, str], names: list[str], path: Path) -> None:
    for ch in ("torque_in", "torque_out"):
        if ch not in chosen:
            raise RigDataError(f"missing: no column recognised as {ch}; columns found: {names}; name it "
                               f"with {_MAP_HINT.format(ch=ch)}", file=path, channel=ch)
    for shaft in SHAFTS:
        if f"speed_{shaft}" not in chosen and f"angle_{shaft}" not in chosen:
            raise RigDataError(f"missing: no column recognised as speed_{shaft} or angle_{shaft}; columns "
                               f"found: {names}; name one with {_MAP_HINT.format(ch=f'speed_{shaft}')}",
                               file=path, channel=f"speed_{shaft}")


# ---------------------------------------------------------------------------------------------
# from the table to the record


def _values(raw: RawTable, column: str, channel: str) -> np.ndarray:
    cells = raw.text_cells.get(column)
    if cells is not None:
        raise RigDataError(f"{cells.describe()} in column {column!r}", file=raw.file, channel=channel)
    return np.asarray(raw.columns[column], dtype=float)


def _unit(raw: RawTable, column: str, channel: str, units: Mapping[str, str]) -> Unit:
    kind = "time" if channel == "time" else channel.split("_")[0]
    given = units.get(channel, units.get(column))
    if given is not None:
        return parse_unit(given, kind=kind, column=column, file=raw.file, channel=channel)
    stated = raw.units.get(column)
    if stated is None:
        raise RigDataError(f"no unit: column {column!r} states none; give it with --unit {channel}=UNIT "
                           f"(read(..., units={{{channel!r}: UNIT}})), e.g. {', '.join(_examples(kind))}",
                           file=raw.file, channel=channel)
    return parse_unit(stated, kind=kind, column=column, file=raw.file, channel=channel)


def _examples(kind: str) -> list[str]:
    return {"torque": ["N m", "V"], "speed": ["rad/s", "rpm", "pulses/s"], "angle": ["rad", "deg", "counts"],
            "time": ["s", "ms"]}[kind]


def _header_number(meta: Mapping[str, str], keys: set[str]) -> tuple[str, float, str] | None:
    """A number from the header under one of ``keys`` (normalised): key, value, unit text."""
    for key, value in meta.items():
        bare, key_unit = split_header(key)
        if re.sub(r"[^a-z0-9]", "", bare.lower()) not in keys:
            continue
        m = re.match(r"^\s*([-+]?(?:\d+[.,]?\d*|[.,]\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$", str(value))
        if m:
            number = m.group(1).replace(",", ".") if "." not in m.group(1) else m.group(1)
            return key, float(number), (m.group(2) or key_unit or "")
    return None


def _time_from_header(raw: RawTable, n: int) -> tuple[np.ndarray, dict[str, Any]] | None:
    file = raw.file
    start = _header_number(raw.metadata, _START_KEYS)
    t0 = 0.0 if start is None else start[1] * parse_unit(start[2] or "s", kind="time", file=file,
                                                        channel="time").factor
    rate = _header_number(raw.metadata, _RATE_KEYS)
    if rate is not None:
        factor = _RATE_UNITS.get(normalise(rate[2]))
        if factor is None:
            raise RigDataError(f"header key {rate[0]!r}: unknown rate unit {rate[2]!r}; accepted: Hz, kHz, "
                               f"S/s, 1/s", file=file, channel="time")
        dt = 1.0 / (rate[1] * factor)
        source = f"header {rate[0]!r} = {raw.metadata[rate[0]]}"
    else:
        interval = _header_number(raw.metadata, _INTERVAL_KEYS)
        if interval is None:
            return None
        dt = interval[1] * parse_unit(interval[2] or "s", kind="time", file=file, channel="time").factor
        source = f"header {interval[0]!r} = {raw.metadata[interval[0]]}"
    if not (math.isfinite(dt) and dt > 0):
        raise RigDataError(f"sampling interval from the {source} is not positive", file=file, channel="time")
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


def _time_axis(raw: RawTable, chosen: Mapping[str, str], units: Mapping[str, str],
               n: int) -> tuple[np.ndarray, dict[str, Any], list[str]]:
    """Sample times [s]: the time column, else the channels' sampling, else the header's rate."""
    column = chosen.get("time")
    if column is not None:
        assumed = []
        if units.get("time", units.get(column)) is None and raw.units.get(column) is None:
            unit = parse_unit("s", kind="time")
            assumed.append(f"time column {column!r} states no unit: assumed s")
        else:
            unit = _unit(raw, column, "time", units)
        if raw.sampling:
            _time_from_sampling(raw, {k: v for k, v in chosen.items() if k != "time"}, n)
        t = _values(raw, column, "time") * unit.factor
        return t, {"column": column, "unit": unit.spelling, "source": "column"}, assumed
    for build in (_time_from_sampling(raw, chosen, n), _time_from_header(raw, n)):
        if build is not None:
            return build[0], build[1], []
    raise RigDataError("no time: no time column (names like 'time', 't', 'Time [s]', 'X_Value'), no "
                       "waveform timing and no sample rate or interval in the header (keys like "
                       f"'sample_rate: 1000 Hz', 'dt: 0.001 s'); columns found: {list(raw.columns)}; name "
                       f"the time column with {_MAP_HINT.format(ch='time')}", file=raw.file, channel="time")


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


def read(path: str | Path, format: str = "auto", mapping: Mapping[str, str | None] | None = None,
         units: Mapping[str, str] | None = None, sensitivity: float = SENSITIVITY,
         pulses_per_rev: int = PULSES_PER_REV) -> RigRecord:
    """Read a rig file into a validated record in SI units.

    Parameters
    ----------
    path : str or Path
        Delimited text (``.csv``, ``.tsv``, ``.txt``, ``.dat``), LabVIEW Measurement (``.lvm``)
        or NI TDMS (``.tdms``) file.
    format : {"auto", "csv", "lvm", "tdms"}
        See :func:`read_table`.
    mapping : mapping of str to str or None, optional
        Record channel (or ``"time"``) -> column; channels not named are recognised by their
        headers (:func:`recognise`). None drops a channel.
    units : mapping of str to str, optional
        Unit by channel or column name; overrides or supplies the file's units (``{"speed_in":
        "rpm"}``, ``{"time": "ms"}``).
    sensitivity : float
        Torque transducer output [V/(N m)] for channels in volts; default 0.1 (paper, section 4:
        Magtrol TMB 210, 100 mV/(N m)).
    pulses_per_rev : int
        Pulses per revolution for channels in pulse counts or pulses/s; default 60 (paper,
        section 4: Magtrol TMB 210).

    Returns
    -------
    RigRecord
        Time [s], torques [N m], speeds [rad/s], angles [rad]; ``provenance`` holds ``file``,
        ``format``, ``reader`` (name, version), ``sha256``, ``header`` (the file's key/value
        pairs), ``time`` (column or how the time axis was built), ``conversion``
        (sensitivity, pulses per revolution), ``notes``, ``assumptions`` and, when the header
        has a ``synthetic`` key, ``synthetic`` (``synthetic``, ``generator``, ``settings`` as
        written).

    Raises
    ------
    RigDataError
        Any problem with the file or its data, naming the file, the channel and the problem.
    ValueError
        Bad arguments (``format``, ``mapping`` keys, ``sensitivity``, ``pulses_per_rev``).
    """
    if not (isinstance(sensitivity, (int, float)) and math.isfinite(sensitivity) and sensitivity > 0):
        raise ValueError(f"`sensitivity` must be a positive number of V/(N m), got {sensitivity!r}")
    if not (isinstance(pulses_per_rev, (int, np.integer)) and pulses_per_rev > 0):
        raise ValueError(f"`pulses_per_rev` must be a positive integer, got {pulses_per_rev!r}")
    units = dict(units or {})
    raw = read_table(path, format)
    chosen = match_channels(raw, mapping)
    channels_of = {ch: col for ch, col in chosen.items() if ch != "time"}
    n = _lengths(raw, chosen)
    time, time_info, assumptions = _time_axis(raw, chosen, units, n)
    channels, sources, notes = {}, {}, list(raw.notes)
    for ch, col in channels_of.items():
        values = _values(raw, col, ch)
        unit = _unit(raw, col, ch, units)
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
    return RigRecord(time, channels, sources, provenance)


# ---------------------------------------------------------------------------------------------
# LabVIEW Measurement files

_LVM_SEPARATORS = {"tab": "\t", "comma": ",", "semicolon": ";", "space": " "}


def _lvm_data_lines(lines: list[str], sep: str) -> list[int]:
    """Line indices of the data rows, segment after segment, as lvm_read walks them."""
    rows, reading = [], False
    for i, line in enumerate(lines):
        first = line.split(sep, 1)[0]
        if first in ("***End_of_Header***", "LabVIEW Measurement"):
            continue
        if line in ("", sep):
            reading = False
        elif reading:
            rows.append(i)
        elif first == "X_Value":
            reading = True
    return rows


@dataclass(frozen=True)
class _Segment:
    names: list[str]          # Y channel names
    x: np.ndarray | None      # X values (X_Columns One or Multi)
    y: np.ndarray             # shape (rows, len(names))
    x0: list[float]
    dx: list[float]
    units: list[str | None]
    samples: list[float]


def _lvm_segment(seg: dict, k: int, x_columns: str, path: Path) -> _Segment:
    if "Channel names" not in seg or "data" not in seg:
        raise RigDataError(f"truncated: segment {k + 1} has no data rows (the file ends in its header?)",
                           file=path)
    first = 1 if x_columns == "No" else 0
    names = list(seg["Channel names"])
    if names[-1:] == ["Comment"]:
        names = names[:-1]
    data = np.asarray(seg["data"], dtype=float)
    if data.ndim != 2 or data.shape[0] == 0:
        raise RigDataError(f"truncated: segment {k + 1} has no data rows", file=path)
    if data.shape[1] < len(names):
        data = np.hstack([data, np.full((data.shape[0], len(names) - data.shape[1]), np.nan)])

    def per_column(key: str) -> list:
        values = list(seg.get(key, []))
        # a segment header row has the tag under the first column, values under the Y columns
        at = [j + first - 1 for j in range(len(names))]
        return [values[i] if 0 <= i < len(values) else None for i in at]

    y_index = [j for j, name in enumerate(names) if name != "X_Value"]
    x_index = [j for j, name in enumerate(names) if name == "X_Value"]
    x = None
    if x_index:
        xs = [data[:, j] for j in x_index]
        for j, other in zip(x_index[1:], xs[1:], strict=True):
            if not np.array_equal(xs[0], other, equal_nan=True):
                raise RigDataError(f"mixed sampling rates: segment {k + 1} has X columns with different "
                                   f"values (column {j + 1})", file=path)
        x = xs[0]

    x0, dx, samples = (_lvm_floats(per_column(key)) for key in ("X0", "Delta_X", "Samples"))
    labels = per_column("Y_Unit_Label")
    return _Segment([names[j] for j in y_index], x, data[:, y_index], [x0[j] for j in y_index],
                    [dx[j] for j in y_index], [(labels[j] or "").strip() or None for j in y_index],
                    [samples[j] for j in y_index])


def _lvm_floats(values: list) -> list[float]:
    return [float(v) if isinstance(v, (int, float)) else math.nan for v in values]


def _lvm_join(segments: list[_Segment], path: Path) -> list[str]:
    """Check that the segments continue one another; notes on what was joined."""
    ref = segments[0]
    dt = ref.dx[0]
    for k, seg in enumerate(segments):
        if seg.names != ref.names:
            raise RigDataError(f"segment {k + 1} has channels {seg.names}, segment 1 {ref.names}: segments "
                               f"with different channels cannot be joined", file=path)
        for name, d in zip(seg.names, seg.dx, strict=True):
            if math.isfinite(dt) and not (math.isfinite(d) and abs(d / dt - 1.0) <= RATE_TOLERANCE):
                raise RigDataError(f"mixed sampling rates: Delta_X {d:.6g} s in segment {k + 1}, {dt:.6g} s "
                                   f"for {ref.names[0]!r} in segment 1", file=path, channel=name)
        samples = {s for s in seg.samples if math.isfinite(s)}
        if len(samples) == 1 and seg.y.shape[0] < samples.pop():
            raise RigDataError(f"truncated: segment {k + 1} has {seg.y.shape[0]} rows, its header says "
                               f"Samples {max(seg.samples):g}", file=path)
        if k:
            prev = segments[k - 1]
            end = prev.x[-1] + dt if prev.x is not None else prev.x0[0] + dt * prev.y.shape[0]
            start = seg.x[0] if seg.x is not None else seg.x0[0]
            if math.isfinite(dt) and abs(start - end) > 0.5 * dt:
                raise RigDataError(f"segment {k + 1} starts at t = {start:.6g} s, segment {k} ends at "
                                   f"{end - dt:.6g} s with Delta_X {dt:.6g} s: the segments are not "
                                   f"contiguous (a gap or overlap); split the file", file=path)
    return [f"{len(segments)} LVM segments joined"] if len(segments) > 1 else []


def _lvm_rows(lines: list[str], sep: str, width: int, path: Path, ends_clean: bool) -> list[int]:
    """Line indices of the data rows; a row with fewer than ``width`` fields is an error (the
    last one, or one without a line end: the file was cut short)."""
    rows = _lvm_data_lines(lines, sep)
    for k, i in enumerate(rows):
        n = len(lines[i].split(sep))
        if n >= width and (ends_clean or k < len(rows) - 1):
            continue
        if k == len(rows) - 1:
            cut = "" if ends_clean else " and no line end"
            raise RigDataError(f"truncated: the last line ({i + 1}) has {n} of {width} fields{cut}; the file "
                               f"seems cut short", file=path)
        raise RigDataError(f"line {i + 1} has {n} fields, the header has {width}", file=path)
    return rows


def _lvm_text_cells(lines: list[str], rows: list[int], sep: str, decimal: str,
                    positions: Mapping[str, int], columns: Mapping[str, np.ndarray]) -> dict[str, TextCells]:
    """The text behind the NaN that lvm_read leaves, silently, for cells it cannot read."""
    cells = {}
    for name, j in positions.items():
        if not np.isnan(columns[name]).any():
            continue
        texts = np.array([lines[i].split(sep)[j].strip() for i in rows], dtype=object)
        numbers = np.array([float(t.replace(decimal, ".")) if _is_number(t) else math.nan for t in texts])
        found = _text_cells(texts, numbers, [i + 1 for i in rows])
        if found:
            cells[name] = found
    return cells


def _read_lvm(path: Path, text: str, sha: str) -> RawTable:
    import lvm_read

    try:
        lvm = lvm_read.read_str(text)
    except Exception as exc:  # lvm_read raises bare ValueError/KeyError/SyntaxError on bad files
        if "no data segment" in str(exc):
            raise RigDataError("truncated: no data segment after the LVM header", file=path) from exc
        raise RigDataError(f"cannot parse as LVM: {type(exc).__name__}: {exc}", file=path) from exc
    header = {k: str(v) for k, v in lvm.items() if isinstance(k, str) and k != "Segments"}
    x_columns = header.get("X_Columns", "One").strip()
    sep = _LVM_SEPARATORS.get(header.get("Separator", "Tab").strip().lower(), "\t")
    decimal = header.get("Decimal_Separator", ".").strip() or "."
    try:
        segments = [_lvm_segment(lvm[k], k, x_columns, path) for k in range(lvm["Segments"])]
    except RigDataError:
        raise
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise RigDataError(f"cannot parse as LVM: segment header incomplete ({type(exc).__name__}: {exc})",
                           file=path) from exc
    notes = _lvm_join(segments, path)
    ref = segments[0]
    dup = sorted({n for n in ref.names if ref.names.count(n) > 1})
    if dup:
        raise RigDataError(f"duplicate channel names {dup}", file=path)
    columns = {name: np.concatenate([s.y[:, j] for s in segments]) for j, name in enumerate(ref.names)}
    units = {name: _column_unit(name, ref.units[j]) for j, name in enumerate(ref.names)}
    sampling = {name: (ref.x0[j], ref.dx[j]) for j, name in enumerate(ref.names)
                if math.isfinite(ref.x0[j]) and math.isfinite(ref.dx[j])}
    time = None
    if ref.x is not None:
        dimension = (lvm[0].get("X_Dimension") or ["Time"])[0].strip() or "Time"
        if dimension.lower() != "time":
            raise RigDataError(f"X_Dimension is {dimension!r}, not Time: not a time record", file=path)
        time = "X_Value"
        columns = {time: np.concatenate([s.x for s in segments]), **columns}
        units[time] = "s"
    lines = text.splitlines()
    first = 1 if x_columns == "No" else 0
    all_names = [n for n in lvm[0]["Channel names"] if n != "Comment"]
    rows = _lvm_rows(lines, sep, first + len(all_names), path, text.endswith(("\n", "\r")))
    positions = {n: first + all_names.index(n) for n in ref.names}
    if time is not None:
        positions[time] = all_names.index("X_Value")
    text_cells = _lvm_text_cells(lines, rows, sep, decimal, positions, columns)
    return RawTable(str(path), "lvm", time, columns, units, header, text_cells, sampling,
                    {"name": "lvm_read", "version": getattr(lvm_read, "__version__", "unknown")}, sha,
                    tuple(notes))


# ---------------------------------------------------------------------------------------------
# TDMS files

_TDMS_DAMAGE = re.compile(r"last segment|less data|incomplete|not a multiple|cropping", re.I)


@contextlib.contextmanager
def _nptdms_warnings() -> Iterator[list[str]]:
    """Collect npTDMS' logged warnings (it reports a cut file only there) and keep them off the
    console while the file is read."""
    import nptdms.log

    messages: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            messages.append(record.getMessage())

    keep, mute = Keep(logging.WARNING), logging.Filter("rigdata.readers.muted")
    loggers = [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
               if name.startswith("nptdms")]
    console = getattr(getattr(nptdms.log, "log_manager", None), "console_handler", None)
    for lg in loggers:
        lg.addHandler(keep)
    if console is not None:
        console.addFilter(mute)
    try:
        yield messages
    finally:
        for lg in loggers:
            lg.removeHandler(keep)
        if console is not None:
            console.removeFilter(mute)


def _tdms_values(channel: Any) -> tuple[np.ndarray, TextCells | None, str | None]:
    data = channel[:]
    if np.issubdtype(data.dtype, np.datetime64):
        seconds = (data - data[0]) / np.timedelta64(1, "s") if data.size else data.astype(float)
        return np.asarray(seconds, dtype=float), None, "s"
    if data.dtype.kind in "biuf":
        return data.astype(float), None, None
    strings = np.asarray(data, dtype=object)
    numbers = np.array([float(s) if isinstance(s, str) and _is_number(s) else math.nan for s in strings])
    return numbers, _text_cells(strings, numbers, None), None


def _read_tdms(path: Path, data: bytes, sha: str) -> RawTable:
    import nptdms

    try:
        with _nptdms_warnings() as warnings:
            tdms = nptdms.TdmsFile.read(io.BytesIO(data))
            groups = [(g.name, c) for g in tdms.groups() for c in g.channels()]
            loaded = [(g, c, *_tdms_values(c)) for g, c in groups]
    except Exception as exc:  # npTDMS raises ValueError, KeyError, struct.error, EOFError ...
        raise RigDataError(f"cannot read as TDMS ({type(exc).__name__}: {exc}); the file may be cut short "
                           f"or damaged", file=path) from exc
    damage = [w for w in warnings if _TDMS_DAMAGE.search(w)]
    if damage:
        raise RigDataError(f"truncated or damaged TDMS file: npTDMS reports {damage[0]!r}", file=path)
    if not loaded:
        raise RigDataError("no channels in the TDMS file", file=path)
    plain = [c.name for _, c, *_ in loaded]
    columns, units, text_cells, sampling = {}, {}, {}, {}
    for group, channel, values, cells, implied in loaded:
        name = channel.name if plain.count(channel.name) == 1 else f"{group}/{channel.name}"
        props = channel.properties
        stated = props.get("unit_string") or props.get("NI_UnitDescription") or implied
        columns[name] = values
        units[name] = _column_unit(name, str(stated).strip() or None if stated is not None else None)
        if cells:
            text_cells[name] = cells
        if "wf_increment" in props:
            start = props.get("wf_start_offset", 0.0)
            sampling[name] = (float(start) if isinstance(start, (int, float)) else 0.0,
                              float(props["wf_increment"]))
    meta = {str(k): str(v) for k, v in tdms.properties.items()}
    return RawTable(str(path), "tdms", _time_column(columns), columns, units, meta, text_cells,
                    sampling, {"name": "npTDMS", "version": nptdms.__version__},
                    sha, tuple(f"npTDMS: {w}" for w in warnings))
