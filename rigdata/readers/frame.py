"""A table of named columns (a pandas DataFrame or a mapping of 1-D arrays) as the RawTable every reader
returns: numbers as floats, timestamps as seconds from the first, text cells kept.
"""

from __future__ import annotations

import hashlib
import math
import sys
from collections.abc import Mapping
from typing import Any

import numpy as np

from rigdata.readers.channels import column_unit, time_column
from rigdata.readers.table import RawTable, TextCells, cell_value, find_text_cells
from rigdata.record import RigDataError

__all__ = ["column_values", "frame_columns", "frame_table"]


def column_values(values: Any) -> tuple[np.ndarray, TextCells | None, str | None]:
    """A column as floats, its text cells, and the unit its type implies (timestamps: ``s`` from the
    first).
    """
    data = np.asarray(values)
    if data.dtype.kind in "Mm":
        delta = data - data[0] if data.dtype.kind == "M" and data.size else data
        seconds = delta / np.timedelta64(1, "s") if data.size else data.astype(float)
        return np.asarray(seconds, dtype=float), None, "s"
    if data.dtype.kind in "biuf":
        return data.astype(float), None, None
    strings = np.asarray(data, dtype=object)
    numbers = np.array([float(s) if isinstance(s, (int, float, np.number)) and not isinstance(s, bool)
                        else cell_value(s) if isinstance(s, str) else math.nan for s in strings])
    return numbers, find_text_cells(strings, numbers, None), None


def frame_columns(frame: Any, file: str) -> dict[str, np.ndarray]:
    """Columns of a DataFrame or a mapping of 1-D arrays by name (str); RigDataError otherwise."""
    pd = sys.modules.get("pandas")  # not loaded: ``frame`` cannot be a DataFrame
    if pd is not None and isinstance(frame, pd.DataFrame):
        return {str(k): frame[k].to_numpy() for k in frame.columns}
    if not isinstance(frame, Mapping):
        raise RigDataError(f"expected a pandas.DataFrame or a mapping of column names to 1-D arrays, got "
                           f"{type(frame).__name__}", file=file)
    columns = {str(k): np.asarray(v) for k, v in frame.items()}
    bad = {k: v.shape for k, v in columns.items() if v.ndim != 1}
    if bad:
        raise RigDataError(f"columns must be 1-D arrays, got shapes {bad}", file=file)
    return columns


def _sha(columns: Mapping[str, np.ndarray]) -> str:
    """SHA-256 of the columns' names and values."""
    digest = hashlib.sha256()
    for name, values in columns.items():
        digest.update(name.encode() + b"\0" + np.ascontiguousarray(values).tobytes())
    return digest.hexdigest()


def frame_table(frame: Any, file: str, format: str, *, units: Mapping[str, str] | None = None,
                metadata: Mapping[str, Any] | None = None,
                reader: Mapping[str, str], sha: str = "", notes: tuple[str, ...] = ()) -> RawTable:
    """RawTable of ``frame`` (DataFrame or mapping of 1-D arrays) read from ``file`` in ``format``;
    ``units`` by column over the names' ``[unit]``; ``sha`` defaults to a hash of the values.
    """
    raw_columns = frame_columns(frame, file)
    if not raw_columns:
        raise RigDataError("no columns", file=file)
    columns = {}
    column_units = {}
    text_cells = {}
    for name, values in raw_columns.items():
        numbers, cells, implied = column_values(values)
        columns[name] = numbers
        column_units[name] = column_unit(name, (units or {}).get(name) or implied)
        if cells is not None:
            text_cells[name] = cells
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    return RawTable(file, format, time_column(columns), columns, column_units, meta, text_cells, {},
                    dict(reader),
                    sha or _sha(raw_columns), notes)
