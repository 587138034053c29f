"""The RCCC Cardan joint as an Exudyn model, built from a scene with only the items it needs.

Three rigid-body nodes at the centres of mass (node axes = global axes at input angle 0; the input
always ``NodeRigidBodyRxyz``, its first angle the input angle); four ``ObjectJointGeneric`` pairs
(revolute ``[1,1,1,1,1,0]``, cylindrical ``[1,1,0,1,1,0]``, z the pair axis): 17 constraints on 18
coordinates, mobility one. Mounting errors place the markers by :mod:`reference.physics.rccc`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cardan_exudyn.model.converged import ConvergedCoupling
from cardan_exudyn.model.extrapolated import ExtrapolatedCoupling
from cardan_exudyn.model.lagged import LaggedCoupling
from cardan_exudyn.model.rotations import ROTATION_COORDINATES, TWO_PI, RotationCoordinates, WholeTurns
from reference.physics import rccc
from reference.scene.drives import AngleDrive, SpeedDrive
from reference.scene.histories import run_clock
from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["CONSTRAINED_AXES", "COUPLINGS", "node_axes_in_canonical", "pair_geometry", "assembled_state",
           "ExudynModel", "build_model", "add_sensors"]

CONSTRAINED_AXES = {"revolute": [1, 1, 1, 1, 1, 0], "cylindrical": [1, 1, 0, 1, 1, 0]}
COUPLINGS = {"extrapolated": ExtrapolatedCoupling, "converged": ConvergedCoupling,
             "lagged": LaggedCoupling}
"""The friction coupling scheme of each ``scene.friction.coupling`` but ``uncoupled`` (friction
evaluated after the run)."""


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` of two 3-vectors without ``np.cross``'s axis handling (costlier than the product)."""
    a0, a1, a2 = (float(x) for x in a)
    b0, b1, b2 = (float(x) for x in b)
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _loop_motion(scene: Scene, theta: float, omega: float) -> dict[str, rccc.BodyMotion]:
    """Body motions of the joint with mounting errors at input angle ``theta`` [rad], speed ``omega``
    [rad/s]."""
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
    y_out = _cross(ez, a2)
    return {
        "frame_input": (-geo.input_bearing * ex, np.column_stack([ey, ez, ex])),
        "input_spider": (np.zeros(3), np.column_stack([ez, ex, ey])),
        "spider_output": (np.zeros(3), np.eye(3)),
        "output_frame": (geo.output_bearing * a2, np.column_stack([y_out, ez, a2])),
    }


