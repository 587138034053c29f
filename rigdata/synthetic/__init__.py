"""Synthetic rig files, labelled as such: the reference engine's joint measured by a model of the
rig's transducers (:mod:`rigdata.synthetic.rig`), and validation campaigns of them
(:mod:`rigdata.synthetic.campaign`). Names load on first use (PEP 562): ``cardan`` imports the
``synthetic`` command (:mod:`rigdata.synthetic.command`) at every start, and the generator pulls in
the engines.
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "rigdata.synthetic.campaign": ("CAMPAIGN_TRANSDUCER", "DEFAULT_POINTS", "write_campaign"),
    "rigdata.synthetic.rig": ("EXTENSIONS", "FORMATS", "GENERATOR", "MAX_SAMPLES", "RigSettings", "Truth",
                              "joint_scene", "measure", "metadata", "motor_angle", "record", "true_signals",
                              "write"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
