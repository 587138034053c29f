"""Readers of measured rig files: delimited text, LabVIEW Measurement (.lvm), NI TDMS.

:func:`read_table` returns what a file holds (:class:`RawTable`: columns as floats, units and
header as written); :func:`read` goes on to the record: it picks the time axis and the four
transducer channels (explicit ``mapping`` or recognition by name, :func:`match_channels`),
converts them to SI with :mod:`rigdata.conversion` and returns a validated
:class:`~rigdata.record.RigRecord` whose ``provenance`` says where every number came from.

Every problem with a file is one :class:`~rigdata.record.RigDataError` naming the file, the
channel or column, and the problem; errors of pandas, lvm_read and npTDMS are wrapped the same
way. The record's own validation (time increasing and uniform, no NaN) is not repeated here.

Modules: ``dispatch`` (:func:`read_table`, :func:`read`), ``detect`` (bytes, format, text),
``delimited``, ``lvm``, ``tdms`` (one per format), ``table`` (the :class:`RawTable` they return),
``channels`` (recognition, mapping, units of columns), ``assemble`` (time axis, SI conversion,
provenance).

Assumptions
-----------
* A time column without a unit (header ``time`` or ``t``) is in seconds; the record's
  provenance lists this under ``assumptions``. LVM X values and TDMS waveform timing are seconds
  by the formats' definitions.
* Pulse counts are a cumulative counter (:func:`rigdata.conversion.unwrap_counter`); a speed given as
  a pulse frequency must say ``pulses/s``, ``Hz`` is refused as ambiguous.
* Raw conversions default to the paper's Magtrol TMB 210: 0.1 V/(N m), 60 pulses per revolution.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "rigdata.readers.dispatch": ("read", "read_table"),
    "rigdata.readers.table": ("FORMATS", "RawTable", "TextCells"),
    "rigdata.readers.channels": ("KIND_WORDS", "SIDE_WORDS", "TIME_WORDS", "match_channels", "recognise"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