def assembled_state(scene: Scene, theta: float, omega: float) -> dict[str, dict[str, np.ndarray]]:
    """Per moving body at input angle ``theta`` [rad] and speed ``omega`` [rad/s]: ``A`` (node to global),
    ``omega`` [rad/s], frame ``origin`` [m] and ``velocity`` [m/s] (zero for the ideal joint).

    Ideal joint, closed form independent of ``reference``: the velocity loop
    ``omega e_x + gamma_t u1 = theta2_t a2 + phi_t u2``. Mounting errors: :mod:`reference.physics.rccc`.
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
    u2 = _cross(a2, u1)
    u2 /= np.linalg.norm(u2)
    a_spider = np.column_stack([_cross(u1, u2), u1, u2])
    a_out_canonical = np.column_stack([a2, _cross(u2, a2), u2])
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
    friction: Any = None  # a cardan_exudyn.model.coupling.FrictionCoupling when friction is applied
    node_type: str = "Rxyz"  # the build_model argument
    # per body: the node's rotation coordinates (cardan_exudyn.model.rotations.ROTATION_COORDINATES)
    rotations: dict[str, RotationCoordinates] = field(default_factory=dict)
    # whole revolutions taken out of the input's angle coordinate (_wrap_rotations)
    input_turns: WholeTurns = field(default_factory=WholeTurns)
    # the scene's time at the model's t = 0 [s] (reference.scene.histories.run_clock): model.scene's
    # histories start at 0, the results' time column adds this back
    time_origin: float = 0.0


def build_model(scene: Scene, sensors: bool = True, reactions: bool = True,
                node_type: str = "Rxyz") -> ExudynModel:
    """Assemble (not solve) the Exudyn system of ``scene`` on a clock starting at 0 (``time_origin``:
    the scene's time there), with recording ``sensors`` (``reactions``: the eight pair reactions too).
    ``node_type`` of spider and output: ``"Rxyz"``, ``"EP"`` or ``"RotVecLG"`` (needs spectral radius
    <= 0.8: docs/engines.md#exudyn-model-measurements); the input stays Rxyz (the drive uses its angle)."""
    if node_type not in ROTATION_COORDINATES:
        raise ValueError(f"node_type must be one of {list(ROTATION_COORDINATES)}, got {node_type!r}")
    # the model runs on a clock that starts at 0 (histories starting at t = 1e9 s included):
    # model.scene is the scene on that clock, model.time_origin what was subtracted
    scene, origin = run_clock(scene)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    model = ExudynModel(scene=scene, system_container=sc, mbs=mbs, node_type=node_type,
                        time_origin=origin)
    ground = mbs.AddObject(eii.ObjectGround())
    _add_bodies(model)
    _add_pairs(model, ground)
    _add_drive(model, ground)
    _add_loads(model)
    if scene.has_friction and scene.friction.coupling != "uncoupled":
        model.friction = COUPLINGS[scene.friction.coupling](model)
    if sensors:
        add_sensors(model, reactions=reactions)
    mbs.Assemble()
    if model.friction is not None:
        model.friction.prepare()
    _wrap_rotations(model)
    return model


def _add_bodies(model: ExudynModel) -> None:
    """A node and a rigid body per moving body, in the assembled initial state."""
    scene = model.scene
    theta0, omega0, t0 = _initial_drive_state(scene)
    model.start_time = t0
    state = assembled_state(scene, theta0, omega0)
    reference_state = assembled_state(scene, 0.0, 0.0)
    axes = node_axes_in_canonical(scene)
    for name, body in scene.joint.bodies():
        mass, com_c, inertia_c = body.canonical()
        r = axes[name]
        com = r @ com_c  # from the body's frame origin, node axes = global axes at reference
        model.com_reference[name] = reference_state[name]["origin"] + com
        model.mass[name] = mass
        model.inertia[name] = r @ inertia_c @ r.T
        rot = ROTATION_COORDINATES["Rxyz" if name == "input" else model.node_type]
        model.rotations[name] = rot
        p0 = rot.from_matrix(state[name]["A"])
        if name == "input":  # its angle coordinate starts within [-pi, pi]: the rest is whole turns
            model.input_turns = WholeTurns(start=round((theta0 - p0[0]) / TWO_PI))
        _add_body(model, name, state[name], com, p0)


def _add_body(model: ExudynModel, name: str, state: dict[str, np.ndarray], com: np.ndarray,
              p0: np.ndarray) -> None:
    """The node and rigid body of body ``name`` in its initial ``state``; ``com`` its centre of mass from
    its frame origin [m], ``p0`` its initial rotation coordinates."""
    rot = model.rotations[name]
    inertia = model.inertia[name]
    w = state["omega"]
    arm = state["A"] @ com
    pos0 = state["origin"] + arm
    node = model.mbs.AddNode(getattr(eii, rot.node_class)(
        referenceCoordinates=[*model.com_reference[name], *rot.reference],
        initialCoordinates=[*(pos0 - model.com_reference[name]), *(p0 - np.asarray(rot.reference))],
        initialVelocities=[*(state["velocity"] + _cross(w, arm)), *rot.rates(p0, w)],
    ))
    model.nodes[name] = node
    model.bodies[name] = model.mbs.AddObject(eii.ObjectRigidBody(
        mass=model.mass[name],
        inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2],
                 inertia[1, 2], inertia[0, 2], inertia[0, 1]],
        centerOfMass=[0.0, 0.0, 0.0],
        nodeNumber=node,
    ))


def _add_pairs(model: ExudynModel, ground: int) -> None:
    """A marker on each body of each pair and the pair's generic joint (R or C)."""
    mbs = model.mbs

    def marker(owner: str, position: np.ndarray, frame: np.ndarray):
        # node axes equal the global axes at reference, so the pair frame is the marker rotation
        body = ground if owner == "ground" else model.bodies[owner]
        local = position - (0.0 if owner == "ground" else model.com_reference[owner])
        ht = exu.HT(rotation=frame, translation=local)
        return mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localHT=ht)), local

    for name, (origin, frame) in pair_geometry(model.scene).items():
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


