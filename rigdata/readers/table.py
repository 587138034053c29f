"""The parsed table every reader returns: columns as floats, units and header as written.

:class:`RawTable` is what a file holds before channels are chosen and converted; its
non-numeric cells are NaN in the columns and kept as text in :class:`TextCells`, so that an
error can quote them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rigdata.record import RigDataError

__all__ = ["FORMATS", "NUMBER", "RawTable", "TextCells", "find_text_cells", "cell_value", "is_number"]

FORMATS = ("csv", "lvm", "tdms")
#: How many non-numeric cells of a column a RawTable keeps the text of.
KEEP_TEXT = 5
#: Cell texts that mark a missing value (NaN in the column, not an error by themselves).
MISSING = {"", "nan", "-nan", "+nan", "na", "n/a", "nat", "null", "none", "#n/a"}


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

    def values(self, column: str, channel: str) -> np.ndarray:
        """The column's values as floats.

        Parameters
        ----------
        column : str
            The column.
        channel : str
            The record channel it is read for (named in the error).

        Returns
        -------
        ndarray, shape (n,)

        Raises
        ------
        RigDataError
            The column has text cells.
        """
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
    """A text cell as a number: the cells :func:`is_number` accepts, with the decimal mark
    replaced by a point; NaN for any other text (``float`` alone would also take ``"1_0"``).

    Parameters
    ----------
    text : str
        The cell.
    decimal : {".", ","}
        The file's decimal mark.

    Returns
    -------
    float
    """
    if not is_number(text):
        return math.nan
    try:
        return float(text.replace(decimal, "."))
    except ValueError:  # a comma where the file's decimal mark is a point
        return math.nan


def find_text_cells(raw: Any, numbers: np.ndarray, lines: list[int] | None) -> TextCells | None:
    """Cells whose text is neither a number nor a missing-value mark.

    Parameters
    ----------
    raw : array_like of object
        The cells as read (strings, or numbers where the parser made them).
    numbers : ndarray
        The same cells as floats, NaN where they are not numbers.
    lines : list of int, optional
        File line (1-based) of every cell, when known.

    Returns
    -------
    TextCells or None
        The cells that are text (None when every cell is a number or empty).
    """
    strings = np.asarray(raw, dtype=object)
    nan = np.flatnonzero(np.isnan(numbers))
    hits = [k for k in nan if isinstance(strings[k], str) and strings[k].strip().lower() not in MISSING]
    if not hits:
        return None
    first = tuple((int(k), None if lines is None else lines[k], strings[k].strip())
                  for k in hits[:KEEP_TEXT])
    return TextCells(len(hits), first)
