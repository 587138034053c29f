"""Atomic writers of rig files (delimited text, LVM, TDMS, MATLAB v5, Parquet, ASAM MDF 4) that
:mod:`rigdata.readers` reads back to the same numbers, units and metadata. A table is column
name -> 1-D array with a time column [s]; ``metadata`` (str -> str) goes to the preamble, LVM
header, TDMS file properties or MDF header comment.
"""

from __future__ import annotations

import datetime
import io
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

from cardan_exudyn.outputs import atomic_open
from rigdata.readers.binary import INSTALL
from rigdata.record import RigDataError
from rigdata.units import split_header

__all__ = ["write_csv", "write_lvm", "write_tdms", "write_mat", "write_parquet", "write_mdf"]

#: Column names recognised as time by the writers (the first such column is the time axis).
_TIME_NAMES = ("time", "t", "x_value", "zeit")
#: LVM header tags the writer sets itself; metadata may not override them.
_LVM_RESERVED = {"writer_version", "reader_version", "separator", "decimal_separator", "multi_headings",
                 "x_columns", "time_pref", "channels", "samples", "y_unit_label", "x_dimension", "x0",
                 "delta_x", "***end_of_header***", "x_value"}


def _check(table: Mapping[str, np.ndarray], units: Mapping[str, str],
           metadata: Mapping[str, str]) -> tuple[dict[str, np.ndarray], str]:
    """Columns as float arrays of one length, every unit given, metadata one line each; columns and time
    column name.
    """
    columns = {str(k): np.asarray(v, dtype=float).ravel() for k, v in table.items()}
    lengths = {k: v.size for k, v in columns.items()}
    if not columns or len(set(lengths.values())) != 1:
        raise ValueError(f"`table` needs columns of one length, got {lengths}")
    missing = set(columns) - set(units)
    if missing:
        raise ValueError(f"`units` has no unit for columns {sorted(missing)}")
    for key, value in {**dict(metadata), **dict(units)}.items():
        text = f"{key}{value}"
        if any(c in text for c in "\t\r\n"):
            raise ValueError(f"metadata and units must be one line without tabs, got {key!r}: {value!r}")
    time = [k for k in columns if split_header(k)[0].strip().lower() in _TIME_NAMES]
    if not time:
        raise ValueError(f"`table` needs a time column named one of {_TIME_NAMES}, got {sorted(columns)}")
    return columns, time[0]


def _interval(t: np.ndarray) -> float:
    """Sampling interval [s] of a uniform time column (span over steps: no rounding build-up)."""
    return float((t[-1] - t[0]) / (t.size - 1)) if t.size > 1 else 1.0


def _numbers(columns: Mapping[str, np.ndarray], sep: str, decimal: str) -> str:
    """Rows of numbers, shortest repr that reads back to the same float."""
    buf = io.StringIO()
    pd.DataFrame(columns).to_csv(buf, sep=sep, decimal=decimal, header=False, index=False,
                                 lineterminator="\n", na_rep="NaN")
    return buf.getvalue()


def write_csv(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
              metadata: Mapping[str, str], sep: str = ",", decimal: str = ".", preamble: bool = True,
              *, units_row: bool = False) -> Path:
    """Write a delimited text file: ``# key: value`` preamble (if ``preamble``), header with units (or a
    ``units_row``), one row per sample; ``sep`` any of ``,`` ``;`` tab or blank, ``decimal`` ``.`` or
    ``,``.
    Returns ``path``.
    """
    if decimal not in (".", ",") or sep == decimal or sep not in (",", ";", "\t", " "):
        raise ValueError(f"`sep` must be one of ',', ';', tab, space and `decimal` '.' or ',' and differ "
                         f"from it, got sep={sep!r}, decimal={decimal!r}")
    columns, _ = _check(table, units, metadata)
    if sep == " " and any(" " in k or " " in units[k] for k in columns):
        raise ValueError("space-separated files need column names and units without blanks")
    lines = [f"# {k}: {v}" for k, v in metadata.items()] if preamble else []
    if units_row:
        lines += [sep.join(columns), sep.join(units[k] for k in columns)]
    else:
        lines.append(sep.join(f"{k} [{units[k]}]" for k in columns))
    with atomic_open(path, "w", encoding="utf-8", newline="") as f:
        f.write("\n".join(lines) + "\n")
        f.write(_numbers(columns, sep, decimal))
    return Path(path)


