"""Delimited text of any separator (tab, ``;``, ``,``, ``|``, blanks) and decimal mark, with a
``key: value`` preamble and units in headers or a units row. The layout is found, not configured.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rigdata.readers.channels import column_unit, time_column
from rigdata.readers.table import RawTable, TextCells, find_text_cells, is_number
from rigdata.readers.timestamps import timestamp_seconds
from rigdata.record import RigDataError
from rigdata.units import lookup

__all__ = ["Layout", "layout", "preamble", "read_delimited"]

COMMA_NUMBER = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")
#: Separators tried, in order of preference on a tie (None: runs of blanks).
SEPARATORS = ("\t", ";", ",", "|", None)


@dataclass(frozen=True)
class Layout:
    """Where a delimited file's parts are (0-based line indices)."""

    sep: str | None          # None: runs of blanks
    decimal: str
    header: int              # line index of the column names
    units_row: int | None    # line index of a units row, if any
    first: int               # line index of the first data row
    width: int               # fields per data row


def split(line: str, sep: str | None) -> list[str]:
    """Fields of ``line`` split at ``sep`` (None: runs of blanks), quotes and blanks removed."""
    return line.split() if sep is None else [f.strip().strip('"').strip() for f in line.split(sep)]


def separator_name(sep: str | None) -> str:
    """How messages name a separator."""
    return {"\t": "tab", None: "blanks"}.get(sep, repr(sep))


def _numeric_row(fields: list[str]) -> bool:
    """Two or more fields, mostly numbers, none holding a tab or semicolon (a wrong separator)."""
    return (len(fields) >= 2 and 2 * sum(map(is_number, fields)) > len(fields)
            and not any("\t" in f or ";" in f for f in fields))


def _data_start(lines: list[str], sep: str | None, limit: int = 2000) -> tuple[int, int] | None:
    """First line that opens a block of numeric rows of one width, with the width."""
    body = [i for i, line in enumerate(lines[:limit]) if line.strip()]
    for pos, i in enumerate(body):
        fields = split(lines[i], sep)
        if not _numeric_row(fields):
            continue
        following = [split(lines[j], sep) for j in body[pos + 1:pos + 3]]
        if all(_numeric_row(f) and len(f) == len(fields) for f in following[:-1]) and (
                not following or _numeric_row(following[-1])):
            return i, len(fields)
    return None


def _units_row(fields: list[str]) -> bool:
    """A row of unit names under the header: no numbers, at least half of them known units."""
    names = [f.strip("[](){} ") for f in fields]
    known = sum(lookup(f) is not None for f in names if f)
    return not any(map(is_number, fields)) and known > 0 and 2 * known >= sum(1 for f in names if f)


def header_fields(line: str, sep: str | None, width: int) -> list[str]:
    """Fields of header ``line`` for ``width`` data fields; blank-separated names may hold single blanks."""
    fields = split(line, sep)
    if sep is None and len(fields) != width:
        # blank-separated files may have names with single blanks, columns apart by two or more
        fields = [f for f in re.split(r"\t|\s{2,}", line.strip()) if f]
    return fields


def _separator(lines: list[str], path: Path) -> tuple[str | None, int, int]:
    """Separator with the widest numeric block (earliest on a tie), its start and width."""
    best = None
    for order, sep in enumerate(SEPARATORS):
        found = _data_start(lines, sep)
        if found and found[1] >= 2 and (best is None or (found[1], -found[0]) > (best[2], -best[1])):
            best = (sep, *found, order)
    if best is None:
        raise RigDataError("no data rows: no block of numeric rows with two or more columns found "
                           "(separators tried: tab, ';', ',', '|', blanks)", file=path)
    return best[0], best[1], best[2]


def layout(lines: list[str], path: Path) -> Layout:
    """Separator, decimal mark, header, units row and first data row; RigDataError when none fits."""
    sep, first, width = _separator(lines, path)
    sample = [f for line in lines[first:first + 50] for f in split(line, sep)]
    decimal = "," if sep != "," and any(COMMA_NUMBER.match(f) for f in sample) else "."
    above = [i for i in range(first) if lines[i].strip()]
    if not above:
        raise RigDataError(f"no header line with column names above the data (line {first + 1})", file=path)
    header = above[-1]
    units_row = None
    units = header_fields(lines[header], sep, width)
    if len(above) > 1 and len(units) == width and _units_row(units):
        candidate = header_fields(lines[above[-2]], sep, width)
        if len(candidate) == width and not any(map(is_number, candidate)):
            header = above[-2]
            units_row = above[-1]
    names = header_fields(lines[header], sep, width)
    if len(names) != width or any(map(is_number, names)):
        raise RigDataError(f"no header line with column names above the data: line {header + 1} "
                           f"({lines[header].strip()[:60]!r}) has {len(names)} fields, the data rows "
                           f"{width} (separator {separator_name(sep)})", file=path)
    return Layout(sep, decimal, header, units_row, first, width)


def preamble(lines: list[str], sep: str | None) -> dict[str, str]:
    """Key/value pairs above the header: ``key: value``, ``key = value`` (``#`` optional), or two fields
    apart by ``sep``; free text skipped.
    """
    meta = {}
    for line in lines:
        text = line.strip().lstrip("#%;/").strip()
        if not text:
            continue
        cut = [i for i in (text.find(":"), text.find("=")) if i > 0]
        if cut:
            key = text[:min(cut)].strip()
            value = text[min(cut) + 1:].strip()
        else:
            parts = [p for p in split(text, sep if sep else "\t") if p]
            if len(parts) != 2:
                continue
            key, value = parts
        if key and len(key) <= 80:
            meta[key] = value
    return meta


