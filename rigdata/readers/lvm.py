"""LabVIEW Measurement files (``.lvm``), parsed by ``lvm_read.read_str``; continuing segments joined.

lvm_read silently leaves NaN in unreadable cells, accepts short rows and fails on bad headers with
bare KeyError/IndexError/SyntaxError: all are checked here against the text.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import lvm_read
import numpy as np

from rigdata.readers.channels import column_unit
from rigdata.readers.table import RawTable, TextCells, cell_value, find_text_cells
from rigdata.record import RATE_TOLERANCE, RigDataError

__all__ = ["read_lvm"]

SEPARATORS = {"tab": "\t", "comma": ",", "semicolon": ";", "space": " "}
#: What lvm_read raises on a file it cannot parse (it wraps nothing).
PARSE_ERRORS = (ValueError, LookupError, TypeError, AttributeError, ArithmeticError, SyntaxError)


@dataclass(frozen=True)
class Segment:
    """One LVM data segment: Y channel names, X and Y values, and per Y channel its header."""

    names: list[str]          # Y channel names
    x: np.ndarray | None      # X values (X_Columns One or Multi)
    y: np.ndarray             # shape (rows, len(names))
    x0: list[float]
    dx: list[float]
    units: list[str | None]
    samples: list[float]


def _data_lines(lines: list[str], sep: str) -> list[int]:
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


def _floats(values: list) -> list[float]:
    return [float(v) if isinstance(v, (int, float)) else math.nan for v in values]


def _per_column(seg: dict, key: str, count: int, first: int) -> list:
    """A segment header tag's value for each of ``count`` columns (tag under the first column)."""
    values = list(seg.get(key, []))
    at = [j + first - 1 for j in range(count)]
    return [values[i] if 0 <= i < len(values) else None for i in at]


def _segment_data(seg: dict, k: int, path: Path) -> tuple[list[str], np.ndarray]:
    """Column names (without a trailing ``Comment``) and the values, padded to one per name."""
    if "Channel names" not in seg or "data" not in seg:
        raise RigDataError(f"truncated: segment {k + 1} has no data rows (the file ends in its header?)",
                           file=path)
    names = list(seg["Channel names"])
    if names[-1:] == ["Comment"]:
        names = names[:-1]
    data = np.asarray(seg["data"], dtype=float)
    if data.ndim != 2 or data.shape[0] == 0:
        raise RigDataError(f"truncated: segment {k + 1} has no data rows", file=path)
    if data.shape[1] < len(names):
        data = np.hstack([data, np.full((data.shape[0], len(names) - data.shape[1]), np.nan)])
    return names, data


def _x_values(names: list[str], data: np.ndarray, k: int, path: Path) -> np.ndarray | None:
    """The X column's values (all X columns must agree), None without one."""
    x_index = [j for j, name in enumerate(names) if name == "X_Value"]
    if not x_index:
        return None
    xs = [data[:, j] for j in x_index]
    for j, other in zip(x_index[1:], xs[1:], strict=True):
        if not np.array_equal(xs[0], other, equal_nan=True):
            raise RigDataError(f"mixed sampling rates: segment {k + 1} has X columns with different "
                               f"values (column {j + 1})", file=path)
    return xs[0]


def segment(seg: dict, k: int, x_columns: str, path: Path) -> Segment:
    """Segment ``k`` (0-based) of lvm_read's output, checked (``x_columns``: header's ``X_Columns``)."""
    names, data = _segment_data(seg, k, path)
    first = 1 if x_columns == "No" else 0
    y_index = [j for j, name in enumerate(names) if name != "X_Value"]
    x = _x_values(names, data, k, path)
    x0, dx, samples = (_floats(_per_column(seg, key, len(names), first))
                       for key in ("X0", "Delta_X", "Samples"))
    labels = _per_column(seg, "Y_Unit_Label", len(names), first)
    return Segment([names[j] for j in y_index], x, data[:, y_index], [x0[j] for j in y_index],
                   [dx[j] for j in y_index], [(labels[j] or "").strip() or None for j in y_index],
                   [samples[j] for j in y_index])


