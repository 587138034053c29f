"""The one number and table formatter of every report and of the CLI.

A value that is not a finite number prints as ``missing`` ("-" by default), never as "nan".
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable, Mapping, Sequence
from typing import Any

__all__ = ["is_number", "number", "markdown_table"]


def is_number(value: Any) -> bool:
    """True for a finite int or float (numpy scalars included), False for bool, None, NaN, inf."""
    if isinstance(value, bool) or value is None:
        return False
    try:
        return math.isfinite(value)
    except TypeError:
        return False


def number(value: Any, spec: str = ".4g", missing: str = "-") -> str:
    """``value`` formatted with format spec ``spec`` (``".4f"``), or ``missing`` if not a finite number."""
    return format(value, spec) if is_number(value) else missing


def _cell(value: Any, spec: str | None, missing: str) -> str:
    """One cell of :func:`markdown_table`: numbers by ``spec`` (floats ``.4g`` without one), text
    with ``|`` escaped and line ends as blanks."""
    if spec is not None:
        return number(value, spec, missing) if not isinstance(value, str) else value
    if isinstance(value, float) or (not isinstance(value, (str, bool, int)) and is_number(value)):
        return number(value, ".4g", missing)
    if value is None:
        return missing
    return str(value).replace("|", "\\|").replace("\n", " ")


def markdown_table(rows: Iterable[Mapping[str, Any]] | Any, columns: Sequence[str],
                   formats: Mapping[str, str] | None = None, headers: Sequence[str] | None = None,
                   missing: str = "-", right: Collection[str] = ()) -> str:
    """A GitHub-flavoured markdown table, ending in a line end.

    Parameters
    ----------
    rows : iterable of mappings, or a pandas DataFrame
    columns : sequence of str
        Keys to show, in order.
    formats : mapping, optional
        Format spec per column (``{"mean_efficiency": ".4f"}``); floats default to ``.4g``.
    headers : sequence of str, optional
        Column titles (default: the keys).
    missing : str
        What a value that is not a finite number prints as.
    right : collection of str
        Keys of the columns to right-align (``---:``); the others keep the renderer's default.
    """
    if hasattr(rows, "to_dict") and hasattr(rows, "columns"):  # a DataFrame
        rows = rows.to_dict("records")
    formats = formats or {}
    titles = list(headers) if headers is not None else list(columns)
    if len(titles) != len(columns):
        raise ValueError(f"`headers` must have {len(columns)} entries, got {len(titles)}")
    unknown = sorted(set(right) - set(columns))
    if unknown:
        raise ValueError(f"`right` must name shown columns, got {unknown!r} not in {list(columns)!r}")
    rule = "".join("---:|" if c in right else "---|" for c in columns)
    lines = ["| " + " | ".join(titles) + " |", "|" + rule]
    for row in rows:
        cells = [_cell(row.get(c), formats.get(c), missing) for c in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
