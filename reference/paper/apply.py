"""A parameter set's open values applied to a scene: levers, bodies, gravity, friction law, load."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from reference.paper.loads import mean_input_load
from reference.paper.parameter_sets import CHOICES, NUMBER_PARAMETERS
from reference.scene.joint import GEOMETRY_LEVER
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import SceneError, finite

__all__ = ["apply_parameters", "body_changes", "lever_changes"]

LEVER_PAIRS = (("spider_lever", ("input_spider", "spider_output"), "arm_radius"),
               ("frame_lever", ("frame_input", "output_frame"), "support_spacing"))
"""Per lever: its parameter, the pairs it acts in, and the dimension it derives from otherwise."""


def lever_changes(values: dict[str, Any]) -> dict[str, Any]:
    """Scene changes (dotted path -> value) for the levers and dimensions in ``values``: a dimension [m]
    sets the geometry and its pairs' lever derives from it, a lever [m] is set on its pairs; SceneError
    when both are given.
    """
    changes: dict[str, Any] = {}
    for key, pairs, geometry in LEVER_PAIRS:
        if key in values and geometry in values:
            raise SceneError(f"give `{key}` (a lever) or `{geometry}` (the lever from geometry), not both")
        if geometry in values:
            changes[f"joint.geometry.{geometry}"] = values[geometry]
        lever = values[key] if key in values else GEOMETRY_LEVER if geometry in values else None
        for pair in pairs if lever is not None else ():
            changes[f"joint.pairs.{pair}.moment_lever"] = lever
    return changes


def body_changes(scene: Scene, values: dict[str, Any]) -> dict[str, Any]:
    """Scene changes (dotted path -> SI value) for the bodies' centres of mass of ``scene`` from
    ``input_eccentricity`` and ``spider_com_offset`` [m] in ``values`` (None or absent: Table 1's).
    """
    changes: dict[str, Any] = {}
    if values.get("input_eccentricity") is not None:
        body = scene.joint.input
        centroidal = np.diag(np.diag(body.centroidal_inertia_local()))
        com = list(body.com)
        # local z: the eccentric direction of Table 1's input shaft; the 0.03 mm that Table 1's
        # rounding leaves in local x is dropped
        com[0] = 0.0
        com[2] = finite("input_eccentricity", values["input_eccentricity"])
        changes.update({"joint.input.com": com, "joint.input.inertia_about": "com",
                        "joint.input.inertia": centroidal.tolist()})
    if values.get("spider_com_offset") is not None:
        # the spider's centre of mass on its normal (canonical x), `value` from the centre
        body = scene.joint.spider
        normal_local = int(np.argmax(np.abs(np.asarray(body.local_axes)[0])))
        offset = finite("spider_com_offset", values["spider_com_offset"])
        changes["joint.spider.local_origin"] = [offset - body.com[normal_local], 0.0, 0.0]
    return changes


def _check_values(values: dict[str, Any]) -> None:
    """Raise :class:`SceneError` for an unknown parameter or a choice outside its options."""
    unknown = [k for k in values if k not in NUMBER_PARAMETERS and k not in CHOICES]
    if unknown:
        raise SceneError(f"unknown parameter(s) {unknown}; choose from "
                         f"{list(NUMBER_PARAMETERS) + list(CHOICES)}")
    for key, options in CHOICES.items():
        if key in values and values[key] not in options:
            raise SceneError(f"`{key}` must be one of {list(options)}, got {values[key]!r:.80}")


def apply_parameters(scene: Scene, values: dict[str, Any]) -> Scene:
    """``scene`` (a paper scene) with the open values of a parameter set applied.

    ``values`` holds any of :data:`reference.paper.parameter_sets.NUMBER_PARAMETERS` [m] and
    :data:`reference.paper.parameter_sets.CHOICES`: ``arm_radius``, ``support_spacing`` set the geometry
    the spider and frame levers derive from; ``spider_lever``, ``frame_lever`` set the levers;
    ``input_eccentricity`` moves the input's centre of mass off its axis (centroidal inertia kept);
    ``spider_com_offset`` moves the spider's along its normal; ``torque_reading = "mean_input"`` turns
    the load into the constant output load with that mean input torque
    (:func:`reference.paper.loads.mean_input_load`), last; the description says which. SceneError for
    an unknown parameter or choice.
    """
    _check_values(values)
    changes = {**lever_changes(values), **body_changes(scene, values)}
    if "gravity" in values:
        changes["gravity"] = list(CHOICES["gravity"][values["gravity"]])
    if "friction_law" in values:
        changes["friction.law"] = values["friction_law"]
    scene = replace(scene, **changes) if changes else scene
    if values.get("torque_reading") != "mean_input":
        return scene
    return _with_mean_input_load(scene)


def _with_mean_input_load(scene: Scene) -> Scene:
    """``scene`` with the constant output load whose mean input torque is its load torque; a joint that
    locks keeps its load and the description says why.
    """
    target = scene.load.torque
    try:
        load = mean_input_load(scene)
    except SceneError as exc:
        return dataclasses.replace(scene, description=f"{scene.description}; output load {target:g} "
                                   f"N m: no load gives a mean input torque of {target:g} N m ({exc})")
    return dataclasses.replace(replace(scene, **{"load.torque": load}), description=(
        f"{scene.description}; output load {load:.6g} N m, the constant load whose mean input "
        f"torque is {target:g} N m (reference engine)"))
