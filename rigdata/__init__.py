"""Measured data from the test rig: readers, conditioning, measured efficiency (issue 5).

- ``record``: :class:`RigRecord`, the validated measurement (SI units), and :class:`RigDataError`.
- ``units``: the explicit table of unit spellings, header unit parsing, raw conversions to SI.
- ``readers``: ``read`` (file -> RigRecord) and ``read_table`` for delimited text, LVM and TDMS.
- ``files``: atomic writers of the same formats (synthetic rig, tests).
- ``transducer``: the transducers' data (paper) and accuracy, drift, acquisition (assumed).
- ``conditioning``: angles from pulse edges, zero-phase low-pass, derivatives, whole-revolution
  window, input yoke phase.
- ``efficiency``: measured efficiency with its GUM budget and Monte Carlo.
- ``model``: the engines driven by the measurement; ``report``: Figure 10 and the comparison.
- ``synthetic``: the synthetic rig; ``cli``: ``cardan rig``. See ``docs/rigdata.md``.
"""