def _check_segment(seg: Segment, k: int, ref: Segment, path: Path) -> None:
    """Same channels and sampling interval as segment 1, and as many rows as the header says."""
    if not seg.names:
        raise RigDataError(f"segment {k + 1} has no channels besides X_Value: its header is incomplete "
                           f"(a blank line inside it?)", file=path)
    dt = ref.dx[0]
    bad = [d for d in seg.dx if not (d > 0.0 or math.isnan(d))]
    if bad:
        raise RigDataError(f"segment {k + 1} has Delta_X {bad[0]:g} s: a sampling interval must be "
                           f"positive", file=path)
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


def _check_contiguous(prev: Segment, seg: Segment, k: int, dt: float, path: Path) -> None:
    end = prev.x[-1] + dt if prev.x is not None else prev.x0[0] + dt * prev.y.shape[0]
    start = seg.x[0] if seg.x is not None else seg.x0[0]
    if math.isfinite(dt) and abs(start - end) > 0.5 * dt:
        raise RigDataError(f"segment {k + 1} starts at t = {start:.6g} s, segment {k} ends at "
                           f"{end - dt:.6g} s with Delta_X {dt:.6g} s: the segments are not "
                           f"contiguous (a gap or overlap); split the file", file=path)


def join(segments: list[Segment], path: Path) -> list[str]:
    """Check that ``segments`` continue one another; notes on what was joined, for provenance."""
    ref = segments[0]
    for k, seg in enumerate(segments):
        _check_segment(seg, k, ref, path)
        if k:
            _check_contiguous(segments[k - 1], seg, k, ref.dx[0], path)
    return [f"{len(segments)} LVM segments joined"] if len(segments) > 1 else []


def data_rows(lines: list[str], sep: str, width: int, path: Path, ends_clean: bool) -> list[int]:
    """Line indices of the data rows; one with fewer than ``width`` fields is an error (file cut short)."""
    rows = _data_lines(lines, sep)
    for k, i in enumerate(rows):
        n = len(lines[i].split(sep))
        if n >= width and (ends_clean or k < len(rows) - 1):
            continue
        if k == len(rows) - 1 and n >= width:  # every field, but no line end: LabVIEW ends each row
            raise RigDataError(f"truncated: the last line ({i + 1}) has no line end (its last value may be "
                               f"cut short); the file seems cut short", file=path)
        if k == len(rows) - 1:
            cut = "" if ends_clean else " and no line end"
            raise RigDataError(f"truncated: the last line ({i + 1}) has {n} of {width} fields{cut}; the file "
                               f"seems cut short", file=path)
        raise RigDataError(f"line {i + 1} has {n} fields, the header has {width}", file=path)
    return rows


def text_cells(lines: list[str], rows: list[int], sep: str, decimal: str,
               positions: Mapping[str, int], columns: Mapping[str, np.ndarray]) -> dict[str, TextCells]:
    """Per column, the text behind the NaN lvm_read leaves for cells it cannot read."""
    cells = {}
    for name, j in positions.items():
        if not np.isnan(columns[name]).any():
            continue
        texts = np.array([lines[i].split(sep)[j].strip() for i in rows], dtype=object)
        numbers = np.array([cell_value(t, decimal) for t in texts])
        found = find_text_cells(texts, numbers, [i + 1 for i in rows])
        if found:
            cells[name] = found
    return cells


END_OF_HEADER = "***End_of_Header***"
NUMBER_TAGS = ("Samples", "X0", "Delta_X")
"""Segment-header tags whose values lvm_read reads as Python number literals (with ``Channels``,
a whole number)."""


