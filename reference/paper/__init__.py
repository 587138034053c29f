"""The paper's data with provenance, its parameter sets and its named scenes."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.paper.paper": ('named_scene', 'paper_scene', 'rig_scene', 'paper_data', 'paper_cases', 'PARAMETER_SETS', 'DEFAULT_PARAMETER_SET', 'parameter_set'),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
