"""The one table formatter (cardan_exudyn.report.format.markdown_table): column alignment."""

from __future__ import annotations

import pytest

from cardan_exudyn.report.format import markdown_table

ROWS = [{"name": "a", "value": 1.5}, {"name": "b", "value": None}]


def _rule(table: str) -> str:
    """The table's second line: the one that sets each column's alignment."""
    return table.splitlines()[1]


def test_default_alignment_is_the_renderers():
    """Without ``right`` every column's rule is ``---`` (GitHub's default, left), as every report had it."""
    assert _rule(markdown_table(ROWS, ["name", "value"])) == "|---|---|"


def test_right_aligns_the_named_columns_only():
    """``right`` turns the named columns' rule into ``---:``; headers and cells are unchanged."""
    plain = markdown_table(ROWS, ["name", "value"]).splitlines()
    aligned = markdown_table(ROWS, ["name", "value"], right=["value"]).splitlines()
    assert aligned[1] == "|---|---:|"
    assert [aligned[0], *aligned[2:]] == [plain[0], *plain[2:]]


def test_right_naming_a_column_not_shown_is_refused():
    """A ``right`` key that is not among the columns is a ValueError naming the argument and the key."""
    with pytest.raises(ValueError, match=r"`right` must name shown columns, got \['valeu'\]"):
        markdown_table(ROWS, ["name", "value"], right=["valeu"])
