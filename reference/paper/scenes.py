"""The paper's cases as named scenes.

``paper[-<set>][-<A>deg][-<R>rpm][-frictionless]``
    Section 4.1 multibody case (default 10 deg, 2000 rpm, f1 = 0.42, f2 = 0.20, 2 N m).
``rig[-<set>][-errors][-frictionless]``
    Section 4.2 rig case (15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m), ideal or with the
    section's tolerances (:func:`paper_errors`).

``<set>`` is a parameter set (:mod:`reference.paper.parameter_sets`), spelled out in the scene's
own name (``paper-10deg`` is ``paper-physical-10deg-2000rpm``) and in ``Scene.parameter_set``.
"""

from __future__ import annotations

import re
from typing import Any

from reference.paper.apply import apply_parameters
from reference.paper.data import value
from reference.paper.joint import paper_joint
from reference.paper.parameter_sets import (
    DEFAULT_PARAMETER_SET,
    PARAMETER_SETS,
    RENAMED_SETS,
    parameter_set_name,
    set_of,
)
from reference.scene.drives import SpeedDrive
from reference.scene.joint import Joint, Pair, Pairs
from reference.scene.load import Load
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.settings import Record
from reference.scene.validation import DEG, RPM, SceneError, SceneTypeError, finite

__all__ = ["named_scene", "paper_errors", "paper_scene", "rig_scene"]


def paper_scene(shaft_angle_deg: float = 10.0, speed_rpm: float | None = None,
                friction: bool = True, reading: str = "origin",
                parameters: str | dict[str, Any] = DEFAULT_PARAMETER_SET) -> Scene:
    """Section 4.1 scene ``paper-<set>-<A>deg-<R>rpm[-frictionless]``: constant speed, 2 N m.

    Parameters
    ----------
    shaft_angle_deg : float
        Shaft angle [deg].
    speed_rpm : float or None
        Input speed [rpm]; None: 2000 rpm.
    friction : bool
        The case's friction coefficients, or none.
    reading : {"origin", "com"}
        Reference point of Table 1's inertia tensors (:func:`reference.paper.joint.table1_body`).
    parameters : str or dict
        A set of :data:`reference.paper.parameter_sets.PARAMETER_SETS` (default ``physical``), or
        values for :func:`reference.paper.apply.apply_parameters` (name ``custom``).
    """
    shaft_angle_deg = finite("shaft_angle_deg", shaft_angle_deg)
    if speed_rpm is not None:
        speed_rpm = finite("speed_rpm", speed_rpm)
    if not isinstance(friction, bool):
        raise SceneTypeError(f"`friction` must be True or False, got {friction!r:.80}")
    label, values = set_of(parameters)
    rpm = value("case.multibody.speed") if speed_rpm is None else speed_rpm
    scene = Scene(
        joint=paper_joint(shaft_angle_deg, reading, friction),
        drive=SpeedDrive(speed=rpm * RPM),
        load=Load(torque=value("case.multibody.input_torque")),
        gravity=tuple(value("assumption.gravity")),
        revolutions=float(value("assumption.revolutions")),
        record=Record(),
        name=f"paper-{label}-{shaft_angle_deg:g}deg-{rpm:g}rpm" + ("" if friction else "-frictionless"),
        description=f"Section 4.1 multibody case, {label} parameter set",
        parameter_set=label,
    )
    return apply_parameters(scene, values)


def paper_errors() -> dict[str, float]:
    """Section 4.2's tolerances as scene overrides: ``a_i = 0.5 mm``, ``alpha_i`` 6e-3 deg, i = 1..3, all
    positive (the paper gives no signs).
    """
    a = value("case.rig.offset_error")
    alpha = value("case.rig.twist_error") * DEG
    return {**{f"joint.errors.a{k}": a for k in (1, 2, 3)},
            **{f"joint.errors.alpha{k}": alpha for k in (1, 2, 3)}}