def _lvm_row(key: str, values: list[str]) -> str:
    """A segment header row: one value per Y column, an empty field under Comment, as LabVIEW writes."""
    return "\t".join([key, *values, ""])


def write_lvm(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
              metadata: Mapping[str, str], decimal: str = ",", segments: int = 1,
              *, x_columns: str = "One") -> Path:
    """Write a LabVIEW Measurement file (LVM 2.0, tab-separated) in ``segments`` contiguous segments.

    ``metadata`` adds header tags (``Date``/``Time`` default to now); ``decimal`` is stated as
    ``Decimal_Separator``; ``x_columns="No"`` leaves X empty (time from ``X0``/``Delta_X``). Returns
    ``path``.
    """
    if decimal not in (".", ",") or x_columns not in ("One", "No"):
        raise ValueError(f"`decimal` must be '.' or ',' and `x_columns` 'One' or 'No', "
                         f"got {decimal!r}, {x_columns!r}")
    columns, time = _check(table, units, metadata)
    reserved = {k for k in metadata if k.strip().lower() in _LVM_RESERVED}
    if reserved:
        raise ValueError(f"metadata keys {sorted(reserved)} are LVM structure tags")
    t = columns.pop(time)
    n = t.size
    if not 1 <= segments <= n:
        raise ValueError(f"`segments` must be in [1, {n}], got {segments!r}")
    now = datetime.datetime.now()
    date = metadata.get("Date", now.strftime("%Y/%m/%d"))
    clock = metadata.get("Time", now.strftime("%H:%M:%S.%f"))
    head = {"Writer_Version": "2", "Reader_Version": "2", "Separator": "Tab", "Decimal_Separator": decimal,
            "Multi_Headings": "No", "X_Columns": x_columns, "Time_Pref": "Relative",
            "Operator": metadata.get("Operator", "rigdata"), "Date": date, "Time": clock}
    extra = {k: v for k, v in metadata.items() if k not in head}
    out = ["LabVIEW Measurement\t"] + [f"{k}\t{v}" for k, v in {**head, **extra}.items()]
    out.append("***End_of_Header***\t")
    for rows in np.array_split(np.arange(n), segments):
        out += _lvm_segment(t, columns, units, rows, (date, clock), decimal, x_columns)
    with atomic_open(path, "w", encoding="utf-8", newline="") as f:
        f.write("\r\n".join(out) + "\r\n")
    return Path(path)


def _lvm_number(x: float, decimal: str) -> str:
    """``x`` to its last digit with decimal mark ``decimal``."""
    return repr(float(x)).replace(".", decimal)


def _lvm_segment(t: np.ndarray, columns: Mapping[str, np.ndarray], units: Mapping[str, str],
                 rows: np.ndarray, stamp: tuple[str, str], decimal: str, x_columns: str) -> list[str]:
    """Lines of one LVM segment: header, column line and rows ``rows`` (``stamp``: date and time)."""
    names = list(columns)
    m = len(columns)
    date, clock = stamp
    lines = ["\t",
             _lvm_row("Channels", [str(m)] + [""] * (m - 1)),
             _lvm_row("Samples", [str(rows.size)] * m),
             _lvm_row("Date", [date] * m),
             _lvm_row("Time", [clock] * m),
             _lvm_row("Y_Unit_Label", [units[k] for k in names]),
             _lvm_row("X_Dimension", ["Time"] * m),
             _lvm_row("X0", [_lvm_number(t[rows[0]], decimal)] * m),
             _lvm_row("Delta_X", [_lvm_number(_interval(t), decimal)] * m),
             "***End_of_Header***" + "\t" * (m + 1),
             "\t".join(["X_Value", *names, "Comment"])]
    block = {"X_Value": t[rows] if x_columns == "One" else np.full(rows.size, np.nan),
             **{k: columns[k][rows] for k in names}}
    rows_text = _numbers(block, "\t", decimal).rstrip("\n").split("\n")
    if x_columns == "No":
        # the X field stays in every row, empty
        rows_text = ["\t" + line.split("\t", 1)[1] for line in rows_text]
    return lines + rows_text


