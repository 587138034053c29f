"""Measured data from the test rig: readers, conditioning, measured efficiency, validation against the
engines (``docs/rigdata.md``). ``rigdata.read``, ``read_frame``, ``measure``, ``validate``, ``write_report``,
``synthetic.write``, ``rerun``.

Names load on first use (PEP 562): ``cardan`` imports ``rigdata.cli`` at every start, and the
modules behind them pull in scipy, pandas and the engines (about a second).
"""

from __future__ import annotations

from reference.lazy import lazy_face

__all__ = ["read", "read_table", "read_frame", "record_of_table", "measure", "Measurement", "validate",
           "Validation",
           "MODEL_ENGINES", "write_report", "RigRecord", "RigDataError", "ChannelSource", "Transducer",
           "Conditioning", "RigSettings", "synthetic", "RigDataWarning", "rerun"]

#: Public name -> the module that defines it (a name that is a module maps to itself).
_WHERE = {
    "read": "rigdata.readers", "read_table": "rigdata.readers", "read_frame": "rigdata.readers",
    "record_of_table": "rigdata.readers",
    "measure": "rigdata.measurement", "Measurement": "rigdata.measurement",
    "validate": "rigdata.validation", "Validation": "rigdata.validation",
    "MODEL_ENGINES": "rigdata.validation", "write_report": "rigdata.report",
    "RigRecord": "rigdata.record", "RigDataError": "rigdata.record", "ChannelSource": "rigdata.record",
    "Transducer": "rigdata.transducer", "Conditioning": "rigdata.conditioning",
    "RigSettings": "rigdata.synthetic", "synthetic": "rigdata.synthetic",
    "RigDataWarning": "rigdata.checks", "rerun": "rigdata.reproduce",
}


__getattr__, __dir__ = lazy_face(__name__, _WHERE)
