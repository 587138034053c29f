"""What a friction evaluation reads from Exudyn and the loads it sets, in plain floats.

The friction coupling (:mod:`cardan_exudyn.model.coupling`) evaluates the law after every Newton
solve; on this model numpy on three-vectors costs more than the law itself, so everything here is
float arithmetic on values read once per evaluation.

Reactions
---------
All Lagrange multipliers are read with one ``GetAECoordinates`` call. Each ``ObjectJointGeneric``
owns six of them (``GetObjectLTGAE``): force then torque. For a joint between two bodies they
equal its ``ForceLocal`` and ``TorqueLocal`` outputs (components in the joint frame, z the pair
axis; ``TorqueLocal``'s in-plane components are rotated by 90 deg, which the magnitude ignores).
For a joint whose first marker is on the ground, the force part is in global components and the
constant rows of the ground marker's frame give the pair components (measured on Exudyn 1.13.6 and
pinned by ``tests/test_coupling_lean.py`` against ``ForceLocal`` / ``TorqueLocal``).

Relative motion
---------------
The pair angle and slide are the joint's own ``Rotation`` z and ``DisplacementLocal`` z outputs
(the relative rotation of body b about the axis and the axial offset of its pair point, in the
frame of body a); the relative speeds are their second-order backward differences, as in
:func:`cardan_exudyn.model.postprocess.relative_speeds`, because the integrator's velocities miss
the velocity constraints by ``O(h^2)`` (about 1e-3 m/s of spurious slide). At the initial,
consistent state the joint's ``AngularVelocityLocal`` z and ``VelocityLocal`` z are used.

Loads
-----
One body-fixed ``LoadTorqueVector`` per moving body with friction, and a body-fixed
``LoadForceVector`` at its centre of mass (the node) only where a pair slides: a pair's axial
force ``F`` at its point ``p`` (node frame) is the force ``F`` at the node plus the torque
``p x F``, exact for a rigid body. Body ``b`` of a pair receives the friction, body ``a`` its
opposite; the pair axis is fixed in both bodies, so every contribution is a constant vector
times one number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cardan_exudyn.model.friction_law import bdf2_weights

__all__ = ["PairChannel", "pair_channel", "read_reactions", "pair_coordinates", "bdf2_speeds",
           "initial_speeds", "BodyLoads"]

_ROTATION = exu.OutputVariableType.Rotation
_DISPLACEMENT = exu.OutputVariableType.DisplacementLocal
_ANGULAR_VELOCITY = exu.OutputVariableType.AngularVelocityLocal
_VELOCITY = exu.OutputVariableType.VelocityLocal
_PI, _TWO_PI = math.pi, 2.0 * math.pi


@dataclass(frozen=True)
class PairChannel:
    """Where one pair's law inputs are read.

    Attributes
    ----------
    joint : int
        The pair's ``ObjectJointGeneric``.
    ae : int
        Index of its first Lagrange multiplier in the system's algebraic coordinates.
    force_rows : tuple or None
        None: the force multipliers are pair components; else the two rows (3-tuples) that turn
        global components into the pair's x and y (a joint whose first marker is on the ground).
    slides : bool
        Whether the pair's slide is read (a cylindrical pair of a joint with mounting errors).
    """

    joint: int
    ae: int
    force_rows: tuple | None
    slides: bool


def pair_channel(mbs: Any, joint: int, ground_first: bool, frame: np.ndarray, slides: bool) -> PairChannel:
    """The channel of ``joint`` (after ``mbs.Assemble``); ``frame`` the pair frame's columns in
    global axes (the ground marker's, used when ``ground_first``)."""
    rows = None
    if ground_first:
        rows = (tuple(float(c) for c in frame[:, 0]), tuple(float(c) for c in frame[:, 1]))
    return PairChannel(joint, int(mbs.systemData.GetObjectLTGAE(joint)[0]), rows, slides)


def read_reactions(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float, float, float]]:
    """Per pair the reaction in the pair frame from one read of all multipliers: the force
    components normal to the axis [N] and the bending moment's two components [N m] (as
    ``TorqueLocal`` gives them: rotated by 90 deg about the axis, which magnitudes ignore)."""
    ae = mbs.systemData.GetAECoordinates(exu.ConfigurationType.Current).tolist()
    out = []
    for c in channels:
        i = c.ae
        if c.force_rows is None:
            fx, fy = ae[i], ae[i + 1]
        else:
            (a, b, d), (e, f, g) = c.force_rows
            gx, gy, gz = ae[i], ae[i + 1], ae[i + 2]
            fx, fy = a * gx + b * gy + d * gz, e * gx + f * gy + g * gz
        out.append((fx, fy, ae[i + 3], ae[i + 4]))
    return out


