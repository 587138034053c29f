"""The paper's parameter sets: its open values (the moment lever of eq. (1), the shafts' balance, the
spider's centre of mass, gravity, the reading of "input torque 2 Nm") fixed with reasons
(``[sets.<name>]`` in ``data/paper.toml``):

``physical`` (default)
    Every value inside its plausible range (:func:`plausible_box`), levers from the geometry,
    fitted on a stated subset of the paper's numbers and checked on the rest.
``literal``
    The paper read literally with the assumption register, kept as evidence.
``matched``
    Fitted to the paper's numbers regardless of plausibility; its description lists every
    non-physical ingredient.
"""

from __future__ import annotations

from typing import Any

from reference.paper.data import paper_data
from reference.scene.validation import SceneError, SceneTypeError

__all__ = ["CHOICES", "DEFAULT_PARAMETER_SET", "LEVER_DIMENSIONS", "NUMBER_PARAMETERS", "PARAMETER_SETS",
           "RENAMED_SETS", "parameter_set", "parameter_set_name", "parameter_table",
           "plausible_box", "set_of", "set_values"]

PARAMETER_SETS = ("physical", "literal", "matched")
"""The paper's parameter sets (``[sets.<name>]`` in ``data/paper.toml``): ``physical`` (default),
every open value a dimension or physical quantity inside its plausible range; ``literal``, the
paper read literally (bearing length as the moment lever, Table 1's input eccentricity);
``matched``, fitted to the paper's numbers with values that are not plausible dimensions."""
DEFAULT_PARAMETER_SET = "physical"
RENAMED_SETS = {"plain": "literal", "calibrated": "matched"}
"""Former names of the parameter sets, refused with the new name (their defaults changed)."""

NUMBER_PARAMETERS = ("arm_radius", "support_spacing", "spider_lever", "frame_lever",
                     "input_eccentricity", "spider_com_offset")
"""The open values a parameter set fixes that are numbers [m]
(:func:`reference.paper.apply.apply_parameters` applies them); their plausible ranges and reasons
are ``[plausible]`` of the data file."""
CHOICES = {
    "gravity": {"normal": (0.0, 0.0, -9.81), "off": (0.0, 0.0, 0.0), "along_input": (-9.81, 0.0, 0.0)},
    "torque_reading": {"output_load": None, "mean_input": None},
    "friction_law": {"paper": None, "resultant": None},
}
"""Discrete choices: ``gravity`` normal to the plane of the shafts (``normal``), none, or along
the input axis with the input below the joint (``along_input``); ``torque_reading`` of the
case's 2 N m (0.2 N m on the rig): a constant load on the output (``output_load``) or the mean
input torque (``mean_input``: the constant output load that gives it,
:func:`reference.paper.loads.mean_input_load`);
``friction_law`` of a pair that rotates and slides (``FrictionSettings.law``: the paper's eqs. (3),
(5) as written, or one Coulomb force against the resultant slip; the same in the ideal joint)."""


def parameter_set_name(name: Any) -> str:
    """``name`` checked against :data:`PARAMETER_SETS` (a renamed set is refused with its new name)."""
    if not isinstance(name, str):
        raise SceneTypeError(f"`parameters` must be one of {list(PARAMETER_SETS)} or a dict of "
                             f"parameter values, got {name!r:.80}")
    if name in RENAMED_SETS:
        raise SceneError(f"parameter set {name!r} is now called {RENAMED_SETS[name]!r} (the default "
                         f"is {DEFAULT_PARAMETER_SET!r}); see docs/paper.md")
    if name not in PARAMETER_SETS:
        raise SceneError(f"parameter set must be one of {list(PARAMETER_SETS)}, got {name!r:.80}")
    return name


def parameter_set(name: str) -> dict[str, Any]:
    """One parameter set as stored: ``description``, ``fit_cases`` (``study:angle:rpm`` keys) and
    ``values`` (name -> ``value``, ``reason``; numbers also ``unit``, ``fitted``).
    """
    return paper_data()["sets"][parameter_set_name(name)]


def set_values(name: str) -> dict[str, Any]:
    """Parameter name -> value of a set (numbers [m], choices as strings, Nones dropped)."""
    return {k: v["value"] for k, v in parameter_set(name)["values"].items()}


def plausible_box() -> dict[str, dict[str, Any]]:
    """Every open value's plausible ``range`` [m] or ``options``, with ``unit`` and ``reason``
    (``[plausible]`` of the data file).
    """
    return dict(paper_data()["plausible"])


LEVER_DIMENSIONS = {"spider_lever": ("arm_radius", 2.0), "frame_lever": ("support_spacing", 1.0)}
"""A lever given as a number stands for a dimension of the lumped pair: the spider lever for
2 x arm radius, the frame lever for the support spacing (name -> (dimension, factor))."""


def set_of(parameters: str | dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """The label (a set's name, or ``custom`` for values given) and the values of ``parameters``."""
    if isinstance(parameters, dict):
        return "custom", dict(parameters)
    label = parameter_set_name(parameters)
    return label, set_values(label)


def parameter_table(name: str) -> list[dict[str, Any]]:
    """Report rows of set ``name``: name, value, unit, plausible range, inside it, fitted, reason (a lever
    checked against its dimension's range, :data:`LEVER_DIMENSIONS`).
    """
    box = plausible_box()
    rows = []
    for key, entry in parameter_set(name)["values"].items():
        plaus = box.get(key, {})
        if key in LEVER_DIMENSIONS:
            dimension, factor = LEVER_DIMENSIONS[key]
            plaus = {"range": [factor * v for v in box[dimension]["range"]]}
        lo_hi = plaus.get("range") or plaus.get("options")
        inside = _inside(entry["value"], plaus)
        rows.append({"name": key, "value": entry["value"], "unit": entry.get("unit", "-"),
                     "plausible": lo_hi, "plausible_value": inside,
                     "fitted": bool(entry.get("fitted", False)), "reason": entry["reason"]})
    return rows


def _inside(v: Any, plaus: dict[str, Any]) -> bool | None:
    if "range" in plaus and isinstance(v, (int, float)):
        return plaus["range"][0] <= v <= plaus["range"][1]
    if "options" in plaus:
        return v in plaus["options"]
    return None
