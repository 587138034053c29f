"""What a campaign report is made of: sections of paragraphs, lists, tables and figures, all text
already formatted, and the tones that make a paragraph or a cell stand out. Built by
:mod:`rigdata.campaign.content`, rendered by :mod:`rigdata.campaign.render`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["BANNER", "WARNING", "RESOLVABLE", "NOT_RESOLVABLE", "CALIBRATION", "FAILED", "Text", "Items",
           "Table", "Image", "Block", "Section"]

#: A paragraph's tone.
BANNER = "banner"
WARNING = "warning"
#: A table cell's tone: a verdict.
RESOLVABLE = "resolvable"
NOT_RESOLVABLE = "not-resolvable"
CALIBRATION = "calibration"
FAILED = "failed"


@dataclass(frozen=True)
class Text:
    """A paragraph; ``**bold**`` and ```code``` inline; ``tone`` :data:`BANNER` or :data:`WARNING`
    stands out."""

    text: str
    tone: str | None = None


@dataclass(frozen=True)
class Items:
    """A bulleted list."""

    items: tuple[str, ...]


@dataclass(frozen=True)
class Table:
    """A table of formatted cells; ``numeric`` columns are right-aligned; ``tones`` (row, column) ->
    tone colour cells.
    """

    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    numeric: tuple[bool, ...]
    tones: Mapping[tuple[int, int], str]


@dataclass(frozen=True)
class Image:
    """A figure: its PNG file's stem in the report folder and its caption."""

    name: str
    caption: str


Block = Text | Items | Table | Image


@dataclass(frozen=True)
class Section:
    """A titled section of the report (an empty title: the part above the first heading)."""

    title: str
    blocks: tuple[Block, ...]
