"""What a friction evaluation reads from Exudyn and the loads it sets, in plain floats (numpy on
3-vectors costs more than the law; measured: docs/engines.md#friction-coupling-measurements).

Reactions: a generic joint's six Lagrange multipliers (force, torque; pair frame, or global force
components when its first marker is on the ground). Relative speeds: BDF2 of the joint's
``Rotation`` z and ``DisplacementLocal`` z (the integrator's velocities miss the constraints by
``O(h^2)``). Loads: per moving body one body-fixed torque, plus a force at the node where a pair
slides (axial ``F`` at point ``p`` = ``F`` at the node + ``p x F``); body b gets the friction.
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
    """Where one pair's law inputs are read: its ``joint``, index ``ae`` of its first multiplier,
    ``force_rows`` turning global force components into the pair's x, y (None: already pair
    components) and whether it ``slides``."""

    joint: int
    ae: int
    force_rows: tuple | None
    slides: bool


def pair_channel(mbs: Any, joint: int, ground_first: bool, frame: np.ndarray, slides: bool) -> PairChannel:
    """The :class:`PairChannel` of an assembled ``joint``; ``frame`` (3, 3) the pair frame's columns,
    used when ``ground_first``."""
    rows = None
    if ground_first:
        rows = (tuple(float(c) for c in frame[:, 0]), tuple(float(c) for c in frame[:, 1]))
    return PairChannel(joint, int(mbs.systemData.GetObjectLTGAE(joint)[0]), rows, slides)


def read_reactions(mbs: Any, channels: list[PairChannel]) -> list[tuple[float, float, float, float]]:
    """Per pair ``(fx, fy, mx, my)``: force normal to the axis [N] and bending moment [N m] (as
    ``TorqueLocal``, rotated 90 deg about the axis), from one read of all multipliers."""
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
    """Per pair ``(angle [rad] in (-pi, pi], slide [m])`` (slide 0 when not read)."""
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ROTATION)[2]), float(get(c.joint, _DISPLACEMENT)[2]) if c.slides else 0.0)
            for c in channels]


def bdf2_speeds(coords: list, h1: float, previous: list, h2: float | None = None,
                before: list | None = None) -> list[tuple[float, float]]:
    """Per pair ``(omega_rel [rad/s], slide_rel [m/s])``: BDF2 of ``coords``, ``previous`` and ``before``
    over steps ``h1``, ``h2`` [s] (BDF1 without ``before``), angles unwrapped."""
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
    """Per pair ``(omega_rel [rad/s], slide_rel [m/s])`` from the joint's velocity outputs (the initial
    state, no history)."""
    get = mbs.GetObjectOutput
    return [(float(get(c.joint, _ANGULAR_VELOCITY)[2]),
             float(get(c.joint, _VELOCITY)[2]) if c.slides else 0.0) for c in channels]


class PairReader:
    """The law's inputs of every pair after a Newton solve in one pass (the hot path), bit-identical to
    :func:`read_reactions`, :func:`pair_coordinates` and :func:`bdf2_speeds`; keeps the last two
    accepted steps and sets :attr:`regime` (each pair's side of its sign ramps). ``sides``: per pair
    journal radius [m] and rotation, sliding ramp widths [m/s]; ``start_time`` [s]."""

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
        """Per pair ``(|F| [N], |M| [N m], omega_rel [rad/s], slide_rel [m/s])`` at the current state,
        setting :attr:`regime`; ``t`` [s] for BDF2 over the accepted steps, None for the initial state."""
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
    """The merged friction loads of the moving bodies. ``contributions``: per pair, per moving body
    (body number, pair point in its node frame [m], +1 body b / -1 body a); ``axes`` per pair the unit
    axis in node frames; ``slides`` per pair whether it carries an axial force."""

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
        """Set every load from flat ``friction`` ``(torque_0, force_0, torque_1, ...)`` on body b [N m, N]."""
        set_load = self.mbs.SetLoadParameter
        for load, terms in self._loads:
            x = y = z = 0.0
            for index, ax, ay, az in terms:
                value = friction[index]
                x += value * ax
                y += value * ay
                z += value * az
            set_load(load, "loadVector", [x, y, z])
