"""The paper's data with provenance, its parameter sets and its named scenes."""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "reference.paper.data": ("paper_data", "value", "assumption_register", "stated_values"),
    "reference.paper.joint": ("paper_joint", "table1_body"),
    "reference.paper.parameter_sets": ("PARAMETER_SETS", "DEFAULT_PARAMETER_SET", "parameter_set",
                                       "set_values", "plausible_box", "parameter_table"),
    "reference.paper.apply": ("apply_parameters",),
    "reference.paper.loads": ("mean_input_load",),
    "reference.paper.scenes": ("named_scene", "paper_scene", "rig_scene", "paper_errors"),
    "reference.paper.cases": ("paper_cases", "case_key", "envelope"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