def _check_widths(lines: list[str], rows: list[int], lay: Layout, path: Path, ends_clean: bool) -> None:
    if lay.sep is None:
        counts = [len(lines[i].split()) for i in rows]
    else:
        counts = [lines[i].count(lay.sep) + 1 for i in rows]
    bad = [k for k, c in enumerate(counts) if c != lay.width]
    if not bad:
        return
    k = bad[0]
    line = rows[k] + 1
    n = counts[k]
    if k == len(rows) - 1 and n < lay.width:
        cut = "" if ends_clean else " and no line end"
        raise RigDataError(f"truncated: the last line ({line}) has {n} of {lay.width} fields{cut}; "
                           f"the file seems cut short", file=path)
    raise RigDataError(f"line {line} has {n} fields, the header has {lay.width} "
                       f"(separator {separator_name(lay.sep)})", file=path)


def _headers(lines: list[str], lay: Layout, path: Path) -> tuple[list[str], list[str], list[str]]:
    """Header fields as written, column names (blank ones named by position), units row fields."""
    headers = header_fields(lines[lay.header], lay.sep, lay.width)
    names = [h or f"column {i + 1}" for i, h in enumerate(headers)]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise RigDataError(f"duplicate column names {dup} in the header (line {lay.header + 1})", file=path)
    row_units = (header_fields(lines[lay.units_row], lay.sep, lay.width) if lay.units_row is not None
                 else [""] * lay.width)
    return headers, names, row_units


def _pandas() -> Any:
    """pandas, imported on first use (about 0.5 s that LVM and TDMS files never need)."""
    import pandas

    return pandas


def _frame(lines: list[str], rows: list[int], lay: Layout, path: Path) -> Any:
    try:
        return _pandas().read_csv(io.StringIO("\n".join(lines[i] for i in rows)), sep=lay.sep or r"\s+",
                           decimal=lay.decimal, header=None, names=list(range(lay.width)),
                           skip_blank_lines=False, engine="c")
    except (ValueError, OverflowError) as exc:  # pandas' ParserError (a ValueError) names no file
        quoted = [i for i in rows if lines[i].count('"') % 2]
        if quoted:  # pandas reads on to the end of the file for the closing quote
            raise RigDataError(f"line {quoted[0] + 1} has an unbalanced double quote ('\"'): a data "
                               f"row cannot be read from it", file=path) from exc
        raise RigDataError(f"cannot parse the data rows (pandas: {exc})", file=path) from exc


def _column(series: Any, decimal: str,
            file_lines: list[int]) -> tuple[np.ndarray, TextCells | None, str | None]:
    """A parsed column as floats, its text cells, and the first of its absolute timestamps (then the
    floats are seconds from it).
    """
    if series.dtype.kind in "biuf":
        return series.to_numpy(dtype=float), None, None
    cells = series.to_list()
    stamps = timestamp_seconds(cells) if all(isinstance(c, str) for c in cells) else None
    if stamps is not None:
        return stamps[0], None, stamps[1]
    cleaned = series.astype(object).where(series.notna(), None)
    if decimal == ",":
        cleaned = cleaned.map(lambda s: s.replace(",", ".") if isinstance(s, str) else s)
    values = _pandas().to_numeric(cleaned, errors="coerce").to_numpy(dtype=float)
    return values, find_text_cells(series.to_numpy(dtype=object), values, file_lines), None


def _notes(lay: Layout) -> tuple[str, ...]:
    units = f", units on line {lay.units_row + 1}" if lay.units_row is not None else ""
    return (f"separator {separator_name(lay.sep)}, decimal mark {lay.decimal!r}, header on line "
            f"{lay.header + 1}{units}, data from line {lay.first + 1}",)


def read_delimited(path: Path, text: str, sha: str) -> RawTable:
    """RawTable of delimited file ``path`` from its decoded ``text`` and ``sha`` (SHA-256)."""
    lines = text.splitlines()
    lay = layout(lines, path)
    rows = [i for i in range(lay.first, len(lines)) if lines[i].strip()]
    _check_widths(lines, rows, lay, path, text.endswith(("\n", "\r")))
    headers, names, row_units = _headers(lines, lay, path)
    frame = _frame(lines, rows, lay, path)
    columns = {}
    units = {}
    text_cells = {}
    file_lines = [k + 1 for k in rows]
    notes = list(_notes(lay))
    for i, name in enumerate(names):
        values, cells, first_stamp = _column(frame[i], lay.decimal, file_lines)
        if cells:
            text_cells[name] = cells
        if not headers[i] and np.all(np.isnan(values)) and name not in text_cells:
            continue  # an empty column after a trailing separator
        columns[name] = values
        units[name] = column_unit(name, row_units[i].strip("[](){} ") or None)
        if first_stamp is not None:
            units[name] = "s"
            notes.append(f"column {name!r}: absolute timestamps from {first_stamp} converted to seconds "
                         f"from the first")
    meta = preamble(lines[:lay.header], lay.sep)
    return RawTable(str(path), "csv", time_column(columns), columns, units, meta, text_cells, {},
                    {"name": "pandas", "version": _pandas().__version__}, sha, tuple(notes))
