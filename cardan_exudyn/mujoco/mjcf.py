"""The MJCF model of a frictionless Cardan joint: three hinges through the centre O, one ``connect``
at the output bearing closing the loop; a prescribed input follows a heavy ``drive_reference``
hinge through a joint equality whose force is the drive torque. Why: ``docs/mujoco.md#the-model``."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from cardan_exudyn.mujoco.options import MUJOCO_DEFAULT_SOLIMP, MUJOCO_DEFAULT_SOLREF, MujocoOptions
from reference.scene import Scene, TorqueDrive

__all__ = ["BODY_IDS", "mjcf"]

BODY_IDS = {"input": 1, "spider": 2, "output": 3}
"""MuJoCo body id of each joint body in :func:`mjcf`'s model (0 is the world)."""


def _numbers(values: Iterable[float]) -> str:
    """``values`` as MJCF's space-separated numbers, each to its last digit."""
    return " ".join(repr(float(v)) for v in np.ravel(np.asarray(values, dtype=float)))


def _inertial(scene: Scene, name: str) -> str:
    """The ``<inertial>`` of body ``name``: mass [kg], centre of mass [m], full inertia about it
    [kg m^2], in its canonical frame."""
    mass, com, j = getattr(scene.joint, name).canonical()
    full = [j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]]
    return f'<inertial pos="{_numbers(com)}" mass="{mass!r}" fullinertia="{_numbers(full)}"/>'


def _option(scene: Scene, options: MujocoOptions, dt: float) -> str:
    """The ``<option>`` element: step [s], integrator, gravity [m/s^2], solver, flags."""
    override = options.o_solref is not None or options.o_solimp is not None
    o_solref = options.o_solref if options.o_solref is not None else MUJOCO_DEFAULT_SOLREF
    o_solimp = options.o_solimp if options.o_solimp is not None else MUJOCO_DEFAULT_SOLIMP
    return f"""<option timestep="{dt!r}" integrator="{options.integrator}" gravity="{_numbers(scene.gravity)}"
          solver="Newton" jacobian="dense" iterations="{options.iterations}"
          tolerance="{options.tolerance!r}" noslip_iterations="{options.noslip_iterations}"
          o_solref="{_numbers(o_solref)}" o_solimp="{_numbers(o_solimp)}">
    <flag refsafe="{'enable' if options.refsafe else 'disable'}" autoreset="disable"
          override="{'enable' if override else 'disable'}"/>
  </option>"""


def _joint_bodies(scene: Scene) -> str:
    """The ``input`` -> ``spider`` -> ``output`` bodies with their hinges; the output frame turned by the
    shaft angle about z, carrying the ``bearing_output`` site."""
    geo = scene.joint.geometry
    half = 0.5 * geo.shaft_angle
    return f"""<body name="input">
      <joint name="input" axis="1 0 0"/>
      {_inertial(scene, "input")}
      <body name="spider">
        <joint name="spider" axis="0 1 0"/>
        {_inertial(scene, "spider")}
        <body name="output" quat="{math.cos(half)!r} 0 0 {math.sin(half)!r}">
          <joint name="output" axis="0 0 1"/>
          {_inertial(scene, "output")}
          <site name="bearing_output" pos="{geo.output_bearing!r} 0 0"/>
        </body>
      </body>
    </body>"""


def _drive(scene: Scene, options: MujocoOptions, solref: str) -> tuple[str, str]:
    """The drive-reference body and the equality coupling the input to it; empty for a torque drive."""
    if isinstance(scene.drive, TorqueDrive):
        return "", ""
    i_ref = options.reference_inertia
    body = (f'<body name="drive_reference"><joint name="drive_reference" axis="1 0 0"/>'
            f'<inertial pos="0 0 0" mass="1" diaginertia="{i_ref!r} {i_ref!r} {i_ref!r}"/></body>')
    equality = (f'<joint name="drive" joint1="input" joint2="drive_reference" polycoef="0 1 0 0 0" '
                f'{solref}/>')
    return body, equality


def mjcf(scene: Scene, options: MujocoOptions, dt: float) -> str:
    """The MJCF XML of ``scene`` at step ``dt`` [s] with ``options``, for
    ``mujoco.MjModel.from_xml_string``."""
    geo = scene.joint.geometry
    solref = f'solref="{_numbers(options.solref_for(dt))}" solimp="{_numbers(options.solimp)}"'
    reference_body, drive = _drive(scene, options, solref)
    return f"""<mujoco model="cardan">
  {_option(scene, options, dt)}
  <worldbody>
    <site name="bearing_ground" pos="{_numbers(geo.output_bearing * geo.output_axis())}"/>
    {_joint_bodies(scene)}
    {reference_body}
  </worldbody>
  <equality>
    <connect name="closure" site1="bearing_output" site2="bearing_ground" {solref}/>
    {drive}
  </equality>
</mujoco>
"""