def rig_scene(friction: bool = True, parameters: str | dict[str, Any] = DEFAULT_PARAMETER_SET,
              errors: bool = False) -> Scene:
    """Section 4.2 rig scene ``rig-<set>[-errors][-frictionless]``: 15 deg, 6 rad/s, 0.2 N m.

    Parameters
    ----------
    friction : bool
        f = 0.42 in every pair, or none.
    parameters : str or dict
        A parameter set (default ``physical``) or values, as for :func:`paper_scene`; the set's
        reading of the torque applies to the rig's 0.2 N m.
    errors : bool
        The section's tolerances (:func:`paper_errors`), else the ideal geometry.
    """
    for name, flag in (("friction", friction), ("errors", errors)):
        if not isinstance(flag, bool):
            raise SceneTypeError(f"`{name}` must be True or False, got {flag!r:.80}")
    label, values = set_of(parameters)
    joint = paper_joint(value("case.rig.shaft_angle"), friction=False)
    f = value("case.rig.friction") if friction else 0.0
    pairs = Pairs(**{n: Pair(f, p.journal_diameter, p.moment_lever) for n, p in joint.pairs.items()})
    joint = Joint(joint.input, joint.spider, joint.output, joint.geometry, pairs)
    scene = Scene(
        joint=joint,
        drive=SpeedDrive(speed=value("case.rig.speed")),
        load=Load(torque=value("case.rig.input_torque")),
        gravity=tuple(value("assumption.gravity")),
        revolutions=2.0,
        name=f"rig-{label}" + ("-errors" if errors else "") + ("" if friction else "-frictionless"),
        description=(f"Section 4.2 rig case, {'stated tolerances' if errors else 'ideal geometry'}, "
                     f"constant speed, {label} parameter set"),
        parameter_set=label,
    )
    # the errors first: the mean-input load is solved on the scene that runs
    scene = replace(scene, **paper_errors()) if errors else scene
    return apply_parameters(scene, values)


_SET = "(?:-(?P<set>" + "|".join((*PARAMETER_SETS, *RENAMED_SETS)) + "))?"
_RIG = re.compile(rf"^rig{_SET}(?P<err>-errors)?(?P<fl>-frictionless)?$")
_NAME = re.compile(rf"^paper{_SET}(?:-(?P<deg>\d+(?:\.\d+)?)deg)?"
                   r"(?:-(?P<rpm>\d+(?:\.\d+)?)rpm)?(?P<fl>-frictionless)?$")
_FORMS = ("'paper[-<set>][-<A>deg][-<R>rpm][-frictionless]' (e.g. 'paper-10deg-2000rpm', "
          "'paper-literal-35deg') or 'rig[-<set>][-errors][-frictionless]', with <set> one of "
          f"{', '.join(PARAMETER_SETS)} (default {DEFAULT_PARAMETER_SET})")


def named_scene(name: str) -> Scene:
    """:func:`paper_scene` or :func:`rig_scene` by ``name`` (module doc: ``paper...`` or ``rig...``);
    no engine runs when the set's load is stored (:mod:`reference.paper.loads`). SceneError for an
    unknown name or parameter set.
    """
    if not isinstance(name, str):
        raise SceneTypeError(f"`name` must be a scene name (a string such as 'paper-10deg'), got "
                             f"{type(name).__name__} {name!r:.80}")
    match = _RIG.match(name) or _NAME.match(name)
    if not match:
        raise SceneError(f"unknown scene name {name!r:.80}; use {_FORMS}")
    try:
        label = parameter_set_name(match["set"] or DEFAULT_PARAMETER_SET)
    except SceneError as exc:
        raise SceneError(f"scene name {name!r:.80}: {exc}") from None
    if name.startswith("rig"):
        return rig_scene(friction=not match["fl"], parameters=label, errors=bool(match["err"]))
    deg = float(match["deg"]) if match["deg"] else value("case.speed_study.shaft_angle")
    rpm = float(match["rpm"]) if match["rpm"] else None
    return paper_scene(deg, rpm, friction=not match["fl"], parameters=label)
