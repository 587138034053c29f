"""The RCCC Cardan joint as an Exudyn model, built from a scene with only the items it needs.

Modelling choices
-----------------
- Three ``NodeRigidBodyRxyz`` nodes, each at its body's centre of mass, with node axes equal to the
  global axes in the reference configuration (input angle 0). The input rotates about global x,
  so its first Tait-Bryan angle is the shaft angle (the drive acts on it directly). The spider's
  orientation is ``Rx(theta) Ry(gamma)`` with ``|gamma| <= beta``, and the output's second angle
  stays below ``beta`` too: the parametrisation is regular for every shaft angle below 90 deg.
- Four ``ObjectJointGeneric`` pairs (revolute ``[1,1,1,1,1,0]``, cylindrical ``[1,1,0,1,1,0]``,
  z the pair axis): 17 constraints on 18 coordinates, mobility one, no redundancy.
- Constant speed: ``ObjectConnectorCoordinate`` at velocity level on the input angle (no Python
  user function). Prescribed angle: the same connector at position level with an offset user
  function evaluating a cubic spline. Torque drive: ``LoadTorqueVector``.
- Gravity loads and the output load only when they are non-zero; friction loads and their user
  function only for pairs with a non-zero coefficient (``cardan_exudyn.friction``).
- Mounting errors (``scene.joint.errors``): each pair's marker frames are displaced and rotated
  to the joint's Denavit-Hartenberg geometry (the pair axes no longer meet at one point, so the
  cylindrical pairs slide). The marker frames and the initial assembled state are taken from
  :mod:`reference.rccc` at the start; from there on the motion is Exudyn's own (its constraints
  keep the loop closed; the tests compare it with the reference engine). The ideal joint keeps
  the closed form below, written independently of ``reference``. In both cases the reference
  configuration (node axes = global axes) is the assembled joint at input angle 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cardan_exudyn.rotations import rxyz_from_matrix, rxyz_rates
from reference import rccc
from reference.scene import PAIR_BODIES, PAIR_KIND, PAIR_NAMES, AngleDrive, Scene, SpeedDrive

CONSTRAINED_AXES = {"revolute": [1, 1, 1, 1, 1, 0], "cylindrical": [1, 1, 0, 1, 1, 0]}


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _loop_motion(scene: Scene, theta: float, omega: float) -> dict[str, rccc.BodyMotion]:
    """Body motions of the joint with mounting errors at one input state (reference.rccc)."""
    params = rccc.DHParameters.of_joint(scene.joint)
    positions, rates = rccc.solve_motion(params, np.array([theta]), omega, 0.0)
    return {name: rccc.BodyMotion(*(np.asarray(v)[0] for v in (m.rotation, m.origin, m.omega,
                                                                m.velocity, m.alpha, m.acceleration)))
            for name, m in rccc.body_motions(params, positions, rates).items()}


def node_axes_in_canonical(scene: Scene) -> dict[str, np.ndarray]:
    """Rotation from canonical body coordinates to node coordinates (= global at reference)."""
    if scene.joint.errors.any:
        return {name: m.rotation for name, m in _loop_motion(scene, 0.0, 0.0).items()
                if name != "ground"}
    beta = scene.joint.geometry.shaft_angle
    return {"input": np.eye(3), "spider": np.eye(3), "output": _rot_z(beta)}


def pair_geometry(scene: Scene) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each pair's origin and frame (columns x, y, z; z the pair axis) in the reference configuration."""
    if scene.joint.errors.any:
        params = rccc.DHParameters.of_joint(scene.joint)
        frames = rccc.pair_frames(params, rccc.solve_positions(params, np.array([0.0])),
                                  rccc.axial_positions(scene.joint.geometry))
        return {name: (origin[0], frame[0]) for name, (frame, origin) in frames.items()}
    geo = scene.joint.geometry
    a2 = geo.output_axis()
    ex, ey, ez = np.eye(3)
    y_out = np.cross(ez, a2)
    return {
        "frame_input": (-geo.input_bearing * ex, np.column_stack([ey, ez, ex])),
        "input_spider": (np.zeros(3), np.column_stack([ez, ex, ey])),
        "spider_output": (np.zeros(3), np.eye(3)),
        "output_frame": (geo.output_bearing * a2, np.column_stack([y_out, ez, a2])),
    }


