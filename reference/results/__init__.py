"""The result every engine returns, and the means over whole input revolutions."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.results.schema": ('Status', 'Result', 'Summary', 'OptionsError', 'SCHEMA_VERSION', 'table_columns', 'mean_values'),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
