"""Absolute timestamps in a text column (``2025-03-12 14:02:11.000000``) as seconds from the first."""

from __future__ import annotations

import re

import numpy as np

__all__ = ["TIMESTAMP_FORMATS", "timestamp_seconds"]

#: Written timestamp forms -> the ISO 8601 rewrite numpy parses (date, time, optional fraction).
TIMESTAMP_FORMATS = {
    "ISO 8601": (re.compile(r"(\d{4})-(\d\d)-(\d\d)[ T](\d\d):(\d\d):(\d\d)(?:[.,](\d{1,9}))?"),
                 r"\1-\2-\3T\4:\5:\6.\7"),
    "German (DD.MM.YYYY)": (re.compile(r"(\d\d)\.(\d\d)\.(\d{4}) (\d\d):(\d\d):(\d\d)(?:[.,](\d{1,9}))?"),
                            r"\3-\2-\1T\4:\5:\6.\7"),
}


def timestamp_seconds(cells: list[str]) -> tuple[np.ndarray, str] | None:
    """Seconds [s] of each cell from the first cell, and the first cell; None unless every cell is a
    timestamp of one form of :data:`TIMESTAMP_FORMATS` (no time zones: a file's clock is its own).
    """
    texts = [c.strip().strip('"') for c in cells]
    if not texts:
        return None
    for pattern, iso in TIMESTAMP_FORMATS.values():
        if all(pattern.fullmatch(t) for t in texts):
            stamps = np.array([pattern.sub(iso, t).rstrip(".") for t in texts], dtype="datetime64[ns]")
            seconds = (stamps - stamps[0]) / np.timedelta64(1, "s")
            return np.asarray(seconds, dtype=float), texts[0]
    return None
