"""The width of each pair's friction sign ramp: relative to the pair's own speed, or absolute.

The friction law (eqs. (3), (5); :mod:`reference.physics.friction`) takes ``sign()`` of a pair's relative
surface speed (``omega_rel d / 2``) or sliding speed. Every engine replaces it by a linear ramp
``clip(v / band, -1, 1)``: with the exact sign, the direction of friction in a pair that does not
move (the spider pairs at 0 deg, the axial direction of the ideal joint) is decided by
rounding-level speeds. Inside the ramp the friction is smaller than Coulomb's, so the band must
be small against the speeds the pair actually has. A fixed band in m/s is not: the speeds scale
with the input speed (measured: docs/paper.md#friction-at-every-speed).

So by default each band is relative (``FrictionSettings.sign_band_relative``, default 1e-3,
:data:`reference.scene.settings.DEFAULT_SIGN_BAND_RELATIVE`): ``band = sign_band_relative * v_char``,
where ``v_char`` is the pair's *characteristic speed*, the RMS over one input revolution of its
surface (or sliding) speed when the input turns uniformly at the scene's :func:`nominal_speed`.
The kinematics are linear in the input speed, so these are the speeds at 1 rad/s (closed form
for the ideal joint, the dual-number loop with mounting errors;
:func:`reference.physics.joint_motion.joint_motion`) times the nominal speed. A pair that hardly moves
(``v_char`` below :data:`SPEED_FLOOR` times the scene's fastest ``v_char``: the spider pairs at
0 deg, the sliding of the ideal joint) gets the band of one moving at that floor, so its band
stays far above rounding (relative speeds of pairs at rest in the Exudyn model are ~1e-13 of the
frame journals' surface speed) and scales with the scene. Then the share of each pair's motion
spent inside its ramp does not depend on the speed, and the mean efficiency converges to the
exact-sign value as ``sign_band_relative`` shrinks, at every speed (``docs/paper.md``, "Friction
at every speed").

``FrictionSettings.sign_band`` [m/s], when given, is one absolute band for every pair (0: the
exact sign).

Under the resultant-slip law (``FrictionSettings.law = "resultant"``) one Coulomb force opposes
the pair's slip velocity ``v = (omega_rel d / 2, v_slide)`` and is regularised as a vector,
``v / max(|v|, band)``: its band (``PairBands.resultant``) is ``sign_band_relative *
max(hypot(v_char rotation, v_char sliding), floor)``, or the absolute ``sign_band``. For a pair
that does not slide it is the rotation's band, so the two laws then coincide even inside it.

Every engine takes its bands from :func:`sign_bands`, so they regularise identically.
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
    """The input speed the bands are sized for [rad/s], > 0.

    A constant-speed drive's speed; a torque drive's initial speed; for an angle history, the
    input speed averaged over the angle turned in the simulated span, ``int w^2 dt / int |w| dt``
    (time spent at rest does not lower it; the constant speed for a uniform history).
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
    """RMS relative surface and sliding speed of every pair over one input revolution [m/s].

    The input turns uniformly at :func:`nominal_speed`; the raw RMS, without the floor
    :func:`sign_bands` applies.

    Raises
    ------
    reference.physics.loop_closure.LoopClosureError
        The joint's mounting errors keep the loop from closing at some angle.
    """
    motion = joint_motion(scene.joint, profile_angles(), 1.0, 0.0)
    return speeds_from_profile(scene, motion.omega_rel, motion.slide_rel)


def profile_angles() -> np.ndarray:
    """The input angles [rad] of the speed profile: :data:`PROFILE_SAMPLES` over one turn."""
    return np.linspace(0.0, 2.0 * math.pi, PROFILE_SAMPLES, endpoint=False)


def speeds_from_profile(scene: Scene, omega_rel: dict[str, np.ndarray],
                        slide_rel: dict[str, np.ndarray]) -> dict[str, PairSpeeds]:
    """:func:`characteristic_speeds` from the pairs' relative speeds over the speed profile.

    Parameters
    ----------
    scene : Scene
        Journal diameters and the nominal speed (:func:`nominal_speed`).
    omega_rel : dict of str to ndarray, shape (PROFILE_SAMPLES,)
        Per pair the relative angular speed [rad/s] at the :func:`profile_angles` for an input
        turning at 1 rad/s.
    slide_rel : dict of str to ndarray, shape (PROFILE_SAMPLES,)
        Per pair the relative sliding speed [m/s] there.

    Returns
    -------
    dict of str to PairSpeeds
        Per pair [m/s].
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
    """:func:`sign_bands` from characteristic speeds a caller computed itself.

    Parameters
    ----------
    scene : Scene
        Its friction settings.
    speeds : dict of str to PairSpeeds or None
        :func:`characteristic_speeds` [m/s]; None where :func:`needs_speeds` is False.

    Returns
    -------
    dict of str to PairBands
        Per pair [m/s].
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
    """Width of every pair's sign ramps [m/s], as every engine applies them.

    ``FrictionSettings.sign_band`` given: that band for every ramp. Otherwise
    ``sign_band_relative * max(v_char, SPEED_FLOOR * max(v_char over the scene))`` per ramp, with
    ``v_char`` from :func:`characteristic_speeds` (for the resultant slip, ``v_char`` is the
    hypotenuse of the pair's rotation and sliding ``v_char``).

    Raises
    ------
    reference.physics.loop_closure.LoopClosureError
        (relative bands) The joint's mounting errors keep the loop from closing at some angle.
    """
    return dict(zip(PAIR_NAMES, _bands(scene), strict=True))


@functools.lru_cache(maxsize=64)
def _bands(scene: Scene) -> tuple[PairBands, ...]:
    # cached per scene (frozen, hashable): engines ask for the bands at every evaluation
    return _from_speeds(scene, characteristic_speeds(scene) if needs_speeds(scene) else None)