def pair_coordinates(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float]]:
    """Per pair: the relative rotation angle [rad] and the slide [m] (0 for a pair that is not read)."""
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ROTATION)[2]), float(get(c.joint, _DISPLACEMENT)[2]) if c.slides else 0.0)
            for c in channels]


def bdf2_speeds(coords: list, h1: float, previous: list, h2: float | None = None,
                before: list | None = None) -> list[tuple[float, float]]:
    """Relative angular and sliding speeds: BDF2 of the pair coordinates over the steps ``h1``
    (``coords`` from ``previous``) and ``h2`` (``previous`` from ``before``); BDF1 without
    ``before``. Angles are unwrapped."""
    out = []
    if before is None:
        for (a, s), (a1, s1) in zip(coords, previous, strict=True):
            out.append((((a - a1 + _PI) % _TWO_PI - _PI) / h1, (s - s1) / h1))
        return out
    w1, w2 = bdf2_weights(h1, h2)
    w1, w2 = w1 / h1, w2 / h1
    for (a, s), (a1, s1), (a2, s2) in zip(coords, previous, before, strict=True):
        d1 = (a - a1 + _PI) % _TWO_PI - _PI
        d2 = (a1 - a2 + _PI) % _TWO_PI - _PI
        out.append((w1 * d1 - w2 * d2, w1 * (s - s1) - w2 * (s1 - s2)))
    return out


def initial_speeds(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float]]:
    """Per pair: relative angular and sliding speed from the joint's velocity outputs (for the
    consistent initial state, where no history exists)."""
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ANGULAR_VELOCITY)[2]),
             float(get(c.joint, _VELOCITY)[2]) if c.slides else 0.0) for c in channels]


class BodyLoads:
    """The merged friction loads of the moving bodies (see the module doc).

    ``contributions``: per pair, ``(body number, node-frame pair point, +1 for body b / -1 for
    body a)`` for each moving body of the pair; ``axes``: per pair the axis in node frames;
    ``slides``: per pair whether it carries an axial force.
    """

    def __init__(self, mbs: Any, contributions: list[list[tuple[int, np.ndarray, int]]],
                 axes: list[np.ndarray], slides: list[bool]) -> None:
        self.mbs = mbs
        bodies: dict[int, dict] = {}
        for k, (parts, axis, slide) in enumerate(zip(contributions, axes, slides, strict=True)):
            for body, point, role in parts:
                entry = bodies.setdefault(body, {"torque": [], "force": []})
                entry["torque"].append((k, 0, *(role * float(c) for c in axis)))
                if slide:
                    arm = np.cross(point, axis)
                    entry["torque"].append((k, 1, *(role * float(c) for c in arm)))
                    entry["force"].append((k, 1, *(role * float(c) for c in axis)))
        self._loads = []  # (load number, [(pair, column, x, y, z)])
        self.kinds: list[str] = []  # "torque" or "force", per load added
        for body, entry in bodies.items():
            marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
            for kind, item in (("torque", eii.LoadTorqueVector), ("force", eii.LoadForceVector)):
                if entry[kind]:
                    load = mbs.AddLoad(item(markerNumber=marker, loadVector=[0.0, 0.0, 0.0], bodyFixed=True))
                    self._loads.append((load, entry[kind]))
                    self.kinds.append(kind)

    def apply(self, friction: list) -> None:
        """Set every load from ``friction``, per pair ``(torque, force)`` on body b [N m, N]."""
        set_load = self.mbs.SetLoadParameter
        for load, terms in self._loads:
            x = y = z = 0.0
            for k, j, ax, ay, az in terms:
                value = friction[k][j]
                x += value * ax
                y += value * ay
                z += value * az
            set_load(load, "loadVector", [x, y, z])
