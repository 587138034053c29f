"""The result schema's columns from an Exudyn run's recorded sensors.

Reaction conventions of ``ObjectJointGeneric`` (Exudyn 1.13.6, pinned by ``tests/test_reactions.py``):
``ForceLocal`` is minus the force of body a on body b in a's joint frame; the moment of a on b in
b's pair frame is ``(-TL_y, TL_x, -TL_z)`` of ``TorqueLocal``. The drive torque is minus the
coordinate connector's ``Force``.
"""

from __future__ import annotations

import numpy as np

from cardan_exudyn.model.build import ExudynModel
from cardan_exudyn.model.friction_law import PairLaw, bdf2_weights, pair_loads
from cardan_exudyn.model.projection import cross_rows, project_velocities
from reference.physics.bands import sign_bands
from reference.results.columns import instantaneous_efficiency
from reference.scene.drives import AngleDrive
from reference.scene.joint import PAIR_BODIES, PAIR_KIND, PAIR_NAMES

__all__ = ["postprocess", "body_states", "pair_kinematics", "relative_speeds", "relative_angle",
           "mechanical_energy", "constraint_violation", "first_non_finite", "stored"]


def first_non_finite(columns: dict[str, np.ndarray]) -> str | None:
    """The first column (``efficiency`` aside) with a non-finite value, None when all are finite."""
    checked = [v for k, v in columns.items() if k != "efficiency"]
    if not checked or np.isfinite(np.concatenate([np.ravel(v) for v in checked])).all():
        return None  # one test of all the columns, the common case
    for key, values in columns.items():
        if key != "efficiency" and not np.all(np.isfinite(values)):
            return key
    return None


def stored(model: ExudynModel, key: str) -> np.ndarray:
    """The stored data of sensor ``key``, shape (n, 1 + k): time [s], then its values;
    ``ValueError`` when it recorded nothing."""
    data = np.asarray(model.mbs.GetSensorStoredData(model.sensors[key]))
    if data.ndim != 2:  # nothing recorded, e.g. a failure in the first step
        raise ValueError(f"sensor `{key}` recorded no data")
    return data


def body_states(model: ExudynModel) -> dict[str, dict[str, np.ndarray]]:
    """Per body: time, CoM position, velocity, rotation matrices (node axes), angular velocity and
    ``psi``, the node's total rotation coordinates (the input's first the continuous shaft angle)."""
    states = {}
    for name in model.nodes:
        q = stored(model, f"{name}_q")
        q_t = stored(model, f"{name}_q_t")
        n = min(len(q), len(q_t))
        q = q[:n]
        q_t = q_t[:n]
        rot = model.rotations[name]
        end = 4 + rot.size
        p = q[:, 4:end] if rot.zero_reference else q[:, 4:end] + np.asarray(rot.reference)
        a, omega = rot.frame(p, q_t[:, 4:end])  # from the coordinates the solver had
        if name == "input":
            p = p.copy()
            p[:, 0] = model.input_turns.angle(q[:, 0], p[:, 0])
        states[name] = {
            "t": q[:, 0],
            "r": model.com_reference[name] + q[:, 1:4],
            "v": q_t[:, 1:4],
            "A": a,
            "omega": omega,
            "psi": p,
        }
    return states


Kinematics = dict[str, dict[str, np.ndarray]]


def pair_kinematics(model: ExudynModel, states: dict, n: int,
                    positions: Kinematics | None = None) -> Kinematics:
    """Per pair, global, first ``n`` rows: ``frame_a``, ``frame_b`` (n, 3, 3), marker points ``pa``,
    ``pb`` [m], their velocities ``va``, ``vb`` [m/s], ``omega_a``, ``omega_b`` [rad/s] and
    ``relative = frame_a^T frame_b``; ``positions``: reuse its position-level entries."""
    out = {}
    for name in PAIR_NAMES:
        body_a, body_b = PAIR_BODIES[name]
        sa = None if body_a == "ground" else states[body_a]
        sb = None if body_b == "ground" else states[body_b]
        if positions is None:
            k = _pair_positions(model, name, sa, sb, n)
        else:
            k = {key: positions[name][key] for key in ("frame_a", "frame_b", "pa", "pb", "relative")}
        k["va"], k["omega_a"] = _marker_velocity(sa, k["pa"], n)
        k["vb"], k["omega_b"] = _marker_velocity(sb, k["pb"], n)
        out[name] = k
    return out


