"""The width of each pair's friction sign ramp ``clip(v / band, -1, 1)``, relative or absolute.

By default ``band = sign_band_relative * max(v_char, SPEED_FLOOR * max v_char over the scene)``,
``v_char`` the pair's RMS surface (or sliding) speed over one input revolution at the scene's
:func:`nominal_speed`; why relative: the speeds scale with the input speed, so the share of motion
inside the ramp does not (measured: docs/paper.md, "Friction at every speed"). The floor keeps a
pair at rest far above rounding. ``FrictionSettings.sign_band`` [m/s] is one absolute band
instead (0: exact sign). Resultant-slip law: one band per pair on ``hypot`` of its rotation's and
sliding's ``v_char``. Every engine takes its bands from :func:`sign_bands`.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from reference.physics.joint_motion import joint_motion
from reference.scene.drives import AngleDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene

__all__ = ["PROFILE_SAMPLES", "SPEED_FLOOR", "PairBands", "PairSpeeds", "characteristic_speeds",
           "profile_angles", "speeds_from_profile", "needs_speeds", "bands_from_speeds", "nominal_speed",
           "sign_bands"]

SPEED_FLOOR = 1e-3
"""A pair's characteristic speed is taken as at least this fraction of the scene's largest [-]."""
PROFILE_SAMPLES = 360
"""Input angles per revolution at which the speeds are sampled (uniform grid over a period: the
RMS of these smooth periodic speeds is exact to rounding)."""


class PairSpeeds(NamedTuple):
    """Characteristic speeds of one pair [m/s]: RMS over a revolution at the nominal speed."""

    rotation: float
    """Relative surface speed ``|omega_rel| d / 2``."""
    sliding: float
    """Relative sliding speed along the axis (0 in the ideal joint and in the revolute pair)."""


class PairBands(NamedTuple):
    """Width of one pair's sign ramps [m/s] (0: the exact sign)."""

    rotation: float
    """For the friction torque, in relative surface speed."""
    sliding: float
    """For the axial friction force, in sliding speed."""
    resultant: float
    """For the resultant slip speed ``hypot(omega_rel d / 2, v_slide)`` (``law = "resultant"``)."""


def nominal_speed(scene: Scene) -> float:
    """The input speed [rad/s] (> 0) the bands are sized for: a constant drive's speed, a torque drive's
    initial speed, an angle history's ``int w^2 dt / int |w| dt`` over the span.
    """
    drive = scene.drive
    if not isinstance(drive, AngleDrive):
        return drive.max_speed()
    speed = drive.spline().derivative()
    t_end = drive.time_to_turn(2.0 * math.pi * scene.revolutions)
    t = np.linspace(drive.time[0], t_end, 50 * len(drive.time) + 1)
    w = np.abs(speed(t))
    dt = np.diff(t)
    turned = float(np.sum(0.5 * (w[1:] + w[:-1]) * dt))  # trapezoidal rule
    squared = float(np.sum(0.5 * (w[1:] ** 2 + w[:-1] ** 2) * dt))
    return float(squared / turned) if turned > 0.0 else drive.max_speed()


def characteristic_speeds(scene: Scene) -> dict[str, PairSpeeds]:
    """Raw RMS relative surface and sliding speed [m/s] of every pair over one input revolution at
    :func:`nominal_speed` (no floor); LoopClosureError where mounting errors keep the loop open.
    """
    motion = joint_motion(scene.joint, profile_angles(), 1.0, 0.0)
    return speeds_from_profile(scene, motion.omega_rel, motion.slide_rel)


def profile_angles() -> np.ndarray:
    """The input angles [rad] of the speed profile: :data:`PROFILE_SAMPLES` over one turn."""
    return np.linspace(0.0, 2.0 * math.pi, PROFILE_SAMPLES, endpoint=False)


def speeds_from_profile(scene: Scene, omega_rel: dict[str, np.ndarray],
                        slide_rel: dict[str, np.ndarray]) -> dict[str, PairSpeeds]:
    """Per pair :class:`PairSpeeds` [m/s] (:func:`characteristic_speeds`) from the pairs' relative
    ``omega_rel`` [rad/s] and ``slide_rel`` [m/s] at the :func:`profile_angles` for an input at 1 rad/s.
    """
    w = nominal_speed(scene)

    def rms(v: np.ndarray) -> float:
        return float(w * np.sqrt(np.mean(np.square(v))))

    return {p: PairSpeeds(rms(0.5 * getattr(scene.joint.pairs, p).journal_diameter * omega_rel[p]),
                          rms(slide_rel[p]))
            for p in PAIR_NAMES}


def needs_speeds(scene: Scene) -> bool:
    """Whether the scene's bands are relative to its characteristic speeds (else they are given)."""
    return scene.friction.sign_band is None and scene.friction.relative_band != 0.0


def bands_from_speeds(scene: Scene, speeds: dict[str, PairSpeeds] | None) -> dict[str, PairBands]:
    """Per pair :class:`PairBands` [m/s] (:func:`sign_bands`) of ``scene`` from characteristic ``speeds``
    a caller computed (None where :func:`needs_speeds` is False).
    """
    return dict(zip(PAIR_NAMES, _from_speeds(scene, speeds), strict=True))


def _from_speeds(scene: Scene, speeds: dict[str, PairSpeeds] | None) -> tuple[PairBands, ...]:
    settings = scene.friction
    if settings.sign_band is not None:
        return tuple(PairBands(settings.sign_band, settings.sign_band, settings.sign_band)
                     for _ in PAIR_NAMES)
    relative = settings.relative_band
    if relative == 0.0:
        return tuple(PairBands(0.0, 0.0, 0.0) for _ in PAIR_NAMES)
    floor = SPEED_FLOOR * max(max(s) for s in speeds.values())
    return tuple(PairBands(relative * max(speeds[p].rotation, floor),
                           relative * max(speeds[p].sliding, floor),
                           relative * max(math.hypot(*speeds[p]), floor)) for p in PAIR_NAMES)


def sign_bands(scene: Scene) -> dict[str, PairBands]:
    """Per pair :class:`PairBands`: the width [m/s] of every sign ramp, as every engine applies them
    (module doc); LoopClosureError (relative bands) where mounting errors keep the loop open.
    """
    return dict(zip(PAIR_NAMES, _bands(scene), strict=True))


@functools.lru_cache(maxsize=64)
def _bands(scene: Scene) -> tuple[PairBands, ...]:
    # cached per scene (frozen, hashable): engines ask for the bands at every evaluation
    return _from_speeds(scene, characteristic_speeds(scene) if needs_speeds(scene) else None)
