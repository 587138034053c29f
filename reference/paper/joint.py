"""Table 1's bodies and the Section 4.1 joint under the assumption register's choices."""

from __future__ import annotations

import numpy as np

from reference.paper.data import paper_data, value
from reference.scene.joint import Body, Geometry, Joint, Pair, Pairs
from reference.scene.validation import DEG

__all__ = ["LOCAL_AXES", "com_from_static_moments", "paper_joint", "table1_body"]

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
    """Centre of mass [m] in local axes from Table 1's ``static_moments`` ``S_k = m d_k`` [kg m] and
    ``mass`` [kg]: ``d_k^2 = r^2 - r_k^2``, squares negative from rounding set to zero, signs positive.
    """
    d2 = (np.asarray(static_moments, dtype=float) / mass) ** 2
    r2 = 0.5 * d2.sum()
    return np.sqrt(np.clip(r2 - d2, 0.0, None))


def table1_body(name: str, reading: str = "origin", com_at_centre: bool = False) -> Body:
    """One body ``name`` of Table 1 as a :class:`Body`, its inertia about ``reading`` ``"origin"`` or
    ``"com"``; ``com_at_centre`` puts the centre of mass at the joint centre.
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
    """The Section 4.1 joint at ``shaft_angle_deg`` [deg], Table 1 ``reading`` as for
    :func:`table1_body`, with ``friction`` (f1 = 0.42 spider pairs, f2 = 0.20 frame pairs) or none.
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
