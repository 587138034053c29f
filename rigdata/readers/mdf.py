"""ASAM MDF 3 and 4 rig files through asammdf: every channel with its unit; one time column when all
channels share a time base, else each channel's own uniform timing; ``key: value`` lines of the header
comment and its author/project fields as metadata.
"""

from __future__ import annotations

import html
import io
import re
from pathlib import Path
from typing import Any

import numpy as np

from rigdata.readers.binary import require
from rigdata.readers.channels import column_unit
from rigdata.readers.frame import column_values
from rigdata.readers.table import RawTable
from rigdata.record import RigDataError

__all__ = ["read_mdf"]

#: Header fields kept as metadata when set.
HEADER_FIELDS = ("author", "department", "project", "subject")
#: Relative spread of a channel's time steps below which its sampling counts as uniform.
UNIFORM = 1e-6


def _header(header: Any) -> dict[str, str]:
    """``key: value`` lines of the header comment (XML stripped) and the set header fields."""
    text = html.unescape(re.sub(r"<[^>]*>", "\n", html.unescape(str(getattr(header, "description", "")))))
    meta = {}
    for line in text.splitlines():
        key, sep, value = line.partition(":")
        if sep and key.strip() and " " not in key.strip():
            meta[key.strip()] = value.strip()
    for name in HEADER_FIELDS:
        value = getattr(header, name, None)
        if isinstance(value, str) and value.strip():
            meta.setdefault(name, value.strip())
    return meta


def _load(path: Path, data: bytes) -> tuple[list[Any], dict[str, str], str]:
    """The file's signals, header metadata and asammdf's version."""
    asammdf = require("asammdf", "ASAM MDF files", path)
    try:
        mdf = asammdf.MDF(io.BytesIO(data))
        try:
            signals = list(mdf.iter_channels())
            meta = _header(mdf.header)
        finally:
            mdf.close()
    except (ValueError, KeyError, IndexError, OSError, TypeError, AttributeError) as exc:
        raise RigDataError(f"truncated or damaged MDF file: asammdf cannot read it "
                           f"({type(exc).__name__}: {exc})", file=path) from exc
    if not signals:
        raise RigDataError("no channels in the MDF file", file=path)
    return signals, meta, asammdf.__version__


def _timing(t: np.ndarray) -> tuple[float, float] | None:
    """Start and interval [s] of uniform timestamps, else None."""
    if t.size < 2:
        return None
    steps = np.diff(t)
    dt = (t[-1] - t[0]) / (t.size - 1)
    return (float(t[0]), float(dt)) if dt > 0 and np.ptp(steps) <= UNIFORM * dt else None


def read_mdf(path: Path, data: bytes, sha: str) -> RawTable:
    """RawTable of MDF file ``path`` from ``data`` and ``sha``; RigDataError if asammdf is missing, the
    file is damaged or its channels have different, non-uniform time bases.
    """
    signals, meta, version = _load(path, data)
    names = [s.name for s in signals]
    columns = {}
    units = {}
    text_cells = {}
    sampling = {}
    shared = all(np.array_equal(s.timestamps, signals[0].timestamps) for s in signals)
    for signal in signals:
        name = signal.name if names.count(signal.name) == 1 else f"{signal.name}/{len(columns)}"
        values, cells, implied = column_values(signal.samples)
        columns[name] = values
        units[name] = column_unit(name, signal.unit.strip() or implied if signal.unit else implied)
        if cells is not None:
            text_cells[name] = cells
        timing = None if shared else _timing(np.asarray(signal.timestamps, dtype=float))
        if not shared and timing is None:
            raise RigDataError(f"channels on different time bases and {name!r} is not sampled uniformly "
                               f"(resample the file to one raster)", file=path)
        if timing is not None:
            sampling[name] = timing
    time = None
    if shared:
        time = "time" if "time" not in columns else "time (master)"
        columns = {time: np.asarray(signals[0].timestamps, dtype=float), **columns}
        units[time] = "s"
    return RawTable(str(path), "mdf", time, columns, units, meta, text_cells, sampling,
                    {"name": "asammdf", "version": version}, sha,
                    ("time from the shared master channel",) if shared else ())