def _tagged_lines(text: str) -> tuple[list[str], list[str], str]:
    """Lines, each line's tag (first field, exact as lvm_read compares) and lvm_read's separator (tab by
    default).
    """
    lines = text.splitlines()
    tagged = [line.strip() for line in lines[:22] if line.startswith("Separator")]
    sep = tagged[0][9] if tagged and len(tagged[0]) > 9 else "\t"
    return lines, [line.split(sep, 1)[0] for line in lines], sep


def _header_end(tags: list[str]) -> int | None:
    """Index of the file header's ``***End_of_Header***`` line, None without one."""
    return next((i for i, tag in enumerate(tags) if tag.strip() == END_OF_HEADER), None)


def _missing_data(text: str) -> str | None:
    """Where the text ends when a header has no data section after it (cut short), else None.

    Walks the lines as lvm_read does, which reports such a file only as an internal exception.
    """
    lines, tags, sep = _tagged_lines(text)
    ends = f"the file ends at line {len(lines)}"
    end = _header_end(tags)
    if end is None:
        return f"truncated: header without data section ({ends}, inside the file header)"
    segment = 0
    state = "after header"
    for line, tag in zip(lines[end + 1:], tags[end + 1:], strict=True):
        if line in ("", sep):
            state = "blank"
        elif state == "blank":
            segment += 1
            state = "data" if tag.strip() == "X_Value" else "segment header"
        elif tag.strip() == "X_Value" and state == "segment header":
            state = "data"
    if state == "segment header":
        return f"truncated: header without data section ({ends}, inside the header of segment {segment})"
    if segment == 0:
        return f"truncated: header without data section ({ends}: nothing after the file header)"
    return None


def _header_problem(text: str) -> str | None:
    """First header line lvm_read cannot read, in words, or None."""
    lines, tags, sep = _tagged_lines(text)
    end = _header_end(tags)
    end = len(lines) if end is None else end
    decimal = "."
    for i, (line, tag) in enumerate(zip(lines[:end], tags[:end], strict=True)):
        fields = line.split(sep)
        if i and line in ("", sep):
            return f"line {i + 1}: a blank line inside the file header (before its {END_OF_HEADER})"
        if line.startswith("Separator") and len(line.strip()) <= 9:
            return f"line {i + 1}: the Separator tag has no value"
        if tag == "Decimal_Separator" and len(fields) != 2:
            return (f"line {i + 1}: the Decimal_Separator line has {len(fields)} fields, the tag and "
                    f"one value expected")
        if tag == "Decimal_Separator":
            decimal = fields[1]
    return _segment_problem(lines, tags, sep, decimal, end + 1)


def _segment_problem(lines: list[str], tags: list[str], sep: str, decimal: str,
                     start: int) -> str | None:
    """:func:`_header_problem` for the segments from line ``start`` on."""
    segment = 0
    named = True
    for i in range(start, len(lines)):
        tag = tags[i]
        if lines[i] in ("", sep):
            if not named:
                return (f"line {i + 1}: segment {segment} ends before its X_Value column-names "
                        f"line (a blank line where its header or data should be)")
            segment += 1
            named = False
        elif tag.strip() == "X_Value":
            if tag != "X_Value":
                return f"line {i + 1}: the column-names line starts with {tag!r}, not 'X_Value'"
            named = True
        elif not named and (tag == "Channels" or tag in NUMBER_TAGS):
            fields = lines[i].split(sep)
            values = fields[1:2] if tag == "Channels" else [v for v in fields[1:] if v]
            for value in values or [""]:
                if not _literal_number(value if tag == "Channels" else value.replace(decimal, "."),
                                       whole=tag == "Channels"):
                    comma = (" (a decimal comma, and no Decimal_Separator tag in the file header?)"
                             if decimal == "." and "," in value else "")
                    return (f"line {i + 1}: the {tag} value {value!r} of segment {segment} is not "
                            f"{'a whole number' if tag == 'Channels' else 'a number'}{comma}")
    return None