def _wrap_rotations(model: ExudynModel) -> None:
    """After every step keep the Rxyz angles within ``[-pi, pi]`` (the input's whole turns recorded in
    ``ExudynModel.input_turns``) and ``RotVecLG`` vectors within ``|nu| <= pi`` (``nu (1 - 2 pi / |nu|)``).

    Why: an unbounded input angle rounds at the spacing of doubles and wanders from ``omega t``, and a
    rotation vector reaches the singular ``|nu| = 2 pi`` every two revolutions. The hook runs before
    the step's sensors are stored. Measured: docs/engines.md#exudyn-model-measurements.
    """
    mbs = model.mbs
    angle, angles, vectors = _rotation_indices(model)
    system_data = mbs.systemData
    current = exu.ConfigurationType.Current
    turns = model.input_turns

    def post_step(mbs_, t):
        q = system_data.GetODE2Coordinates(current)
        changed = abs(q[angle]) > math.pi
        if changed:
            q[angle] = turns.remove(float(q[angle]), system_data.GetTime(current))
        for i in angles:
            if abs(q[i]) > math.pi:
                q[i] -= TWO_PI * round(q[i] / TWO_PI)
                changed = True
        for i in vectors:
            x, y, z = q[i], q[i + 1], q[i + 2]
            phi = math.sqrt(x * x + y * y + z * z)
            if phi > math.pi:
                q[i:i + 3] *= 1.0 - TWO_PI / phi
                changed = True
        if changed:
            system_data.SetODE2Coordinates(q, current)
        return True

    model.user_functions.append(post_step)
    mbs.SetPostStepUserFunction(post_step)


def _rotation_indices(model: ExudynModel) -> tuple[int, list[int], list[int]]:
    """ODE2 indices of the input angle, of the other Rxyz nodes' angles and of each ``RotVecLG`` vector's
    first component."""
    mbs = model.mbs
    angle = mbs.GetNodeODE2Index(model.nodes["input"]) + 3
    angles = [mbs.GetNodeODE2Index(node) + 3 + k for name, node in model.nodes.items()
              if name != "input" and model.rotations[name].name == "Rxyz" for k in range(3)]
    vectors = [mbs.GetNodeODE2Index(node) + 3 for name, node in model.nodes.items()
               if model.rotations[name].name == "RotVecLG"]
    return angle, angles, vectors


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
    """The input's drive against ``ground``: a torque load, or a coordinate constraint on its angle
    (velocity level for a constant speed, position level with a spline offset for a history)."""
    mbs = model.mbs
    drive = model.scene.drive
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
        angle = drive.evaluator()  # O(log n) per call in plain floats (reference.scene.histories)
        turns = model.input_turns  # the coordinate is the angle less these (_wrap_rotations)

        def angle_offset(mbs_, t, item, offset):
            return angle(t) - TWO_PI * turns.count

        model.user_functions.append(angle_offset)
        connector = eii.ObjectConnectorCoordinate(markerNumbers=[m_ground, m_angle],
                                                  offsetUserFunction=angle_offset)
    model.drive_connector = mbs.AddObject(connector)


def _add_loads(model: ExudynModel) -> None:
    mbs = model.mbs
    scene = model.scene
    axis = model.pair_frames["output_frame"][:, 2]  # the output axis, fixed in the ground
    if not scene.load.constant:  # a measured history: interpolated at each instant
        torque = scene.load.evaluator()  # O(log n) per call in plain floats (reference.scene.histories)
        ax, ay, az = (-float(c) for c in axis)

        def load_history(mbs_, t, load_vector):
            value = torque(t)
            return [value * ax, value * ay, value * az]

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


def add_sensors(model: ExudynModel, reactions: bool = True) -> None:
    """In-memory sensors of node states, drive force and (``reactions``, most of a frictionless run's
    recording cost) the pair reactions, stored every step into ``model.sensors``."""
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
    for name in PAIR_NAMES if reactions else ():
        sensor(f"{name}_force", model.joints[name], out.ForceLocal)
        sensor(f"{name}_torque", model.joints[name], out.TorqueLocal)
    if model.drive_connector is not None:
        sensor("drive_force", model.drive_connector, out.Force)
