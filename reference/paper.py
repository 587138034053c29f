"""The paper's data (``data/paper.toml``) turned into scenes, with provenance.

Named scenes
------------
``paper[-calibrated][-<A>deg][-<R>rpm][-frictionless]``
    Section 4.1 multibody case (default 10 deg, 2000 rpm, f1 = 0.42, f2 = 0.20, 2 N m), under
    the plain reading of the paper (the assumption register), or with the calibrated parameter
    set (``[calibrated]`` in ``data/paper.toml``, identified by ``cardan calibrate``).
``rig[-calibrated][-errors][-frictionless]``
    Section 4.2 rig case (15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m), ideal geometry
    or, with ``-errors``, the section's manufacturing tolerances (:func:`paper_errors`); plain
    or calibrated parameter set as above.

References
----------
Cavacece, Stefanelli, Valentini, Vita: A multibody dynamic model of a Cardan joint with
experimental validation (not part of this repository; sections, tables and equations cited
here are the paper's).
"""

from __future__ import annotations

import functools
import re
from importlib import resources
from typing import Any

import numpy as np

from reference.joint import Body, Geometry, Joint, Pair, Pairs
from reference.scene import Load, Record, Scene, SpeedDrive, replace
from reference.validation import DEG, RPM, SceneError, SceneTypeError, finite

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib


@functools.lru_cache(maxsize=1)
def paper_data() -> dict[str, Any]:
    """The raw data file, every entry with value, unit and source or assumption."""
    text = resources.files("reference").joinpath("data/paper.toml").read_text(encoding="utf-8")
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


# Columns: local x, y, z axes in canonical coordinates (see reference.joint for the frames).
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


PARAMETER_SETS = ("plain", "calibrated")

# Parameters that ``cardan calibrate`` may identify: unit, plain-reading value, fit start and
# bounds (physical ranges), and what each means. Applied by :func:`apply_parameters`.
CALIBRATION_PARAMETERS: dict[str, dict[str, Any]] = {
    "spider_lever": {
        "unit": "m", "plain": 0.006, "start": 0.024, "bounds": (0.002, 1.0),
        "meaning": "moment lever of eq. (1) in both spider pairs; literal: trunnion bearing "
                   "length L; physical reading of a lumped pair of two trunnion bearings: their "
                   "spacing, 2 x arm radius",
    },
    "frame_lever": {
        "unit": "m", "plain": 0.01, "start": 0.05, "bounds": (0.002, 2.0),
        "meaning": "moment lever of eq. (1) in both shaft-frame pairs; literal: bearing length "
                   "L; physical reading: the spacing of a shaft's two support bearings",
    },
    "input_eccentricity": {
        "unit": "m", "plain": None, "start": 2e-4, "bounds": (1e-6, 0.01),
        "meaning": "distance of the input shaft's centre of mass from its axis (Table 1 under "
                   "the register's reading: 8.6 mm); centroidal inertia kept, products dropped",
    },
}


def calibrated_parameters() -> list[dict[str, Any]]:
    """The calibrated parameter set as stored: name, value, unit, plain value, meaning."""
    section = paper_data().get("calibrated", {}).get("parameters", {})
    out = []
    for name, entry in section.items():
        spec = CALIBRATION_PARAMETERS[name]
        out.append({"name": name, "value": entry["value"], "unit": spec["unit"],
                    "plain_value": spec["plain"], "meaning": spec["meaning"]})
    return out


def calibrated_choices() -> dict[str, Any]:
    """Discrete choices of the calibrated set (not fitted), with reasons."""
    return dict(paper_data().get("calibrated", {}).get("choices", {}))