def _literal_number(text: str, whole: bool) -> bool:
    """Whether lvm_read's ``ast.literal_eval`` reads ``text`` as a number (an int when ``whole``)."""
    try:
        value = ast.literal_eval(text)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return False
    kinds = (int,) if whole else (int, float)
    return isinstance(value, kinds) and not isinstance(value, bool)


def _parse(text: str, path: Path) -> tuple[Any, dict]:
    """lvm_read's result and the file header's tags as text."""
    try:
        lvm = lvm_read.read_str(text)
    except PARSE_ERRORS as exc:  # lvm_read raises bare ValueError/KeyError/SyntaxError on bad files
        why = _missing_data(text) or _header_problem(text)
        if why is not None:
            raise RigDataError(why, file=path) from exc
        if "no data segment" in str(exc):  # lvm_read's own sentence: the separator matches no line
            raise RigDataError(f"cannot parse as LVM: {exc}", file=path) from exc
        raise RigDataError(f"cannot parse as LVM: {type(exc).__name__}: {exc}", file=path) from exc
    return lvm, {k: str(v) for k, v in lvm.items() if isinstance(k, str) and k != "Segments"}


def _segments(lvm: Any, x_columns: str, path: Path) -> list[Segment]:
    try:
        return [segment(lvm[k], k, x_columns, path) for k in range(lvm["Segments"])]
    except RigDataError:
        raise
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise RigDataError(f"cannot parse as LVM: segment header incomplete ({type(exc).__name__}: {exc})",
                           file=path) from exc


def _time(lvm: Any, segments: list[Segment], path: Path) -> np.ndarray | None:
    """The X values of every segment, joined; None when the file has no X column."""
    if segments[0].x is None:
        return None
    dimension = (lvm[0].get("X_Dimension") or ["Time"])[0].strip() or "Time"
    if dimension.lower() != "time":
        raise RigDataError(f"X_Dimension is {dimension!r}, not Time: not a time record", file=path)
    return np.concatenate([s.x for s in segments])


def read_lvm(path: Path, text: str, sha: str) -> RawTable:
    """RawTable of LabVIEW Measurement file ``path`` from its decoded ``text`` and ``sha`` (SHA-256)."""
    lvm, header = _parse(text, path)
    x_columns = header.get("X_Columns", "One").strip()
    sep = SEPARATORS.get(header.get("Separator", "Tab").strip().lower(), "\t")
    segments = _segments(lvm, x_columns, path)
    notes = join(segments, path)
    ref = segments[0]
    dup = sorted({n for n in ref.names if ref.names.count(n) > 1})
    if dup:
        raise RigDataError(f"duplicate channel names {dup}", file=path)
    columns = {name: np.concatenate([s.y[:, j] for s in segments]) for j, name in enumerate(ref.names)}
    units = {name: column_unit(name, ref.units[j]) for j, name in enumerate(ref.names)}
    sampling = {name: (ref.x0[j], ref.dx[j]) for j, name in enumerate(ref.names)
                if math.isfinite(ref.x0[j]) and math.isfinite(ref.dx[j])}
    x = _time(lvm, segments, path)
    time = None if x is None else "X_Value"
    if time is not None:
        columns, units[time] = {time: x, **columns}, "s"
    lines = text.splitlines()
    first = 1 if x_columns == "No" else 0
    all_names = [n for n in lvm[0]["Channel names"] if n != "Comment"]
    rows = data_rows(lines, sep, first + len(all_names), path, text.endswith(("\n", "\r")))
    positions = {n: first + all_names.index(n) for n in ref.names}
    if time is not None:
        positions[time] = all_names.index("X_Value")
    decimal = header.get("Decimal_Separator", ".").strip() or "."
    cells = text_cells(lines, rows, sep, decimal, positions, columns)
    return RawTable(str(path), "lvm", time, columns, units, header, cells, sampling,
                    {"name": "lvm_read", "version": getattr(lvm_read, "__version__", "unknown")}, sha,
                    tuple(notes))
