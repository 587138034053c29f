"""Readers of rig files (delimited text, LabVIEW .lvm, NI TDMS, MATLAB .mat, Parquet, Excel .xlsx, ASAM
MDF): :func:`read_table` (what the file holds), :func:`read` (a validated RigRecord in SI units) and
:func:`read_frame` (the same from a DataFrame); every file problem is one RigDataError.

Assumed: a time column without unit is seconds; pulse counts are cumulative; a pulse frequency
must say ``pulses/s`` (``Hz`` is ambiguous); raw conversions default to Magtrol TMB 210.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "rigdata.readers.dispatch": ("read", "read_table", "read_frame", "record_of_table"),
    "rigdata.readers.table": ("FORMATS", "RawTable", "TextCells"),
    "rigdata.readers.channels": ("KIND_WORDS", "SIDE_WORDS", "TIME_WORDS", "match_channels", "recognise"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