def apply_parameters(scene: Scene, values: dict[str, float], choices: dict | None = None) -> Scene:
    """``scene`` with calibration parameters (see :data:`CALIBRATION_PARAMETERS`) applied.

    Parameters
    ----------
    scene : Scene
    values : dict of str to float
        Parameter name to value, in the unit :data:`CALIBRATION_PARAMETERS` gives (all [m]).
    choices : dict or None
        Discrete choices (:func:`calibrated_choices`): ``gravity`` [m/s^2] and
        ``spider_com_offset`` [m], each as ``{"value": ...}``.

    Raises
    ------
    SceneError
        An unknown parameter or choice.
    """
    changes: dict[str, Any] = {}
    for name, v in values.items():
        if name not in CALIBRATION_PARAMETERS:
            raise SceneError(f"unknown calibration parameter {name!r}; "
                             f"choose from {list(CALIBRATION_PARAMETERS)}")
        if name == "spider_lever":
            changes["joint.pairs.input_spider.moment_lever"] = v
            changes["joint.pairs.spider_output.moment_lever"] = v
        elif name == "frame_lever":
            changes["joint.pairs.frame_input.moment_lever"] = v
            changes["joint.pairs.output_frame.moment_lever"] = v
        elif name == "input_eccentricity":
            body = scene.joint.input
            centroidal = np.diag(np.diag(body.centroidal_inertia_local()))
            com = list(body.com)
            # local z: the eccentric direction of Table 1's input shaft; the 0.03 mm that
            # Table 1's rounding leaves in local x is dropped
            com[0], com[2] = 0.0, float(v)
            changes["joint.input.com"] = com
            changes["joint.input.inertia_about"] = "com"
            changes["joint.input.inertia"] = centroidal.tolist()
    for name, choice in (choices or {}).items():
        if name == "gravity":
            changes["gravity"] = list(choice["value"])
        elif name == "spider_com_offset":
            # the spider's centre of mass on its normal (canonical x), `value` from the centre
            body = scene.joint.spider
            normal_local = int(np.argmax(np.abs(np.asarray(body.local_axes)[0])))
            changes["joint.spider.local_origin"] = [float(choice["value"]) - body.com[normal_local],
                                                    0.0, 0.0]
        else:
            raise SceneError(f"unknown calibrated choice {name!r}")
    return replace(scene, **changes) if changes else scene


def paper_scene(shaft_angle_deg: float = 10.0, speed_rpm: float | None = None,
                friction: bool = True, reading: str = "origin",
                parameters: str | dict[str, float] = "plain") -> Scene:
    """Section 4.1 scene: constant input speed, 2 N m resisting torque, gravity on.

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
    parameters : {"plain", "calibrated"} or dict of str to float
        ``"plain"`` (the register), ``"calibrated"`` (the stored calibrated set, with its
        discrete choices), or calibration parameter values [m] (applied with the calibrated
        set's discrete choices; used by ``cardan calibrate``).
    """
    shaft_angle_deg = finite("shaft_angle_deg", shaft_angle_deg)
    if speed_rpm is not None:
        speed_rpm = finite("speed_rpm", speed_rpm)
    if not isinstance(friction, bool):
        raise SceneTypeError(f"`friction` must be True or False, got {friction!r:.80}")
    if not isinstance(parameters, (str, dict)):
        raise SceneTypeError(f"`parameters` must be 'plain', 'calibrated' or a dict of parameter values, "
                             f"got {parameters!r:.80}")
    if isinstance(parameters, str) and parameters not in PARAMETER_SETS:
        raise SceneError(f"parameter set must be one of {list(PARAMETER_SETS)}, got {parameters!r}")
    rpm = value("case.multibody.speed") if speed_rpm is None else speed_rpm
    calibrated = parameters != "plain"
    tag = (f"paper{'-calibrated' if calibrated else ''}-{shaft_angle_deg:g}deg-"
           f"{rpm:g}rpm" + ("" if friction else "-frictionless"))
    scene = Scene(
        joint=paper_joint(shaft_angle_deg, reading, friction),
        drive=SpeedDrive(speed=rpm * RPM),
        load=Load(torque=value("assumption.load")),
        gravity=tuple(value("assumption.gravity")),
        revolutions=float(value("assumption.revolutions")),
        record=Record(),
        name=tag,
        description=f"Section 4.1 multibody case, {'calibrated' if calibrated else 'plain'} "
                    "parameter set",
    )
    if not calibrated:
        return scene
    values = ({p["name"]: p["value"] for p in calibrated_parameters()}
              if parameters == "calibrated" else dict(parameters))
    return apply_parameters(scene, values, calibrated_choices())


def paper_errors() -> dict[str, float]:
    """Section 4.2's tolerances as scene overrides: ``a_i = 0.5 mm``, ``alpha_i`` errors 6e-3 deg.

    The paper gives magnitudes for i = 1, 2, 3 without signs; all are taken positive (the
    Monte Carlo study of ``cardan tolerance`` draws both signs).
    """
    a, alpha = value("case.rig.offset_error"), value("case.rig.twist_error") * DEG
    return {**{f"joint.errors.a{k}": a for k in (1, 2, 3)},
            **{f"joint.errors.alpha{k}": alpha for k in (1, 2, 3)}}