def write_tdms(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
               metadata: Mapping[str, str]) -> Path:
    """Write an NI TDMS file with npTDMS: group ``Rig``, one channel per column with ``unit_string`` and
    waveform timing; ``metadata`` as file properties; no index file. Returns ``path``.
    """
    columns, time = _check(table, units, metadata)
    t = columns[time]
    dt = _interval(t)
    objects = [RootObject(properties=dict(metadata)), GroupObject("Rig")]
    for name, values in columns.items():
        props = {"unit_string": units[name], "wf_start_offset": float(t[0]), "wf_increment": dt,
                 "wf_samples": values.size}
        objects.append(ChannelObject("Rig", name, values, properties=props))
    with atomic_open(path, "wb") as f, TdmsWriter(f) as writer:
        writer.write_segment(objects)
    return Path(path)


def _identifier(name: str) -> str:
    """A MATLAB variable name for a column (``Torque In`` -> ``Torque_In``)."""
    return "".join(c if c.isalnum() else "_" for c in name)


def write_mat(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
              metadata: Mapping[str, str]) -> Path:
    """Write a MATLAB v5 ``.mat`` with ``scipy.io.savemat``: struct ``rig`` of column vectors, struct
    ``units``, one text variable per metadata key. Returns ``path``.
    """
    from scipy.io import savemat  # scipy.io loads only for this format

    columns, _ = _check(table, units, metadata)
    rig = {_identifier(k): v for k, v in columns.items()}
    unit_struct = {_identifier(k): units[k] for k in columns}
    with atomic_open(path, "wb") as f:
        savemat(f, {"rig": rig, "units": unit_struct, **{_identifier(k): v for k, v in metadata.items()}})
    return Path(path)


def write_parquet(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
                  metadata: Mapping[str, str]) -> Path:
    """Write Parquet with ``pandas.to_parquet`` (pyarrow): ``name [unit]`` columns, ``metadata`` in the
    frame's ``attrs``. Returns ``path``.
    """
    columns, _ = _check(table, units, metadata)
    frame = pd.DataFrame({f"{k} [{units[k]}]": v for k, v in columns.items()})
    frame.attrs.update(metadata)
    with atomic_open(path, "wb") as f:
        frame.to_parquet(f)
    return Path(path)


def write_mdf(path: str | os.PathLike, table: Mapping[str, np.ndarray], units: Mapping[str, str],
              metadata: Mapping[str, str]) -> Path:
    """Write ASAM MDF 4.10 with asammdf: one group, a channel with its unit per column on the time column's
    master, ``metadata`` as ``key: value`` lines of the header comment. Returns ``path``; RigDataError
    when asammdf is missing.
    """
    try:
        import asammdf  # optional (the rig extra), and slow to import
    except ImportError:
        raise RigDataError(f"writing an ASAM MDF file needs the optional package asammdf: {INSTALL}",
                           file=path) from None
    columns, time = _check(table, units, metadata)
    t = columns.pop(time)
    mdf = asammdf.MDF(version="4.10")
    try:
        mdf.append([asammdf.Signal(v, t, name=k, unit=units[k]) for k, v in columns.items()])
        mdf.header.comment = "\n".join(f"{k}: {v}" for k, v in metadata.items())
        buffer = io.BytesIO()
        mdf.save(buffer)
    finally:
        mdf.close()
    with atomic_open(path, "wb") as f:
        f.write(buffer.getvalue())
    return Path(path)
