"""Reading a rig file: format chosen and read (:func:`read_table`), then channels into a record
(:func:`read`).
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Mapping
from pathlib import Path, PurePath
from typing import Any

import numpy as np

from rigdata.readers.assemble import to_record
from rigdata.readers.channels import match_channels
from rigdata.readers.delimited import read_delimited
from rigdata.readers.detect import FORMAT_ALIASES, choose_format, decode, file_bytes
from rigdata.readers.frame import frame_table
from rigdata.readers.lvm import read_lvm
from rigdata.readers.table import FORMATS, RawTable
from rigdata.record import RigRecord
from rigdata.transducer import PULSES_PER_REV, SENSITIVITY

__all__ = ["read_table", "read", "read_frame", "record_of_table"]

#: Module and function reading each binary format (imported on use: scipy and pandas load slowly).
BINARY_READERS = {"tdms": ("tdms", "read_tdms"), "mat": ("matlab", "read_mat"),
                  "parquet": ("columnar", "read_parquet"), "xlsx": ("columnar", "read_xlsx"),
                  "mdf": ("mdf", "read_mdf")}


def read_table(path: str | Path, format: str = "auto") -> RawTable:
    """Read a rig file's columns, units and header as they are, without choosing channels.

    Parameters
    ----------
    path : str or Path
    format : {"auto", "csv", "lvm", "tdms", "mat", "parquet", "xlsx", "mdf"}
        ``"auto"``: MATLAB, HDF5, Parquet, Excel and MDF by their first bytes, the others by the
        extension (else delimited text); content contradicting a format is an error.

    Returns
    -------
    RawTable

    Raises
    ------
    RigDataError
        Any problem with the file, naming it.
    """
    if not isinstance(format, str) or format not in FORMAT_ALIASES:
        raise ValueError(f"`format` must be 'auto' or one of {FORMATS}, got {format!r:.80}")
    if not isinstance(path, (str, PurePath)) or not str(path).strip():
        raise TypeError(f"`path` must be a str or pathlib.Path naming a rig file, got {path!r:.80}")
    path = Path(path)
    data = file_bytes(path)
    fmt = choose_format(path, format, data)
    sha = hashlib.sha256(data).hexdigest()
    if fmt in BINARY_READERS:
        module, function = BINARY_READERS[fmt]
        return getattr(importlib.import_module(f"rigdata.readers.{module}"), function)(path, data, sha)
    text = decode(data, path)
    return read_lvm(path, text, sha) if fmt == "lvm" else read_delimited(path, text, sha)


def read(path: str | Path, format: str = "auto", mapping: Mapping[str, str | None] | None = None,
         units: Mapping[str, str] | None = None, sensitivity: float = SENSITIVITY,
         pulses_per_rev: int = PULSES_PER_REV) -> RigRecord:
    """Read a rig file into a validated record in SI units.

    Parameters
    ----------
    path : str or Path
        Delimited text (``.csv``, ``.tsv``, ``.txt``, ``.dat``), ``.lvm``, ``.tdms``, MATLAB ``.mat``,
        Parquet, Excel ``.xlsx`` or ASAM MDF (``.mf4``, ``.mdf``).
    format : {"auto", "csv", "lvm", "tdms", "mat", "parquet", "xlsx", "mdf"}
        See :func:`read_table`.
    mapping : mapping of str to str or None, optional
        Channel (or ``"time"``) -> column; others recognised (:func:`recognise`); None drops one.
    units : mapping of str to str, optional
        Unit by channel or column name, over the file's (``{"speed_in": "rpm"}``).
    sensitivity : float
        Torque output [V/(N m)] for volts; default 0.1 (Magtrol TMB 210).
    pulses_per_rev : int
        For pulse counts or pulses/s; default 60 (Magtrol TMB 210).

    Returns
    -------
    RigRecord
        Time [s], torques [N m], speeds [rad/s], angles [rad]; ``provenance``: ``file``, ``format``,
        ``reader``, ``sha256``, ``header``, ``time``, ``conversion``, ``notes``, ``assumptions``,
        and ``synthetic`` when the header says so.

    Raises
    ------
    RigDataError
        Any problem with the file or its data, naming file and channel.
    ValueError
        Bad arguments.
    """
    _check_read_arguments(sensitivity, pulses_per_rev, mapping, units)
    return record_of_table(read_table(path, format), mapping, units, sensitivity, pulses_per_rev)


def record_of_table(raw: RawTable, mapping: Mapping[str, str | None] | None = None,
                    units: Mapping[str, str] | None = None, sensitivity: float = SENSITIVITY,
                    pulses_per_rev: int = PULSES_PER_REV) -> RigRecord:
    """The record of a table :func:`read_table` returned, with :func:`read`'s arguments (so a
    caller that also wants the table reads the file once)."""
    _check_read_arguments(sensitivity, pulses_per_rev, mapping, units)
    chosen = match_channels(raw, mapping)
    return to_record(raw, chosen, dict(units or {}), sensitivity, pulses_per_rev)


def read_frame(frame: Any, mapping: Mapping[str, str | None] | None = None,
               units: Mapping[str, str] | None = None, metadata: Mapping[str, Any] | None = None,
               sensitivity: float = SENSITIVITY, pulses_per_rev: int = PULSES_PER_REV,
               name: str = "<frame>") -> RigRecord:
    """Read a table from the caller's own loader into a validated record, like :func:`read`.

    Parameters
    ----------
    frame : pandas.DataFrame or mapping of str to 1-D array
        Columns by name, recognised as in a file (``"Time [s]"``, ``"Torque In [N m]"``, ...);
        datetime columns become seconds from the first sample.
    mapping, sensitivity, pulses_per_rev
        As for :func:`read`.
    units : mapping of str to str, optional
        Unit by channel or column name, over a ``[unit]`` in the column name.
    metadata : mapping, optional
        Key/value header (a sample rate when there is no time column; ``synthetic`` labels).
    name : str
        What the record's ``file`` says.

    Returns
    -------
    RigRecord
        ``provenance["format"]`` is ``"frame"``; ``sha256`` hashes the columns.

    Raises
    ------
    RigDataError
        A frame that is not a table, or bad data, naming the channel.
    """
    _check_read_arguments(sensitivity, pulses_per_rev, mapping, units)
    raw = frame_table(frame, str(name), "frame", units=units, metadata=metadata,
                      reader={"name": "read_frame", "version": f"of a {type(frame).__name__}"})
    chosen = match_channels(raw, mapping)
    return to_record(raw, chosen, dict(units or {}), sensitivity, pulses_per_rev)


def _check_read_arguments(sensitivity: float, pulses_per_rev: int, mapping: Mapping[str, str | None] | None,
                          units: Mapping[str, str] | None) -> None:
    """ValueError/TypeError naming an argument of :func:`read` out of range or of the wrong type."""
    if isinstance(sensitivity, bool) or not (isinstance(sensitivity, (int, float))
                                             and 1e-12 <= sensitivity <= 1e12):  # NaN fails too
        raise ValueError(f"`sensitivity` must be a number of V/(N m) in [1e-12, 1e12], "
                         f"got {sensitivity!r:.80}")
    if isinstance(pulses_per_rev, bool) or not (isinstance(pulses_per_rev, (int, np.integer))
                                                and 0 < pulses_per_rev <= 1_000_000):
        raise ValueError(f"`pulses_per_rev` must be an integer in [1, 1000000], "
                         f"got {pulses_per_rev!r:.80}")
    for name, table in (("mapping", mapping), ("units", units)):
        if table is None:
            continue
        if not isinstance(table, Mapping):
            raise TypeError(f"`{name}` must be a mapping of channel names to strings, got {table!r:.80}")
        wrong = [(k, v) for k, v in table.items()
                 if not isinstance(k, str) or not (isinstance(v, str) or (v is None and name == "mapping"))]
        if wrong:
            raise TypeError(f"`{name}` must map names (str) to strings, "
                            f"got {wrong[0][0]!r:.40}: {wrong[0][1]!r:.40}")