def assembled_state(scene: Scene, theta: float, omega: float) -> dict[str, dict[str, np.ndarray]]:
    """Orientation, angular velocity, frame origin and its velocity of each body at an input state.

    ``A`` rotates node coordinates to global ones; ``origin`` is the body's canonical-frame origin
    [m] and ``velocity`` its velocity [m/s] (both zero for the ideal joint, whose bodies turn
    about the joint centre).

    Ideal joint: closed-form vector geometry (written here independently of
    ``reference.kinematics``): the output yoke axis is normal to the output shaft axis and the
    input yoke axis; the relative rates follow from the velocity loop
    ``omega e_x + gamma_t u1 = theta2_t a2 + phi_t u2``. With mounting errors:
    :mod:`reference.rccc`.
    """
    axes = node_axes_in_canonical(scene)
    if scene.joint.errors.any:
        return {name: {"A": m.rotation @ axes[name].T, "omega": m.omega, "origin": m.origin,
                       "velocity": m.velocity}
                for name, m in _loop_motion(scene, theta, omega).items() if name != "ground"}
    a2 = scene.joint.geometry.output_axis()
    ex = np.array([1.0, 0.0, 0.0])
    a_in = _rot_x(theta)
    u1 = a_in[:, 1]
    u2 = np.cross(a2, u1)
    u2 /= np.linalg.norm(u2)
    a_spider = np.column_stack([np.cross(u1, u2), u1, u2])
    a_out_canonical = np.column_stack([a2, np.cross(u2, a2), u2])
    rates = np.linalg.solve(np.column_stack([u1, -a2, -u2]), -omega * ex)
    w_in = omega * ex
    zero = np.zeros(3)
    return {
        "input": {"A": a_in @ axes["input"].T, "omega": w_in, "origin": zero, "velocity": zero},
        "spider": {"A": a_spider @ axes["spider"].T, "omega": w_in + rates[0] * u1,
                   "origin": zero, "velocity": zero},
        "output": {"A": a_out_canonical @ axes["output"].T, "omega": rates[1] * a2,
                   "origin": zero, "velocity": zero},
    }


@dataclass
class ExudynModel:
    """An assembled Exudyn system and the indices needed to read it."""

    scene: Scene
    system_container: Any
    mbs: Any
    nodes: dict[str, Any] = field(default_factory=dict)
    bodies: dict[str, Any] = field(default_factory=dict)
    joints: dict[str, Any] = field(default_factory=dict)
    pair_markers: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    marker_local: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    pair_frames: dict[str, np.ndarray] = field(default_factory=dict)
    com_reference: dict[str, np.ndarray] = field(default_factory=dict)
    drive_connector: Any = None
    sensors: dict[str, Any] = field(default_factory=dict)
    start_time: float = 0.0
    user_functions: list = field(default_factory=list)
    pair_kinematics: dict = field(default_factory=dict)
    mass: dict[str, float] = field(default_factory=dict)
    inertia: dict[str, np.ndarray] = field(default_factory=dict)
    friction: Any = None  # cardan_exudyn.friction.FrictionCoupling when friction is applied