def _pair_positions(model: ExudynModel, name: str, sa: dict | None, sb: dict | None,
                    n: int) -> dict[str, np.ndarray]:
    """Pair frames and marker points of one pair (a ground body: None)."""
    l_a, l_b = model.marker_local[name]
    frame = model.pair_frames[name]
    k = {}
    for side, s, local in (("a", sa, l_a), ("b", sb, l_b)):
        if s is None:  # the ground: identity rotation, origin at zero
            k[f"frame_{side}"] = np.broadcast_to(frame, (n, 3, 3))
            k[f"p{side}"] = np.broadcast_to(np.asarray(local, float), (n, 3))
        else:
            k[f"frame_{side}"] = s["A"][:n] @ frame
            k[f"p{side}"] = s["r"][:n] + s["A"][:n] @ local
    k["relative"] = np.einsum("nji,njk->nik", k["frame_a"], k["frame_b"])  # frame_a^T frame_b
    return k


def _marker_velocity(s: dict | None, p: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Velocity of the body point ``p`` (n, 3) and the body's angular velocity (ground: zeros)."""
    if s is None:
        zero = np.zeros((n, 3))
        return zero, zero
    return s["v"][:n] + cross_rows(s["omega"][:n], p - s["r"][:n]), s["omega"][:n]


def postprocess(model: ExudynModel, project: bool = False) -> dict[str, np.ndarray]:
    """The result schema's columns (SI, shape (n,)) from the solved ``model``'s sensors, setting its
    ``pair_kinematics``; ``project``: velocities projected onto the velocity constraints.
    ``ValueError`` for fewer than two recorded steps."""
    states = body_states(model)
    n = min(len(s["t"]) for s in states.values())
    if n < 2:
        raise ValueError("fewer than two recorded steps")
    kin = pair_kinematics(model, states, n)
    if project:
        states = projected_states(model, states, n, kin)
        kin = pair_kinematics(model, states, n, positions=kin)
    cols = _shaft_columns(model, states, kin, n)
    for name in PAIR_NAMES:
        cols.update(_pair_columns(model, name, kin[name], cols["t"], n))
    applied = _friction_columns(model, cols, n)
    loss_total = np.zeros(n)
    for name in PAIR_NAMES:
        torque, force = applied[name]
        loss = -(torque * cols[f"{name}_omega_rel"] + force * cols[f"{name}_slide_rel"])
        loss_total += loss
        cols[f"{name}_friction_torque"] = torque
        cols[f"{name}_friction_force"] = force
        cols[f"power_loss_{name}"] = loss
    cols["power_loss"] = loss_total
    cols["energy_kinetic"], cols["energy_potential"] = mechanical_energy(model, states, n)
    cols["efficiency"] = instantaneous_efficiency(cols["power_in"], loss_total)
    model.pair_kinematics = kin
    return cols


def _shaft_columns(model: ExudynModel, states: dict, kin: dict, n: int) -> dict[str, np.ndarray]:
    """Time, shaft angles and speeds, torques and powers."""
    scene = model.scene
    t = states["input"]["t"][:n]
    cols: dict[str, np.ndarray] = {"t": t}
    cols["theta_in"] = states["input"]["psi"][:n, 0]
    cols["omega_in"] = states["input"]["omega"][:n, 0]
    # the output turns about the output_frame axis (fixed in the ground); its angle is minus the
    # pair's relative rotation (ground relative to output), zero in the reference configuration
    cols["theta_out"] = -relative_angle(kin["output_frame"])
    cols["omega_out"] = states["output"]["omega"][:n] @ model.pair_frames["output_frame"][:, 2]
    if scene.drive.kind == "torque":
        cols["torque_in"] = np.full(n, scene.drive.torque)
    else:
        cols["torque_in"] = -stored(model, "drive_force")[:n, 1]
    cols["torque_out"] = scene.load.at(t)
    cols["power_in"] = cols["torque_in"] * cols["omega_in"]
    cols["power_out"] = cols["torque_out"] * cols["omega_out"]
    return cols


def _pair_columns(model: ExudynModel, name: str, k: dict[str, np.ndarray], t: np.ndarray,
                  n: int) -> dict[str, np.ndarray]:
    """Reaction components in the pair frame of body a, and the relative speeds, of one pair."""
    if f"{name}_force" in model.sensors:
        force = stored(model, f"{name}_force")[:n, 1:4]
        torque = stored(model, f"{name}_torque")[:n, 1:4]
    else:  # reactions not recorded (summary-only run)
        force = torque = np.full((n, 3), np.nan)
    fx, fy, fz = (-force).T
    # TorqueLocal: 90-degree in-plane swap, sign flip, and components in the frame of body b
    m_b = np.stack([-torque[:, 1], torque[:, 0], -torque[:, 2]], axis=1)
    mx, my, mz = np.einsum("nij,nj->ni", k["relative"], m_b).T
    omega_rel, slide_rel = relative_speeds(t, k, cylindrical=PAIR_KIND[name] == "cylindrical")
    values = (fx, fy, fz, mx, my, mz, omega_rel, slide_rel)
    suffixes = ("fx", "fy", "fz", "mx", "my", "mz", "omega_rel", "slide_rel")
    return {f"{name}_{s}": v for s, v in zip(suffixes, values, strict=True)}


def _friction_columns(model: ExudynModel, cols: dict[str, np.ndarray],
                      n: int) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Friction torque and force on body b of each pair at the recorded times: what the coupling applied,
    or (``uncoupled``) the law on the frictionless reactions row by row."""
    scene = model.scene
    if model.friction is not None:
        applied = model.friction.columns(cols["t"])
        return {p: (applied[f"{p}_friction_torque"], applied[f"{p}_friction_force"])
                for p in PAIR_NAMES}
    out = {p: (np.zeros(n), np.zeros(n)) for p in PAIR_NAMES}
    if not scene.has_friction:
        return out
    bands = sign_bands(scene)
    for name, pair in scene.joint.friction_pairs():
        if pair.friction_coefficient <= 0.0:
            continue
        law = PairLaw.of(PAIR_KIND[name], pair, scene.friction.law)
        band = bands[name]
        rows = zip(*(cols[f"{name}_{s}"].tolist()
                     for s in ("fx", "fy", "mx", "my", "omega_rel", "slide_rel")), strict=True)
        loads = [pair_loads(law, *row, band.rotation, band.sliding, band.resultant) for row in rows]
        out[name] = (np.array([x.torque for x in loads]), np.array([x.force for x in loads]))
    return out


def projected_states(model: ExudynModel, states: dict, n: int, kin: dict | None = None) -> dict:
    """The first ``n`` rows of ``states`` with ``v`` and ``omega`` projected onto the velocity
    constraints; the largest correction [m/s] left in ``model.velocity_correction``."""
    drive = model.scene.drive
    if isinstance(drive, AngleDrive):
        spline = drive.spline()

        def input_speed(t):
            return spline(t, 1)
    elif drive.kind == "speed":
        def input_speed(t):
            return np.full(np.shape(t), drive.speed)
    else:
        input_speed = None
    trimmed = {name: {k: v[:n] for k, v in s.items()} for name, s in states.items()}
    kin = pair_kinematics(model, trimmed, n) if kin is None else kin
    projected = project_velocities(trimmed, kin, model.mass,
                                   model.inertia, model.pair_frames["frame_input"][:, 2], input_speed)
    model.velocity_correction = projected.pop("max_velocity_correction")
    return projected


def relative_angle(k: dict[str, np.ndarray]) -> np.ndarray:
    """Rotation of body b's pair frame relative to body a's about the pair axis [rad], unwrapped."""
    rel = k["relative"] if "relative" in k else np.einsum("nji,njk->nik", k["frame_a"], k["frame_b"])
    return np.unwrap(np.arctan2(rel[:, 1, 0], rel[:, 0, 0]))


def relative_speeds(t: np.ndarray, k: dict[str, np.ndarray],
                    cylindrical: bool) -> tuple[np.ndarray, np.ndarray]:
    """``(omega_rel [rad/s], slide_rel [m/s])`` of body b w.r.t. a of one pair (``k``), at times ``t``.

    BDF2 (BDF1 for the first step) of the relative angle and axial offset, the initial row at
    velocity level: index-3 integration leaves O(h^2) residuals in the velocity constraints (~1e-3
    m/s of spurious slide). The friction law uses the same definition in the step loop.
    """
    axis = k["frame_a"][:, :, 2]
    angle = relative_angle(k)
    velocity_level = [np.einsum("ij,ij->i", k["omega_b"] - k["omega_a"], axis)]
    coords = [angle]
    if cylindrical:
        coords.append(np.einsum("ij,ij->i", k["pb"] - k["pa"], axis))
        velocity_level.append(np.einsum("ij,ij->i", k["vb"] - k["va"], axis))
    speeds = []
    for c, v in zip(coords, velocity_level, strict=True):
        out = np.empty_like(c)
        out[0] = v[0]
        if len(c) > 1:
            out[1] = (c[1] - c[0]) / (t[1] - t[0])
        if len(c) > 2:
            h1 = np.diff(t)[1:]
            h2 = np.diff(t)[:-1]
            w1, w2 = bdf2_weights(h1, h2)
            out[2:] = (w1 * (c[2:] - c[1:-1]) - w2 * (c[1:-1] - c[:-2])) / h1
        speeds.append(out)
    if not cylindrical:
        speeds.append(np.zeros_like(angle))
    return speeds[0], speeds[1]


def mechanical_energy(model: ExudynModel, states: dict, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and gravitational potential energy [J] of the three bodies, first ``n`` rows."""
    kinetic = np.zeros(n)
    potential = np.zeros(n)
    g = np.asarray(model.scene.gravity)
    for name, s in states.items():
        m = model.mass[name]
        j_body = model.inertia[name]
        w_body = np.einsum("nji,nj->ni", s["A"][:n], s["omega"][:n])  # A^T omega
        kinetic += 0.5 * m * np.einsum("ni,ni->n", s["v"][:n], s["v"][:n])
        kinetic += 0.5 * np.einsum("ni,ij,nj->n", w_body, j_body, w_body)
        potential -= m * (s["r"][:n] @ g)
    return kinetic, potential


def constraint_violation(pair_kinematics: dict[str, dict[str, np.ndarray]]) -> dict[str, float]:
    """Largest pair-constraint violation over the run: position [m] (marker points, or b from a's axis
    for cylindrical pairs) and axis misalignment [rad]."""
    pos = 0.0
    ang = 0.0
    for name, k in pair_kinematics.items():
        d = k["pb"] - k["pa"]
        za = k["frame_a"][:, :, 2]
        zb = k["frame_b"][:, :, 2]
        if PAIR_KIND[name] == "cylindrical":
            d = d - np.einsum("ij,ij->i", d, za)[:, None] * za
        pos = max(pos, float(np.max(np.linalg.norm(d, axis=1))))
        ang = max(ang, float(np.max(np.linalg.norm(cross_rows(za, zb), axis=1))))
    return {"max_constraint_violation_m": pos, "max_constraint_violation_rad": ang}
