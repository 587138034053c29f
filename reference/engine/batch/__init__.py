"""Many constant-speed scenes through the reference engine at once."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.engine.batch.solve": ('BATCH_SCENES', 'batch_key', 'check_scenes', 'run_batch'),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
