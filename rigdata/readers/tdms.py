"""NI TDMS files, parsed by npTDMS from the bytes already read; channels named ``group/channel`` when
names repeat; waveform timing kept. npTDMS reports a cut file only in its log, which is read.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import re
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import nptdms
import nptdms.log
import numpy as np

from rigdata.readers.channels import column_unit, time_column
from rigdata.readers.table import RawTable, TextCells, cell_value, find_text_cells
from rigdata.record import RigDataError

__all__ = ["read_tdms"]

DAMAGE = re.compile(r"last segment|less data|incomplete|not a multiple|cropping", re.I)
#: What npTDMS raises on a file it cannot parse (it wraps nothing).
PARSE_ERRORS = (ValueError, LookupError, TypeError, AttributeError, ArithmeticError, EOFError,
                struct.error, OSError, MemoryError, NotImplementedError)
LEAD_IN_BYTES = 28
"""Size of a TDMS segment's lead-in (tag, table of contents, version, two lengths): a file
shorter than one was cut before its first segment's metadata."""


@contextlib.contextmanager
def nptdms_warnings() -> Iterator[list[str]]:
    """Collect npTDMS' logged warnings and keep them off the console while a file is read."""
    messages: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            messages.append(record.getMessage())

    keep = Keep(logging.WARNING)
    mute = logging.Filter("rigdata.readers.muted")
    loggers = [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
               if name.startswith("nptdms")]
    console = getattr(getattr(nptdms.log, "log_manager", None), "console_handler", None)
    for lg in loggers:
        lg.addHandler(keep)
    if console is not None:
        console.addFilter(mute)
    try:
        yield messages
    finally:
        for lg in loggers:
            lg.removeHandler(keep)
        if console is not None:
            console.removeFilter(mute)


def channel_values(channel: Any) -> tuple[np.ndarray, TextCells | None, str | None]:
    """A channel's values as floats, its text cells, and its type's unit (timestamps: seconds from the
    first).
    """
    data = channel[:]
    if np.issubdtype(data.dtype, np.datetime64):
        seconds = (data - data[0]) / np.timedelta64(1, "s") if data.size else data.astype(float)
        return np.asarray(seconds, dtype=float), None, "s"
    if data.dtype.kind in "biuf":
        return data.astype(float), None, None
    strings = np.asarray(data, dtype=object)
    numbers = np.array([cell_value(s) if isinstance(s, str) else math.nan for s in strings])
    return numbers, find_text_cells(strings, numbers, None), None


def _load(data: bytes, path: Path) -> tuple[Any, list[tuple], list[str]]:
    """The TDMS file, its channels (group, channel, values, text cells, unit) and npTDMS' warnings."""
    if len(data) < LEAD_IN_BYTES:
        raise RigDataError(f"truncated: {len(data)} bytes, less than the {LEAD_IN_BYTES}-byte lead-in of a "
                           f"TDMS segment", file=path)
    try:
        with nptdms_warnings() as warnings:
            tdms = nptdms.TdmsFile.read(io.BytesIO(data))
            groups = [(g.name, c) for g in tdms.groups() for c in g.channels()]
            loaded = [(g, c, *channel_values(c)) for g, c in groups]
    except PARSE_ERRORS as exc:  # npTDMS raises ValueError, KeyError, struct.error, EOFError ...
        raise RigDataError(f"truncated or damaged TDMS file: npTDMS cannot read its structure "
                           f"({type(exc).__name__}: {exc})", file=path) from exc
    damage = [w for w in warnings if DAMAGE.search(w)]
    if damage:
        raise RigDataError(f"truncated or damaged TDMS file: npTDMS reports {damage[0]!r}", file=path)
    if not loaded:
        raise RigDataError("no channels in the TDMS file", file=path)
    return tdms, loaded, warnings


def _sampling(props: Any) -> tuple[float, float] | None:
    """Start [s] and interval [s] of a waveform channel, None for another."""
    if "wf_increment" not in props:
        return None
    start = props.get("wf_start_offset", 0.0)
    return float(start) if isinstance(start, (int, float)) else 0.0, float(props["wf_increment"])


def read_tdms(path: Path, data: bytes, sha: str) -> RawTable:
    """RawTable of TDMS file ``path`` from ``data`` and ``sha`` (SHA-256); RigDataError if cut, damaged or
    empty.
    """
    tdms, loaded, warnings = _load(data, path)
    plain = [c.name for _, c, *_ in loaded]
    columns = {}
    units = {}
    text_cells = {}
    sampling = {}
    for group, channel, values, cells, implied in loaded:
        name = channel.name if plain.count(channel.name) == 1 else f"{group}/{channel.name}"
        props = channel.properties
        stated = props.get("unit_string") or props.get("NI_UnitDescription") or implied
        columns[name] = values
        units[name] = column_unit(name, str(stated).strip() or None if stated is not None else None)
        if cells:
            text_cells[name] = cells
        timing = _sampling(props)
        if timing is not None:
            sampling[name] = timing
    meta = {str(k): str(v) for k, v in tdms.properties.items()}
    return RawTable(str(path), "tdms", time_column(columns), columns, units, meta, text_cells,
                    sampling, {"name": "npTDMS", "version": nptdms.__version__},
                    sha, tuple(f"npTDMS: {w}" for w in warnings))
