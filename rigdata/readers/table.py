"""The parsed table every reader returns: columns as floats, units and header as written, text cells kept."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rigdata.record import RigDataError

__all__ = ["FORMATS", "NUMBER", "RawTable", "TextCells", "find_text_cells", "cell_value", "is_number"]

FORMATS = ("csv", "lvm", "tdms", "mat", "parquet", "xlsx", "mdf")
#: How many non-numeric cells of a column a RawTable keeps the text of.
KEEP_TEXT = 5
#: Cell texts that mark a missing value (NaN in the column, not an error by themselves).
MISSING = {"", "nan", "-nan", "+nan", "na", "n/a", "nat", "null", "none", "#n/a"}


@dataclass(frozen=True)
class TextCells:
    """Non-numeric cells of one column (NaN in :attr:`RawTable.columns`).

    Attributes
    ----------
    count : int
    first : tuple of (int, int or None, str)
        Sample row (0-based), file line (1-based or None) and text of the first few.
    """

    count: int
    first: tuple[tuple[int, int | None, str], ...]

    def describe(self) -> str:
        """The first cell and how many more, for an error message."""
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
    format : {"csv", "lvm", "tdms", "mat", "parquet", "xlsx", "mdf", "frame"}
    time : str or None
        Time column name; None: time from :attr:`sampling` or the header's rate.
    columns : dict of str to ndarray
        Every column as floats by its name in the file (``group/channel`` for repeated TDMS names);
        text cells are NaN; TDMS channels may differ in length.
    units : dict of str to str or None
        Each column's unit as the file states it.
    metadata : dict of str to str
        Header key/value pairs.
    text_cells : dict of str to TextCells
    sampling : dict of str to (float, float)
        Start and interval [s] per channel (LVM, TDMS waveforms); empty for text.
    reader : dict of str to str
        ``name`` and ``version`` of the parsing library.
    sha256 : str
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

    def values(self, column: str, channel: str) -> np.ndarray:
        """Column ``column`` as floats; RigDataError naming ``channel`` if it has text cells."""
        cells = self.text_cells.get(column)
        if cells is not None:
            raise RigDataError(f"{cells.describe()} in column {column!r}", file=self.file, channel=channel)
        return np.asarray(self.columns[column], dtype=float)


NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?$|^[+-]?(?:nan|inf|infinity)$", re.I)
"""A number as a rig file writes one: decimal point or comma, exponent, NaN and infinity."""


def is_number(text: str) -> bool:
    """True when ``text`` reads as a number (decimal point or comma, NaN and infinity included)."""
    return bool(NUMBER.match(text.strip().strip('"')))


def cell_value(text: str, decimal: str = ".") -> float:
    """Text cell as a number (:func:`is_number` cells, ``decimal`` mark replaced), else NaN
    (``float`` alone would take ``"1_0"``).
    """
    if not is_number(text):
        return math.nan
    try:
        return float(text.replace(decimal, "."))
    except ValueError:  # a comma where the file's decimal mark is a point
        return math.nan


def find_text_cells(raw: Any, numbers: np.ndarray, lines: list[int] | None) -> TextCells | None:
    """TextCells of ``raw`` cells that are neither numbers nor missing marks (``lines``: 1-based), else
    None.
    """
    strings = np.asarray(raw, dtype=object)
    nan = np.flatnonzero(np.isnan(numbers))
    hits = [k for k in nan if isinstance(strings[k], str) and strings[k].strip().lower() not in MISSING]
    if not hits:
        return None
    first = tuple((int(k), None if lines is None else lines[k], strings[k].strip())
                  for k in hits[:KEEP_TEXT])
    return TextCells(len(hits), first)
