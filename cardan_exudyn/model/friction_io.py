"""What a friction evaluation reads from Exudyn and the loads it sets, in plain floats.

The friction coupling (:mod:`cardan_exudyn.model.coupling`) evaluates the law after every Newton
solve; on this model numpy on three-vectors costs more than the law itself, so everything here is
float arithmetic on values read once per evaluation.
The coupling's hot path reads through :class:`PairReader` (one pass over the pairs; the
functions below are the same reads one quantity at a time, for the initial state and the tests).
About half of an evaluation is Exudyn's ``GetObjectOutput`` and ``SetLoadParameter`` calls
(measured: docs/engines.md#friction-coupling-measurements).

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
           "initial_speeds", "PairReader", "BodyLoads"]

_ROTATION = exu.OutputVariableType.Rotation
_DISPLACEMENT = exu.OutputVariableType.DisplacementLocal
_ANGULAR_VELOCITY = exu.OutputVariableType.AngularVelocityLocal
_VELOCITY = exu.OutputVariableType.VelocityLocal
_CURRENT = exu.ConfigurationType.Current
_PI = math.pi
_TWO_PI = 2.0 * math.pi


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
    """The channel of one pair's joint.

    Parameters
    ----------
    mbs : exudyn MainSystem
        Assembled (``mbs.Assemble`` called).
    joint : int
        The pair's ``ObjectJointGeneric``.
    ground_first : bool
        Whether the joint's first marker is on the ground.
    frame : ndarray, shape (3, 3)
        The pair frame's columns in global axes (used when ``ground_first``).
    slides : bool
        Whether the pair's slide is read.

    Returns
    -------
    PairChannel
    """
    rows = None
    if ground_first:
        rows = (tuple(float(c) for c in frame[:, 0]), tuple(float(c) for c in frame[:, 1]))
    return PairChannel(joint, int(mbs.systemData.GetObjectLTGAE(joint)[0]), rows, slides)


def read_reactions(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float, float, float]]:
    """Per pair the reaction in the pair frame, from one read of all multipliers.

    Parameters
    ----------
    mbs : exudyn MainSystem
        At the current state.
    channels : list of PairChannel
        One per pair.

    Returns
    -------
    list of (fx, fy, mx, my)
        Per pair the force components normal to the axis [N] and the bending moment's two
        components [N m], as ``TorqueLocal`` gives them (rotated by 90 deg about the axis, which
        magnitudes ignore).
    """
    ae = mbs.systemData.GetAECoordinates(exu.ConfigurationType.Current).tolist()
    out = []
    for c in channels:
        i = c.ae
        if c.force_rows is None:
            fx, fy = ae[i], ae[i + 1]
        else:
            (a, b, d), (e, f, g) = c.force_rows
            gx, gy, gz = ae[i], ae[i + 1], ae[i + 2]
            fx = a * gx + b * gy + d * gz
            fy = e * gx + f * gy + g * gz
        out.append((fx, fy, ae[i + 3], ae[i + 4]))
    return out


def pair_coordinates(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float]]:
    """Per pair the relative rotation angle and the slide.

    Parameters
    ----------
    mbs : exudyn MainSystem
        At the current state.
    channels : list of PairChannel
        One per pair.

    Returns
    -------
    list of (angle, slide)
        Angle [rad] in ``(-pi, pi]`` and slide [m] (0 for a pair whose slide is not read).
    """
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ROTATION)[2]), float(get(c.joint, _DISPLACEMENT)[2]) if c.slides else 0.0)
            for c in channels]


def bdf2_speeds(coords: list, h1: float, previous: list, h2: float | None = None,
                before: list | None = None) -> list[tuple[float, float]]:
    """Relative angular and sliding speeds: BDF2 of the pair coordinates (BDF1 without ``before``).

    Parameters
    ----------
    coords : list of (angle, slide)
        Per pair at the current step [rad, m] (:func:`pair_coordinates`).
    h1 : float
        Step from ``previous`` to ``coords`` [s].
    previous : list of (angle, slide)
        At the step before.
    h2 : float, optional
        Step from ``before`` to ``previous`` [s].
    before : list of (angle, slide), optional
        Two steps back.

    Returns
    -------
    list of (omega_rel, slide_rel)
        Per pair [rad/s, m/s]; angle differences are unwrapped.
    """
    out = []
    if before is None:
        for (a, s), (a1, s1) in zip(coords, previous, strict=True):
            out.append((((a - a1 + _PI) % _TWO_PI - _PI) / h1, (s - s1) / h1))
        return out
    w1, w2 = bdf2_weights(h1, h2)
    w1 = w1 / h1
    w2 = w2 / h1
    for (a, s), (a1, s1), (a2, s2) in zip(coords, previous, before, strict=True):
        d1 = (a - a1 + _PI) % _TWO_PI - _PI
        d2 = (a1 - a2 + _PI) % _TWO_PI - _PI
        out.append((w1 * d1 - w2 * d2, w1 * (s - s1) - w2 * (s1 - s2)))
    return out


def initial_speeds(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float]]:
    """Per pair the relative speeds from the joint's velocity outputs.

    For the consistent initial state, where no history exists.

    Parameters
    ----------
    mbs : exudyn MainSystem
        At the current state.
    channels : list of PairChannel
        One per pair.

    Returns
    -------
    list of (omega_rel, slide_rel)
        Per pair [rad/s, m/s] (0 for a slide that is not read).
    """
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ANGULAR_VELOCITY)[2]),
             float(get(c.joint, _VELOCITY)[2]) if c.slides else 0.0) for c in channels]


class PairReader:
    """The law's inputs of every pair after a Newton solve, in one pass (the coupling's hot path).

    Gives what :func:`read_reactions`, :func:`pair_coordinates` and :func:`bdf2_speeds` (or
    :func:`initial_speeds`) give together, to the last bit, and keeps the coordinates of the last
    two accepted steps for the backward differences. In the same pass it sets :attr:`regime`, the
    side of its sign ramps each pair's motion is on (as
    :meth:`cardan_exudyn.model.friction_law.LawTable.loads` gives it for the inputs it evaluates).

    Parameters
    ----------
    mbs : exudyn MainSystem
        Assembled.
    channels : list of PairChannel
    start_time : float
        Time of the initial state, whose coordinates start the history [s].
    sides : list of (float, float, float)
        Per pair the journal radius [m] and the widths of the rotation's and the sliding's sign
        ramps [m/s].
    """

    def __init__(self, mbs: Any, channels: list[PairChannel], start_time: float,
                 sides: list[tuple[float, float, float]]) -> None:
        self.mbs = mbs
        self.channels = list(channels)
        self._get = mbs.GetObjectOutput
        self._multipliers = mbs.systemData.GetAECoordinates
        self._rows = [(c.joint, c.ae, c.force_rows, c.slides, *side)
                      for c, side in zip(self.channels, sides, strict=True)]
        self.regime: tuple[int, ...] = ()
        self.coords = pair_coordinates(mbs, self.channels)
        self._t1 = start_time
        self._c1 = self.coords
        self._t2 = self._c2 = None
        self._back: list | None = None  # per pair (a1, s1, d2, s1 - s2) of the accepted steps
        self._steps = self._weights = (None, None)

    def accept(self, t: float) -> None:
        """The coordinates read last are those of the step accepted at ``t`` [s]."""
        self._t2 = self._t1
        self._c2 = self._c1
        self._t1 = t
        self._c1 = self.coords
        self._back = [(a1, s1, (a1 - a2 + _PI) % _TWO_PI - _PI, s1 - s2)
                      for (a1, s1), (a2, s2) in zip(self._c1, self._c2, strict=True)]

    def read(self, t: float | None) -> list[tuple[float, float, float, float]]:
        """The law's inputs of every pair at the current state; sets :attr:`regime`.

        One loop on purpose: this runs after every Newton solve, and a pass per quantity costs
        more than the law.

        Parameters
        ----------
        t : float or None
            Time of the state [s]: speeds by BDF2 over the accepted steps, the coordinates kept
            as :attr:`coords`; None: the initial state, with velocity-level speeds.

        Returns
        -------
        list of (float, float, float, float)
            Per pair ``|F|`` [N], ``|M|`` [N m], ``omega_rel`` [rad/s], ``slide_rel`` [m/s].
        """
        if t is None or self._back is None:
            return self._read_plain(t)
        h1 = t - self._t1
        h2 = self._t1 - self._t2
        if (h1, h2) != self._steps:
            w1, w2 = bdf2_weights(h1, h2)
            self._steps = (h1, h2)
            self._weights = (w1 / h1, w2 / h1)
        w1, w2 = self._weights
        ae = self._multipliers(_CURRENT, False).tolist()
        get = self._get
        hypot = math.hypot
        coords = []
        out = []
        regime = []
        for (joint, i, rows, slides, radius, band, slide_band), (a1, s1, d2, e2) in zip(
                self._rows, self._back, strict=True):
            a = float(get(joint, _ROTATION)[2])
            if slides:
                s = float(get(joint, _DISPLACEMENT)[2])
                v = w1 * (s - s1) - w2 * e2
            else:
                s = v = 0.0
            coords.append((a, s))
            if rows is None:
                fx, fy = ae[i], ae[i + 1]
            else:
                (ra, rb, rd), (re, rf, rg) = rows
                gx, gy, gz = ae[i], ae[i + 1], ae[i + 2]
                fx = ra * gx + rb * gy + rd * gz
                fy = re * gx + rf * gy + rg * gz
            w = w1 * ((a - a1 + _PI) % _TWO_PI - _PI) - w2 * d2
            out.append((hypot(fx, fy), hypot(ae[i + 3], ae[i + 4]), w, v))
            surface = radius * w
            regime += ((surface > band) - (surface < -band), (v > slide_band) - (v < -slide_band))
        self.coords = coords
        self.regime = tuple(regime)
        return out

    def _read_plain(self, t: float | None) -> list[tuple[float, float, float, float]]:
        reactions = read_reactions(self.mbs, self.channels)
        if t is None:
            speeds = initial_speeds(self.mbs, self.channels)
        else:
            self.coords = pair_coordinates(self.mbs, self.channels)
            speeds = bdf2_speeds(self.coords, t - self._t1, self._c1)
        out = [(math.hypot(fx, fy), math.hypot(mx, my), w, v)
               for (fx, fy, mx, my), (w, v) in zip(reactions, speeds, strict=True)]
        regime: list[int] = []
        for (*_, radius, band, slide_band), (_, _, w, v) in zip(self._rows, out, strict=True):
            surface = radius * w
            regime += ((surface > band) - (surface < -band), (v > slide_band) - (v < -slide_band))
        self.regime = tuple(regime)
        return out


class BodyLoads:
    """The merged friction loads of the moving bodies (see the module doc).

    Parameters
    ----------
    mbs : exudyn MainSystem
        The loads are added to it.
    contributions : list of list of (int, ndarray, int)
        Per pair, for each moving body of the pair: its body number, the pair point in its node
        frame [m], shape (3,), and +1 for body b, -1 for body a.
    axes : list of ndarray, shape (3,)
        Per pair the unit axis in node frames.
    slides : list of bool
        Per pair whether it carries an axial force.
    """

    def __init__(self, mbs: Any, contributions: list[list[tuple[int, np.ndarray, int]]],
                 axes: list[np.ndarray], slides: list[bool]) -> None:
        self.mbs = mbs
        bodies: dict[int, dict] = {}
        for k, (parts, axis, slide) in enumerate(zip(contributions, axes, slides, strict=True)):
            for body, point, role in parts:
                entry = bodies.setdefault(body, {"torque": [], "force": []})
                entry["torque"].append((2 * k, *(role * float(c) for c in axis)))
                if slide:
                    arm = np.cross(point, axis)
                    entry["torque"].append((2 * k + 1, *(role * float(c) for c in arm)))
                    entry["force"].append((2 * k + 1, *(role * float(c) for c in axis)))
        self._loads = []  # (load number, [(index in the flat friction, x, y, z)])
        self.kinds: list[str] = []  # "torque" or "force", per load added
        for body, entry in bodies.items():
            marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
            for kind, item in (("torque", eii.LoadTorqueVector), ("force", eii.LoadForceVector)):
                if entry[kind]:
                    load = mbs.AddLoad(item(markerNumber=marker, loadVector=[0.0, 0.0, 0.0], bodyFixed=True))
                    self._loads.append((load, entry[kind]))
                    self.kinds.append(kind)

    def apply(self, friction: tuple) -> None:
        """Set every load from ``friction``, flat ``(torque_0, force_0, torque_1, ...)`` on body b
        of each pair [N m, N]."""
        set_load = self.mbs.SetLoadParameter
        for load, terms in self._loads:
            x = y = z = 0.0
            for index, ax, ay, az in terms:
                value = friction[index]
                x += value * ax
                y += value * ay
                z += value * az
            set_load(load, "loadVector", [x, y, z])
