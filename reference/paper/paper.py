"""The paper's data (``data/paper.toml``) turned into scenes, with provenance.

Parameter sets
--------------
The paper leaves open values that decide its numbers (the moment lever of eq. (1), the shafts'
balance, the spider's centre of mass, gravity, what "input torque 2 Nm" means). A parameter set
fixes all of them (``[sets.<name>]`` in ``data/paper.toml``, each value with its reason):

``physical`` (default)
    Every open value a dimension or physical quantity inside its plausible range
    (``[plausible]``; :func:`plausible_box`), the levers from the geometry (2 x arm radius,
    support spacing), fitted on a stated subset of the paper's numbers and checked on the rest.
``literal``
    The paper read literally with the assumption register (bearing length as the lever, Table 1's
    8.6 mm input eccentricity, gravity normal to the shafts): kept as evidence.
``matched``
    Fitted to the paper's numbers without holding the values to plausible dimensions; its
    description lists every non-physical ingredient.

Named scenes
------------
``paper[-<set>][-<A>deg][-<R>rpm][-frictionless]``
    Section 4.1 multibody case (default 10 deg, 2000 rpm, f1 = 0.42, f2 = 0.20, 2 N m).
``rig[-<set>][-errors][-frictionless]``
    Section 4.2 rig case (15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m), ideal geometry
    or, with ``-errors``, the section's manufacturing tolerances (:func:`paper_errors`).

A scene's own name spells the set out (``paper-10deg`` is ``paper-physical-10deg-2000rpm``) and
``Scene.parameter_set`` carries it into every result.

References
----------
Cavacece, Stefanelli, Valentini, Vita: A multibody dynamic model of a Cardan joint with
experimental validation (not part of this repository; sections, tables and equations cited
here are the paper's).
"""

from __future__ import annotations

import dataclasses
import functools
import re
from pathlib import Path
from typing import Any

import numpy as np

from reference.scene.drives import SpeedDrive
from reference.scene.joint import GEOMETRY_LEVER, Body, Geometry, Joint, Pair, Pairs
from reference.scene.load import Load
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.settings import Record
from reference.scene.validation import DEG, RPM, SceneError, SceneTypeError, finite

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib


@functools.lru_cache(maxsize=1)
def paper_data() -> dict[str, Any]:
    """The raw data file, every entry with value, unit and source or assumption."""
    # beside this module (package data), not importlib.resources: ~5 ms less import per command
    text = (Path(__file__).parent / "data" / "paper.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def value(path: str) -> Any:
    """Value of a dotted entry of the data file, e.g. ``value("bearings.frame.length")``, in the
    entry's own ``unit`` (mostly SI; angles in [deg], the multibody speeds in [rpm])."""
    node: Any = paper_data()
    for key in path.split("."):
        node = node[key]
    return node["value"]


def assumption_register() -> list[dict[str, Any]]:
    """Every value the paper does not state: name, value, unit, assumption, reason."""
    return [{"name": k, **v} for k, v in paper_data()["assumption"].items()]


def stated_values() -> list[dict[str, Any]]:
    """Every value taken from the paper, with unit and source."""
    out = []

    def walk(prefix: str, node: dict) -> None:
        for key, item in node.items():
            if isinstance(item, dict) and "source" in item:
                out.append({"name": f"{prefix}{key}", **item})
            elif isinstance(item, dict):
                walk(f"{prefix}{key}.", item)

    for section in ("table1", "bearings", "case"):
        walk(f"{section}.", paper_data()[section])
    return out


# Columns: local x, y, z axes in canonical coordinates (see reference.scene.joint for the frames).
_E = np.eye(3)
LOCAL_AXES = {
    # input: local y is the shaft axis pointing away from the joint (canonical -x); local z kept.
    "input": np.column_stack([_E[1], -_E[0], _E[2]]),
    # spider: local z (normal to the arms) -> canonical x; local x, y -> the two arms.
    "spider": np.column_stack([_E[1], _E[2], _E[0]]),
    # output: local z is the shaft axis pointing away from the joint (canonical x).
    "output": np.column_stack([_E[1], _E[2], _E[0]]),
}


def com_from_static_moments(static_moments: np.ndarray, mass: float) -> np.ndarray:
    """Centre of mass [m] from Table 1's static moments ``S_k`` [kg m] and the mass [kg], read as
    S_k = m * (distance of the centre of mass from axis k).

    Solves d_k^2 = r^2 - r_k^2 for the squared coordinates; a coordinate whose square comes out
    slightly negative from rounding in Table 1 is set to zero. Signs are taken positive (the
    table gives none).
    """
    d2 = (np.asarray(static_moments, dtype=float) / mass) ** 2
    r2 = 0.5 * d2.sum()
    return np.sqrt(np.clip(r2 - d2, 0.0, None))


def table1_body(name: str, reading: str = "origin", com_at_centre: bool = False) -> Body:
    """One body of Table 1 as a :class:`Body` under the chosen reading.

    Parameters
    ----------
    name : {"input", "spider", "output"}
    reading : {"origin", "com"}
        Reference point of Table 1's inertia tensors (see the assumption register).
    com_at_centre : bool
        Place the local origin so that the centre of mass sits at the joint centre.
    """
    raw = paper_data()["table1"][name]
    mass = raw["mass"]["value"]
    com = com_from_static_moments(np.array(raw["static_moments"]["value"]), mass)
    axes = LOCAL_AXES[name]
    origin = -axes @ com if com_at_centre else np.zeros(3)
    return Body(
        mass=mass,
        inertia=raw["inertia"]["value"],
        inertia_about=reading,
        com=tuple(com),
        local_origin=tuple(origin),
        local_axes=tuple(map(tuple, axes)),
    )


def paper_joint(shaft_angle_deg: float = 10.0, reading: str = "origin",
                friction: bool = True) -> Joint:
    """The Section 4.1 joint under the assumption register's choices.

    Parameters
    ----------
    shaft_angle_deg : float
        Shaft angle [deg].
    reading : {"origin", "com"}
        Reference point of Table 1's inertia tensors (:func:`table1_body`).
    friction : bool
        The case's friction coefficients (f1 = 0.42 in the spider pairs, f2 = 0.20 in the frame
        pairs) or none.
    """
    bodies = {
        "input": table1_body("input", reading),
        "spider": table1_body("spider", reading, com_at_centre=True),
        "output": table1_body("output", reading),
    }
    # Frame bearings at the axial position of each shaft's centre of mass (assumption).
    com_in = bodies["input"].canonical()[1]
    com_out = bodies["output"].canonical()[1]
    geometry = Geometry(
        shaft_angle=shaft_angle_deg * DEG,
        input_bearing=abs(com_in[0]),
        output_bearing=abs(com_out[0]),
        arm_radius=value("assumption.arm_radius"),
    )
    f1 = value("case.multibody.friction_spider") if friction else 0.0
    f2 = value("case.multibody.friction_frame") if friction else 0.0
    frame = Pair(f2, value("bearings.frame.diameter"), value("bearings.frame.length"))
    spider = Pair(f1, value("bearings.spider.diameter"), value("bearings.spider.length"))
    pairs = Pairs(frame_input=frame, input_spider=spider, spider_output=spider, output_frame=frame)
    return Joint(geometry=geometry, pairs=pairs, **bodies)


PARAMETER_SETS = ("physical", "literal", "matched")
"""The paper's parameter sets (``[sets.<name>]`` in ``data/paper.toml``): ``physical`` (default),
every open value a dimension or physical quantity inside its plausible range; ``literal``, the
paper read literally (bearing length as the moment lever, Table 1's input eccentricity);
``matched``, fitted to the paper's numbers with values that are not plausible dimensions."""
DEFAULT_PARAMETER_SET = "physical"
RENAMED_SETS = {"plain": "literal", "calibrated": "matched"}
"""Former names of the parameter sets, refused with the new name (their defaults changed)."""

# The open values a parameter set fixes, each applied by :func:`apply_parameters`: numbers [m]
# and discrete choices. Plausible ranges and their reasons are in ``[plausible]`` of the data file.
NUMBER_PARAMETERS = ("arm_radius", "support_spacing", "spider_lever", "frame_lever",
                     "input_eccentricity", "spider_com_offset")
CHOICES = {
    "gravity": {"normal": (0.0, 0.0, -9.81), "off": (0.0, 0.0, 0.0), "along_input": (-9.81, 0.0, 0.0)},
    "torque_reading": {"output_load": None, "mean_input": None},
    "friction_law": {"paper": None, "resultant": None},
}
"""Discrete choices: ``gravity`` normal to the plane of the shafts (``normal``), none, or along
the input axis with the input below the joint (``along_input``); ``torque_reading`` of the
case's 2 N m (0.2 N m on the rig): a constant load on the output (``output_load``) or the mean
input torque (``mean_input``: the constant output load that gives it, :func:`mean_input_load`);
``friction_law`` of a pair that rotates and slides (``FrictionSettings.law``: the paper's eqs. (3),
(5) as written, or one Coulomb force against the resultant slip; the same in the ideal joint)."""


def parameter_set_name(name: Any) -> str:
    """``name`` checked against :data:`PARAMETER_SETS` (a renamed set is refused with its new
    name)."""
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
    """One parameter set as stored: ``description``, ``fit_cases`` (``study:angle:rpm`` keys, empty
    when nothing was fitted) and ``values`` (name -> entry with ``value`` and ``reason``, numbers
    also ``unit`` and ``fitted``)."""
    return paper_data()["sets"][parameter_set_name(name)]


def set_values(name: str) -> dict[str, Any]:
    """Parameter name -> value of a set (numbers [m], choices as strings, Nones dropped)."""
    return {k: v["value"] for k, v in parameter_set(name)["values"].items()}


def plausible_box() -> dict[str, dict[str, Any]]:
    """The plausible range of every open value: name -> ``range`` (numbers, [m]) or ``options``
    (choices), with ``unit`` and ``reason`` (``[plausible]`` of the data file)."""
    return dict(paper_data()["plausible"])


LEVER_DIMENSIONS = {"spider_lever": ("arm_radius", 2.0), "frame_lever": ("support_spacing", 1.0)}
"""A lever given as a number stands for a dimension of the lumped pair: the spider lever for
2 x arm radius, the frame lever for the support spacing (name -> (dimension, factor))."""


def _set_of(parameters: str | dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """The label (a set's name, or ``custom`` for values given) and the values of ``parameters``."""
    if isinstance(parameters, dict):
        return "custom", dict(parameters)
    label = parameter_set_name(parameters)
    return label, set_values(label)


def parameter_table(name: str) -> list[dict[str, Any]]:
    """Rows for a report: name, value, unit, plausible range, inside it, fitted, reason. A lever
    given as a number is checked against the range of the dimension it stands for
    (:data:`LEVER_DIMENSIONS`)."""
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


def _lever_changes(values: dict[str, Any]) -> dict[str, Any]:
    changes: dict[str, Any] = {}
    spider, frame = ("input_spider", "spider_output"), ("frame_input", "output_frame")
    for key, pairs, geometry in (("spider_lever", spider, "arm_radius"),
                                 ("frame_lever", frame, "support_spacing")):
        if key in values and geometry in values:
            raise SceneError(f"give `{key}` (a lever) or `{geometry}` (the lever from geometry), not both")
        if geometry in values:
            changes[f"joint.geometry.{geometry}"] = values[geometry]
        lever = values[key] if key in values else GEOMETRY_LEVER if geometry in values else None
        for pair in pairs if lever is not None else ():
            changes[f"joint.pairs.{pair}.moment_lever"] = lever
    return changes


def _body_changes(scene: Scene, values: dict[str, Any]) -> dict[str, Any]:
    changes: dict[str, Any] = {}
    if values.get("input_eccentricity") is not None:
        body = scene.joint.input
        centroidal = np.diag(np.diag(body.centroidal_inertia_local()))
        com = list(body.com)
        # local z: the eccentric direction of Table 1's input shaft; the 0.03 mm that Table 1's
        # rounding leaves in local x is dropped
        com[0], com[2] = 0.0, finite("input_eccentricity", values["input_eccentricity"])
        changes.update({"joint.input.com": com, "joint.input.inertia_about": "com",
                        "joint.input.inertia": centroidal.tolist()})
    if values.get("spider_com_offset") is not None:
        # the spider's centre of mass on its normal (canonical x), `value` from the centre
        body = scene.joint.spider
        normal_local = int(np.argmax(np.abs(np.asarray(body.local_axes)[0])))
        offset = finite("spider_com_offset", values["spider_com_offset"])
        changes["joint.spider.local_origin"] = [offset - body.com[normal_local], 0.0, 0.0]
    return changes


def apply_parameters(scene: Scene, values: dict[str, Any]) -> Scene:
    """``scene`` with the open values of a parameter set applied.

    Parameters
    ----------
    scene : Scene
    values : dict
        Any of :data:`NUMBER_PARAMETERS` [m] and the :data:`CHOICES` (``gravity``,
        ``torque_reading``, ``friction_law``): ``arm_radius`` and ``support_spacing`` set the
        geometry and make the
        spider and frame levers derive from it; ``spider_lever`` and ``frame_lever`` set the levers
        directly; ``input_eccentricity`` moves the input's centre of mass that far off its axis
        (centroidal inertia kept, products dropped; None: Table 1's); ``spider_com_offset`` puts
        the spider's centre of mass that far from the centre along its normal. ``torque_reading``
        ``mean_input`` turns the scene's load into the constant output load whose mean input
        torque equals it (:func:`mean_input_load`); apply it last, after any other change.

    Raises
    ------
    SceneError
        An unknown parameter or choice, or a value outside a choice's options.
    """
    unknown = [k for k in values if k not in NUMBER_PARAMETERS and k not in CHOICES]
    if unknown:
        raise SceneError(f"unknown parameter(s) {unknown}; choose from "
                         f"{list(NUMBER_PARAMETERS) + list(CHOICES)}")
    for key, options in CHOICES.items():
        if key in values and values[key] not in options:
            raise SceneError(f"`{key}` must be one of {list(options)}, got {values[key]!r:.80}")
    changes = {**_lever_changes(values), **_body_changes(scene, values)}
    if "gravity" in values:
        changes["gravity"] = list(CHOICES["gravity"][values["gravity"]])
    if "friction_law" in values:
        changes["friction.law"] = values["friction_law"]
    scene = replace(scene, **changes) if changes else scene
    if values.get("torque_reading") != "mean_input":
        return scene
    target = scene.load.torque
    try:
        load = mean_input_load(scene)
    except SceneError as exc:
        # a joint that locks has no mean input torque to match: the run will say it locks
        return dataclasses.replace(scene, description=f"{scene.description}; output load {target:g} "
                                   f"N m: no load gives a mean input torque of {target:g} N m ({exc})")
    return dataclasses.replace(replace(scene, **{"load.torque": load}), description=(
        f"{scene.description}; output load {load:.6g} N m, the constant load whose mean input "
        f"torque is {target:g} N m (reference engine)"))


@functools.lru_cache(maxsize=256)
def mean_input_load(scene: Scene) -> float:
    """The constant output load [N m] under which the scene's mean input torque (over whole
    revolutions at its constant input speed) equals the scene's load torque.

    Over whole revolutions the output turns as far as the input, so the mean input torque is
    ``load / eta`` with ``eta`` the mean efficiency: the load is ``target * eta(load)``. Two
    reference-engine runs (at the target and at ``target * eta``) and a secant step through them
    give it to about 1e-6 of the target (the mean input torque is nearly linear in the load).
    A frictionless scene gives the target.

    Raises
    ------
    SceneError
        The drive is not a constant speed, or the reference engine's run fails (the joint locks).
    """
    from reference.engine.solve import run  # the paper's data sit below the engine; imported on use

    target = scene.load.torque
    if not isinstance(scene.drive, SpeedDrive) or not scene.load.constant:
        raise SceneError("`torque_reading` 'mean_input' needs a constant-speed drive and a constant load")
    if not scene.has_friction or target == 0.0:
        return target
    loads, torques = [target], []
    for _ in range(2):
        trial = replace(scene, **{"load.torque": loads[-1], "record.timeseries": False})
        result = run(trial)
        if not result.success or not result.summary.mean_efficiency:
            raise SceneError(f"cannot find the load for a mean input torque of {target:g} N m: the "
                             f"reference run ended {result.status}: {result.message}")
        torques.append(loads[-1] / float(result.summary.mean_efficiency))
        if len(loads) == 1:
            loads.append(target * float(result.summary.mean_efficiency))
    # a secant step through both runs: the mean input torque is nearly linear in the load
    (l0, l1), (t0, t1) = loads, torques
    load = l1 + (target - t1) * (l1 - l0) / (t1 - t0) if t1 != t0 else l1
    return load


def paper_scene(shaft_angle_deg: float = 10.0, speed_rpm: float | None = None,
                friction: bool = True, reading: str = "origin",
                parameters: str | dict[str, Any] = DEFAULT_PARAMETER_SET) -> Scene:
    """Section 4.1 scene: constant input speed, the case's 2 N m, under a parameter set.

    Parameters
    ----------
    shaft_angle_deg : float
        Shaft angle [deg].
    speed_rpm : float or None
        Input speed [rpm]; None: the case's 2000 rpm.
    friction : bool
        The case's friction coefficients or none (``-frictionless``).
    reading : {"origin", "com"}
        Reference point of Table 1's inertia tensors (:func:`table1_body`).
    parameters : str or dict
        A parameter set of :data:`PARAMETER_SETS` (default ``physical``), or parameter values as
        :func:`apply_parameters` takes them, applied to the literal reading (used by the fits).
    """
    shaft_angle_deg = finite("shaft_angle_deg", shaft_angle_deg)
    if speed_rpm is not None:
        speed_rpm = finite("speed_rpm", speed_rpm)
    if not isinstance(friction, bool):
        raise SceneTypeError(f"`friction` must be True or False, got {friction!r:.80}")
    label, values = _set_of(parameters)
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
    """Section 4.2's tolerances as scene overrides: ``a_i = 0.5 mm``, ``alpha_i`` errors 6e-3 deg.

    The paper gives magnitudes for i = 1, 2, 3 without signs; all are taken positive (the
    Monte Carlo study of ``cardan tolerance`` draws both signs).
    """
    a, alpha = value("case.rig.offset_error"), value("case.rig.twist_error") * DEG
    return {**{f"joint.errors.a{k}": a for k in (1, 2, 3)},
            **{f"joint.errors.alpha{k}": alpha for k in (1, 2, 3)}}


def rig_scene(friction: bool = True, parameters: str | dict[str, Any] = DEFAULT_PARAMETER_SET,
              errors: bool = False) -> Scene:
    """Section 4.2 rig case: 15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m.

    Parameters
    ----------
    friction : bool
        f = 0.42 in every pair, or none (``-frictionless``).
    parameters : str or dict
        A parameter set of :data:`PARAMETER_SETS` (default ``physical``) or parameter values
        (:func:`apply_parameters`); the set's reading of the torque applies to the rig's 0.2 N m
        ("mean input torque" in Section 4.2).
    errors : bool
        Apply the section's tolerances (:func:`paper_errors`); otherwise the ideal geometry.
    """
    for name, flag in (("friction", friction), ("errors", errors)):
        if not isinstance(flag, bool):
            raise SceneTypeError(f"`{name}` must be True or False, got {flag!r:.80}")
    label, values = _set_of(parameters)
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
    """A scene by name.

    Parameters
    ----------
    name : str
        ``paper[-<set>][-<A>deg][-<R>rpm][-frictionless]`` (parameter set ``<set>`` of
        :data:`PARAMETER_SETS`, default ``physical``; shaft angle ``A`` [deg], input speed ``R``
        [rpm]; default 10 deg, 2000 rpm) or ``rig[-<set>][-errors][-frictionless]``. The scene's
        own name spells every part out (``paper-10deg`` is ``paper-physical-10deg-2000rpm``).

    Raises
    ------
    SceneError
        An unknown name or parameter set.
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


def case_key(case: dict[str, Any]) -> str:
    """``study:angle:rpm``, the key of one of :func:`paper_cases` (``table2:10:2000``)."""
    return f"{case['study']}:{case['shaft_angle_deg']:g}:{case['speed_rpm']:g}"


def in_fit(case: dict[str, Any], fit: list[str] | tuple[str, ...]) -> bool:
    """Whether ``case`` is one of the fit cases ``fit`` (:func:`case_key` keys) or the same scene
    (angle and speed) as one: the speed study's 10 deg, 2000 rpm case is Table 2's 10 deg case."""
    scene = (float(case["shaft_angle_deg"]), float(case["speed_rpm"]))
    return any((float(k.split(":")[1]), float(k.split(":")[2])) == scene for k in fit)


def envelope() -> list[dict[str, Any]]:
    """The lowest and highest mean efficiency the model gives for each of the paper's eleven
    numbers over the plausible box (:func:`plausible_box`), as stored in ``[envelope]`` of the
    data file by ``cardan calibrate --envelope``.

    Returns
    -------
    list of dict
        Per case of :func:`paper_cases`: ``case`` (:func:`case_key`), ``paper``, ``lowest``,
        ``highest`` [-], ``reachable`` (the paper's value inside ``[lowest, highest]``),
        ``closest`` (the nearest plausible value), and ``lowest_at`` / ``highest_at`` (the
        parameter values where the extremes were found). Empty when nothing is stored.
    """
    stored = paper_data().get("envelope", {}).get("cases", {})
    out = []
    for case in paper_cases():
        entry = stored.get(case_key(case))
        if entry is None:
            continue
        lo, hi, paper = entry["lowest"], entry["highest"], case["paper_mean_efficiency"]
        out.append({"case": case_key(case), "paper": paper, "lowest": lo, "highest": hi,
                    "reachable": lo <= paper <= hi, "closest": min(max(paper, lo), hi),
                    "lowest_at": dict(entry.get("lowest_at", {})),
                    "highest_at": dict(entry.get("highest_at", {}))})
    return out


def paper_cases() -> list[dict[str, Any]]:
    """The paper's eleven numbers: Table 2 (8 angles) and the speed study (3 speeds)."""
    cases = []
    t2 = paper_data()["case"]["table2"]
    for deg, eta in zip(t2["shaft_angle"]["value"], t2["mean_efficiency"]["value"], strict=True):
        cases.append({"study": "table2", "shaft_angle_deg": deg,
                      "speed_rpm": value("case.multibody.speed"), "paper_mean_efficiency": eta})
    sp = paper_data()["case"]["speed_study"]
    for rpm, eta in zip(sp["speed"]["value"], sp["mean_efficiency"]["value"], strict=True):
        cases.append({"study": "speed", "shaft_angle_deg": sp["shaft_angle"]["value"],
                      "speed_rpm": rpm, "paper_mean_efficiency": eta})
    return cases