def build_model(scene: Scene, sensors: bool = True) -> ExudynModel:
    """Assemble the Exudyn system for ``scene`` (no solving), with recording sensors."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    model = ExudynModel(scene=scene, system_container=sc, mbs=mbs)
    ground = mbs.AddObject(eii.ObjectGround())

    theta0, omega0, t0 = _initial_drive_state(scene)
    model.start_time = t0
    state = assembled_state(scene, theta0, omega0)
    reference_state = assembled_state(scene, 0.0, 0.0)
    axes = node_axes_in_canonical(scene)
    for name, body in scene.joint.bodies():
        mass, com_c, inertia_c = body.canonical()
        r = axes[name]
        com = r @ com_c  # from the body's frame origin, node axes = global axes at reference
        inertia = r @ inertia_c @ r.T
        model.com_reference[name] = reference_state[name]["origin"] + com
        model.mass[name] = mass
        model.inertia[name] = inertia
        a0 = state[name]["A"]
        psi0 = rxyz_from_matrix(a0)
        w = state[name]["omega"]
        arm = a0 @ com
        pos0 = state[name]["origin"] + arm
        node = mbs.AddNode(eii.NodeRigidBodyRxyz(
            referenceCoordinates=[*model.com_reference[name], 0.0, 0.0, 0.0],
            initialCoordinates=[*(pos0 - model.com_reference[name]), *psi0],
            initialVelocities=[*(state[name]["velocity"] + np.cross(w, arm)), *rxyz_rates(psi0, w)],
        ))
        model.nodes[name] = node
        model.bodies[name] = mbs.AddObject(eii.ObjectRigidBody(
            mass=mass,
            inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2],
                     inertia[1, 2], inertia[0, 2], inertia[0, 1]],
            centerOfMass=[0.0, 0.0, 0.0],
            nodeNumber=node,
        ))

    def marker(owner: str, position: np.ndarray, frame: np.ndarray):
        # node axes equal the global axes at reference, so the pair frame is the marker rotation
        body = ground if owner == "ground" else model.bodies[owner]
        local = position - (0.0 if owner == "ground" else model.com_reference[owner])
        ht = exu.HT(rotation=frame, translation=local)
        return mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localHT=ht)), local

    for name, (origin, frame) in pair_geometry(scene).items():
        body_a, body_b = PAIR_BODIES[name]
        m_a, l_a = marker(body_a, origin, frame)
        m_b, l_b = marker(body_b, origin, frame)
        model.pair_markers[name] = (m_a, m_b)
        model.marker_local[name] = (l_a, l_b)
        model.pair_frames[name] = frame
        model.joints[name] = mbs.AddObject(eii.ObjectJointGeneric(
            markerNumbers=[m_a, m_b],
            constrainedAxes=CONSTRAINED_AXES[PAIR_KIND[name]],
        ))

    _add_drive(model, ground)
    _add_loads(model)
    if scene.has_friction and scene.friction.coupling != "uncoupled":
        from cardan_exudyn.friction import FrictionCoupling

        model.friction = FrictionCoupling(model)
    if sensors:
        add_sensors(model)
    mbs.Assemble()
    if model.friction is not None:
        model.friction.prepare()
    return model


def _initial_drive_state(scene: Scene) -> tuple[float, float, float]:
    """Input angle [rad], speed [rad/s] and time [s] at the start of the simulation."""
    drive = scene.drive
    if isinstance(drive, SpeedDrive):
        return 0.0, drive.speed, 0.0
    if isinstance(drive, AngleDrive):
        spline = drive.spline()
        t0 = drive.time[0]
        return float(spline(t0)), float(spline(t0, 1)), t0
    return 0.0, drive.initial_speed, 0.0


def _add_drive(model: ExudynModel, ground) -> None:
    mbs, drive = model.mbs, model.scene.drive
    if drive.kind == "torque":
        m_in = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=model.bodies["input"]))
        mbs.AddLoad(eii.LoadTorqueVector(markerNumber=m_in, loadVector=[drive.torque, 0.0, 0.0]))
        return
    ground_node = mbs.AddNode(eii.NodePointGround())
    m_ground = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))
    # the raw ODE2 coordinate psi0 (index 3) of the Rxyz node: unlike a rotation-coordinate
    # marker it does not wrap at +-pi, which breaks a position-level angle drive at half a turn
    m_angle = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=model.nodes["input"], coordinate=3))
    if drive.kind == "speed":
        connector = eii.ObjectConnectorCoordinate(markerNumbers=[m_ground, m_angle],
                                                  velocityLevel=True, offset=drive.speed)
    else:
        spline = drive.spline()

        def angle_offset(mbs_, t, item, offset):
            return float(spline(t))

        model.user_functions.append(angle_offset)
        connector = eii.ObjectConnectorCoordinate(markerNumbers=[m_ground, m_angle],
                                                  offsetUserFunction=angle_offset)
    model.drive_connector = mbs.AddObject(connector)


def _add_loads(model: ExudynModel) -> None:
    mbs, scene = model.mbs, model.scene
    axis = model.pair_frames["output_frame"][:, 2]  # the output axis, fixed in the ground
    if not scene.load.constant:  # a measured history: interpolated at each instant
        load = scene.load

        def load_history(mbs_, t, load_vector):
            return list(-float(load.at(t)) * axis)

        model.user_functions.append(load_history)
        m_out = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=model.bodies["output"]))
        mbs.AddLoad(eii.LoadTorqueVector(markerNumber=m_out, loadVector=[0.0, 0.0, 0.0],
                                         loadVectorUserFunction=load_history))
    elif scene.load.torque != 0.0:
        m_out = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=model.bodies["output"]))
        vector = -scene.load.torque * axis
        mbs.AddLoad(eii.LoadTorqueVector(markerNumber=m_out, loadVector=list(vector)))
    if scene.has_gravity:
        for name in model.bodies:
            m = mbs.AddMarker(eii.MarkerBodyMass(bodyNumber=model.bodies[name]))
            mbs.AddLoad(eii.LoadMassProportional(markerNumber=m, loadVector=list(scene.gravity)))


def add_sensors(model: ExudynModel) -> None:
    """Internal (in-memory) sensors for node states, pair reactions and the drive force."""
    out = exu.OutputVariableType

    def sensor(key: str, item: Any, variable: Any, node: bool = False) -> None:
        kind = eii.SensorNode(nodeNumber=item, outputVariableType=variable, storeInternal=True,
                              writeToFile=False) if node else \
            eii.SensorObject(objectNumber=item, outputVariableType=variable, storeInternal=True,
                             writeToFile=False)
        model.sensors[key] = model.mbs.AddSensor(kind)

    for name, node in model.nodes.items():
        sensor(f"{name}_q", node, out.Coordinates, node=True)
        sensor(f"{name}_q_t", node, out.Coordinates_t, node=True)
    for name in PAIR_NAMES:
        sensor(f"{name}_force", model.joints[name], out.ForceLocal)
        sensor(f"{name}_torque", model.joints[name], out.TorqueLocal)
    if model.drive_connector is not None:
        sensor("drive_force", model.drive_connector, out.Force)
