"""The result every engine returns, and the means over whole input revolutions.

- :mod:`~reference.results.columns`: the time table's columns;
- :mod:`~reference.results.summary`: :class:`Summary`, :class:`Status`, the JSON shape on disk;
- :mod:`~reference.results.accuracy`, :mod:`~reference.results.friction_diagnostics`: the
  summary's typed records of a run's error estimate and friction coupling;
- :mod:`~reference.results.result`: :class:`Result` (table and summary);
- :mod:`~reference.results.means`: the window over whole revolutions and the mean values;
- :mod:`~reference.results.power_flow`, :mod:`~reference.results.quadrature`: the direction of
  the power flow, the window integral across friction's jumps.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.results.summary": ("Status", "Summary", "OptionsError", "SCHEMA_VERSION"),
    "reference.results.result": ("Result",),
    "reference.results.accuracy": ("RunAccuracy",),
    "reference.results.friction_diagnostics": ("FrictionDiagnostics",),
    "reference.results.columns": ("table_columns",),
    "reference.results.means": ("mean_values",),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
