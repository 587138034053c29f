"""Parquet (pyarrow) and Excel .xlsx (openpyxl) rig files through pandas: columns by name, units from
``[unit]`` in a name, a units row, or Parquet field metadata; key/value metadata from the schema,
``DataFrame.attrs``, rows above the header or a two-column sheet.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pandas as pd

from rigdata.readers.binary import require
from rigdata.readers.frame import frame_table
from rigdata.readers.table import RawTable, is_number
from rigdata.record import RigDataError

__all__ = ["read_parquet", "read_xlsx"]

#: Parquet field metadata keys that hold a unit.
UNIT_KEYS = (b"unit", b"units", b"Unit")


def _schema_metadata(schema: Any) -> dict[str, str]:
    """Key/value metadata of a Parquet schema, pandas' own block left out and its ``attrs`` unpacked."""
    meta = {}
    for key, value in (schema.metadata or {}).items():
        name = key.decode(errors="replace")
        text = value.decode(errors="replace")
        if name == "pandas":
            continue
        if name == "PANDAS_ATTRS":
            try:
                meta.update({str(k): str(v) for k, v in json.loads(text).items()})
            except (ValueError, AttributeError):
                meta[name] = text
            continue
        meta[name] = text
    return meta


def read_parquet(path: Path, data: bytes, sha: str) -> RawTable:
    """RawTable of Parquet file ``path`` from ``data`` and ``sha``; RigDataError if pyarrow is missing or
    the file is damaged.
    """
    pyarrow = require("pyarrow", "Parquet files", path)
    parquet = require("pyarrow.parquet", "Parquet files", path)
    try:
        table = parquet.read_table(io.BytesIO(data))
    except (pyarrow.ArrowException, OSError, ValueError) as exc:
        raise RigDataError(f"damaged Parquet file: pyarrow cannot read it ({exc})", file=path) from exc
    units = {}
    for fld in table.schema:
        found = [fld.metadata[k] for k in UNIT_KEYS if fld.metadata and k in fld.metadata]
        if found:
            units[fld.name] = found[0].decode(errors="replace")
    frame = table.to_pandas()
    return frame_table(frame.reset_index(drop=True), str(path), "parquet", units=units,
                       metadata=_schema_metadata(table.schema), sha=sha,
                       reader={"name": "pyarrow", "version": pyarrow.__version__})


def _filled(row: list[Any]) -> list[Any]:
    """The non-empty cells of a row."""
    return [c for c in row if not (c is None or (isinstance(c, float) and c != c) or c == "")]


def _is_numeric_row(row: list[Any]) -> bool:
    """Whether every filled cell of ``row`` is a number (or a number as text)."""
    cells = _filled(row)
    return bool(cells) and all(not isinstance(c, str) or is_number(c) for c in cells)


def _header_row(rows: list[list[Any]]) -> int | None:
    """Index of the column-name row: all text, two or more cells, followed (after an optional units row)
    by numbers; None if there is none.
    """
    for k, row in enumerate(rows[:-1]):
        cells = _filled(row)
        if len(cells) < 2 or not all(isinstance(c, str) for c in cells):
            continue
        after = rows[k + 1] if _is_numeric_row(rows[k + 1]) or k + 2 >= len(rows) else rows[k + 2]
        if _is_numeric_row(after):
            return k
    return None


def _key_values(rows: list[list[Any]]) -> dict[str, str]:
    """``key: value`` pairs from rows of two filled cells."""
    meta = {}
    for row in rows:
        cells = _filled(row)
        if len(cells) == 2 and isinstance(cells[0], str):
            meta[cells[0].strip().rstrip(":").strip()] = str(cells[1])
    return meta


def _sheet_table(rows: list[list[Any]], top: int) -> tuple[dict[str, list], dict[str, str], int]:
    """Columns by header name below row ``top``, units from a units row, and the first data row."""
    names = rows[top]
    units_row = rows[top + 1] if top + 1 < len(rows) and not _is_numeric_row(rows[top + 1]) else None
    start = top + 1 + (units_row is not None)
    columns = {}
    units = {}
    for j, name in enumerate(names):
        if not isinstance(name, str) or not name.strip():
            continue
        columns[name.strip()] = [r[j] if j < len(r) else None for r in rows[start:]]
        if units_row is not None and j < len(units_row) and isinstance(units_row[j], str):
            units[name.strip()] = units_row[j].strip().strip("[]")
    return columns, units, start


def read_xlsx(path: Path, data: bytes, sha: str) -> RawTable:
    """RawTable of the first sheet of Excel workbook ``path`` with a header row over numbers; metadata from
    two-cell rows above it and from two-column sheets. RigDataError if openpyxl is missing or no sheet
    holds a table.
    """
    openpyxl = require("openpyxl", "Excel .xlsx files", path)
    try:
        sheets = pd.read_excel(io.BytesIO(data), sheet_name=None, header=None, engine="openpyxl")
    except (ValueError, OSError, KeyError) as exc:
        raise RigDataError(f"damaged Excel workbook: openpyxl cannot read it ({exc})", file=path) from exc
    meta = {}
    found = None
    for sheet, frame in sheets.items():
        rows = frame.astype(object).values.tolist()
        top = _header_row(rows) if found is None else None
        if top is None:
            meta.update(_key_values(rows))
            continue
        meta.update(_key_values(rows[:top]))
        found = (sheet, *_sheet_table(rows, top))
    if found is None:
        raise RigDataError(f"no sheet holds a table (a row of column names over rows of numbers); sheets: "
                           f"{list(sheets)}", file=path)
    sheet, columns, units, start = found
    return frame_table(columns, str(path), "xlsx", units=units, metadata=meta, sha=sha,
                       reader={"name": "openpyxl", "version": openpyxl.__version__},
                       notes=(f"sheet {sheet!r}, data from row {start + 1}",))
