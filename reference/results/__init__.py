"""The result every engine returns, its summary, and the means over whole input revolutions."""

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
