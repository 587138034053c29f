"""What every engine returns: a time table (built on first read) and a :class:`Summary`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from reference.results.columns import table_columns
from reference.results.summary import Status, Summary

__all__ = ["DeferredTable", "Result", "result_table"]


class DeferredTable:
    """A time table's ``columns`` (every ``every``-th row of ``names``), turned into a pandas DataFrame
    only when read. Why: importing pandas costs about 0.4 s, ten times a short run's solve.
    """

    def __init__(self, columns: Mapping[str, np.ndarray], every: int, names: list[str]) -> None:
        self._columns = {c: columns[c][::every] for c in names}

    def build(self) -> Any:
        """The table as a pandas DataFrame."""
        import pandas as pd  # import cost: see the class docstring

        return pd.DataFrame(self._columns)


class Result:
    """What every engine returns: a ``table`` and a :class:`Summary`.

    Parameters
    ----------
    table : pandas.DataFrame, DeferredTable or None
        :func:`table_columns` (and engine extras), every ``record.every``-th row; None without a
        recorded time series or after a failure. A :class:`DeferredTable` is built on first access.
    summary : Summary
    """

    __slots__ = ("_table", "summary")

    def __init__(self, table: Any, summary: Summary) -> None:
        self._table = table
        self.summary = summary

    def __repr__(self) -> str:
        return f"Result(status={self.summary.status.value!r}, table={self.has_table})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Result):
            return NotImplemented
        return self.summary == other.summary and self.table is other.table

    @property
    def table(self) -> Any:
        """The time table (pandas.DataFrame) or None."""
        if isinstance(self._table, DeferredTable):
            self._table = self._table.build()
        return self._table

    @table.setter
    def table(self, value: Any) -> None:
        self._table = value

    @property
    def has_table(self) -> bool:
        """True when the run recorded a time table (without building it)."""
        return self._table is not None

    @property
    def status(self) -> Status:
        """How the run ended."""
        return self.summary.status

    @property
    def success(self) -> bool:
        """True when the run ended ``ok``."""
        return self.summary.success

    @property
    def message(self) -> str:
        """Why the run did not end ``ok`` (empty when it did)."""
        return self.summary.reason

    @property
    def mean_efficiency(self) -> float | None:
        """One minus lost over input work over whole revolutions (None unless ``ok``)."""
        return self.summary.mean_efficiency


def result_table(columns: Mapping[str, np.ndarray], every: int, extra: tuple[str, ...] = ()) -> Any:
    """A :class:`DeferredTable` of ``columns`` (at least :func:`table_columns`, then the engine's
    ``extra``), every ``every``-th row.
    """
    return DeferredTable(columns, every, table_columns() + list(extra))