def rig_scene(friction: bool = True, parameters: str = "plain", errors: bool = False) -> Scene:
    """Section 4.2 rig case: 15 deg, 6 rad/s, f = 0.42 in every pair, 0.2 N m.

    Parameters
    ----------
    friction : bool
        f = 0.42 in every pair, or none (``-frictionless``).
    parameters : {"plain", "calibrated"}
        The plain reading, or the calibrated lever, eccentricity and choices of the multibody case.
    errors : bool
        Apply the section's tolerances (:func:`paper_errors`); otherwise the ideal geometry.
    """
    for name, flag in (("friction", friction), ("errors", errors)):
        if not isinstance(flag, bool):
            raise SceneTypeError(f"`{name}` must be True or False, got {flag!r:.80}")
    joint = paper_joint(value("case.rig.shaft_angle"), friction=False)
    f = value("case.rig.friction") if friction else 0.0
    pairs = Pairs(**{n: Pair(f, p.journal_diameter, p.moment_lever) for n, p in joint.pairs.items()})
    joint = Joint(joint.input, joint.spider, joint.output, joint.geometry, pairs)
    name = ("rig" + ("-calibrated" if parameters == "calibrated" else "") + ("-errors" if errors else "")
            + ("" if friction else "-frictionless"))
    scene = Scene(
        joint=joint,
        drive=SpeedDrive(speed=value("case.rig.speed")),
        load=Load(torque=value("case.rig.input_torque")),
        gravity=tuple(value("assumption.gravity")),
        revolutions=2.0,
        name=name,
        description=(f"Section 4.2 rig case, {'stated tolerances' if errors else 'ideal geometry'}, "
                     f"constant speed, {parameters} parameter set"),
    )
    if parameters == "calibrated":
        scene = apply_parameters(scene, {p["name"]: p["value"] for p in calibrated_parameters()},
                                 calibrated_choices())
    elif parameters != "plain":
        raise SceneError(f"`parameters` must be 'plain' or 'calibrated', got {parameters!r}")
    return replace(scene, **paper_errors()) if errors else scene


_RIG = re.compile(r"^rig(?P<cal>-calibrated)?(?P<err>-errors)?(?P<fl>-frictionless)?$")
_NAME = re.compile(r"^paper(?P<cal>-calibrated)?(?:-(?P<deg>\d+(?:\.\d+)?)deg)?"
                   r"(?:-(?P<rpm>\d+(?:\.\d+)?)rpm)?(?P<fl>-frictionless)?$")


def named_scene(name: str) -> Scene:
    """A scene by name (see the module docstring for the names).

    Parameters
    ----------
    name : str
        ``paper[-calibrated][-<A>deg][-<R>rpm][-frictionless]`` (shaft angle ``A`` [deg], input
        speed ``R`` [rpm]; default 10 deg, 2000 rpm) or ``rig[-calibrated][-errors][-frictionless]``.

    Raises
    ------
    SceneError
        An unknown name.
    """
    if not isinstance(name, str):
        raise SceneTypeError(f"`name` must be a scene name (a string such as 'paper-10deg'), got "
                             f"{type(name).__name__} {name!r:.80}")
    rig = _RIG.match(name)
    if rig:
        return rig_scene(friction=not rig["fl"], parameters="calibrated" if rig["cal"] else "plain",
                         errors=bool(rig["err"]))
    match = _NAME.match(name) if isinstance(name, str) else None
    if not match:
        raise SceneError(
            f"unknown scene name {name!r}; use "
            "'paper[-calibrated][-<A>deg][-<R>rpm][-frictionless]' "
            "(e.g. 'paper-10deg-2000rpm') or 'rig[-calibrated][-errors][-frictionless]'"
        )
    deg = float(match["deg"]) if match["deg"] else value("case.speed_study.shaft_angle")
    rpm = float(match["rpm"]) if match["rpm"] else None
    return paper_scene(deg, rpm, friction=not match["fl"],
                       parameters="calibrated" if match["cal"] else "plain")


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
