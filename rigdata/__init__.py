"""Measured data from the test rig: readers, conditioning, measured efficiency.

The public face::

    import rigdata

    record = rigdata.read("rig.lvm")                    # file -> RigRecord (SI units)
    m = rigdata.measure(record, shaft_angle_deg=15)     # measured efficiency +- u
    v = rigdata.validate("rig.lvm", "rig")   # measured against computed, per engine
    rigdata.write_report(v, "out/rig")                  # report.md, figure10.png, ...
    used = rigdata.synthetic.write("rig.csv", "csv", rigdata.RigSettings(revolutions=5))

Modules:

- ``record``: :class:`RigRecord`, the validated measurement (SI units), and :class:`RigDataError`.
- ``units``: the explicit table of unit spellings, header unit parsing; ``conversion``: values
  to SI (raw signals included), counter wraps, plausible magnitudes.
- ``readers``: ``read`` (file -> RigRecord) and ``read_table`` for delimited text, LVM and TDMS.
- ``files``: atomic writers of the same formats (synthetic rig, tests).
- ``transducer``: the transducers' data (paper) and accuracy, drift, acquisition (assumed).
- ``conditioning``: angles from pulse edges, zero-phase low-pass, speeds, whole-revolution
  window, input yoke phase.
- ``efficiency``: measured efficiency with its GUM budget; ``montecarlo``: its Monte Carlo.
- ``measurement``: ``measure`` (a record or file to its measured efficiency).
- ``model``: the engines driven by the measurement; ``validation``: ``validate``; ``report``:
  Figure 10 and the report folder.
- ``synthetic``: the synthetic rig; ``cli``: ``cardan rig``. See ``docs/rigdata.md``.

The names below are loaded on first use (PEP 562): ``import rigdata`` costs nothing more than
the package, so ``cardan``, which imports ``rigdata.cli`` at every start, stays quick; the
modules behind them pull in scipy, pandas and the engines (about a second).
"""

from __future__ import annotations

from reference.lazy import lazy_face

__all__ = ["read", "read_table", "measure", "Measurement", "validate", "Validation", "MODEL_ENGINES",
           "write_report", "RigRecord", "RigDataError", "ChannelSource", "Transducer", "Conditioning",
           "RigSettings", "synthetic"]

#: Public name -> the module that defines it (a name that is a module maps to itself).
_WHERE = {
    "read": "rigdata.readers", "read_table": "rigdata.readers",
    "measure": "rigdata.measurement", "Measurement": "rigdata.measurement",
    "validate": "rigdata.validation", "Validation": "rigdata.validation",
    "MODEL_ENGINES": "rigdata.validation", "write_report": "rigdata.report",
    "RigRecord": "rigdata.record", "RigDataError": "rigdata.record", "ChannelSource": "rigdata.record",
    "Transducer": "rigdata.transducer", "Conditioning": "rigdata.conditioning",
    "RigSettings": "rigdata.synthetic", "synthetic": "rigdata.synthetic",
}


__getattr__, __dir__ = lazy_face(__name__, _WHERE)
