"""The friction law of the paper, eqs. (1)-(5), in numpy, vectorised over time samples.

Written independently of the Exudyn engine (which computes the same law inside its step loop)
so that the loads Exudyn applied can be checked against it sample by sample.

For a pair with friction coefficient ``f``, journal diameter ``d`` and moment lever ``L``, whose
reaction has the components ``(F_x, F_y)`` normal to the pair axis and bending moment
``(M_x, M_y)``:

- eqs. (1), (2), (4): the bending moment is carried as a couple of normal forces ``|M| / L``, each
  producing ``f (|M| / L) (d / 2)`` of friction torque at the two ends, in all
  ``tau_M = f d |M| / L`` with ``|M| = sqrt(M_x^2 + M_y^2)``;
- eq. (3): friction torque on body ``b`` about the axis,
  ``M_z = -s(omega_rel) (tau_M + f d / 2 |F|)``, ``|F| = sqrt(F_x^2 + F_y^2)``;
- eq. (5), cylindrical pairs only: friction force on body ``b`` along the axis,
  ``F_z = -s(v_slide) f (|F| + 2 |M| / L)``;
- body ``a`` receives the opposite torque and force.

``s`` is the sign of the relative motion of ``b`` with respect to ``a``, regularised by a linear
ramp of width ``band`` in *surface speed* [m/s]: ``s(v) = clip(v / band, -1, 1)``; for the
rotation the surface speed is ``omega_rel d / 2``. With ``band = 0`` it is the exact ``sign``
(``sign(0) = 0``). Outside the band the law is exactly the paper's. Each pair has its own band
for the rotation and for the sliding (:func:`reference.physics.bands.sign_bands`: by default relative to
the pair's characteristic speed, so the same at every input speed in relative terms).

Resultant-slip law (``FrictionSettings.law = "resultant"``): eqs. (3), (5) as written apply the
full Coulomb load in each direction of a pair that both rotates and slides. Both magnitudes come
from one normal load ``N = |F| + 2 |M| / L`` (the torque is ``(d / 2) f N``, the force ``f N``), so
physically one Coulomb force ``f N`` opposes the contact's resultant slip velocity
``v = (v_c, v_a) = (omega_rel d / 2, v_slide)``: ``M_z = -(d / 2) f N u_c``, ``F_z = -f N u_a`` with
``u = v / max(|v|, band)`` (linear below the band, the unit slip direction above it; ``band = 0``:
``v / |v|``, 0 at rest). A revolute pair (``v_a = 0``) or a pair that does not slide gets the
paper's law exactly outside the band.

The power dissipated in a pair is ``-(M_z omega_rel + F_z v_slide) >= 0``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from reference.physics.bands import sign_bands
from reference.scene.joint import PAIR_KIND, Pair
from reference.scene.scene import Scene


def regularised_sign(speed: Any, band: Any) -> np.ndarray:
    """``clip(speed / band, -1, 1)``; the exact sign where ``band`` is 0.

    Parameters
    ----------
    speed : array_like
        Relative surface or sliding speed [m/s], any shape.
    band : array_like
        Ramp width [m/s], a scalar or broadcasting with ``speed`` (one band per friction value
        along the last axis); 0 where the sign is exact.

    Returns
    -------
    ndarray
        The regularised sign [-], in [-1, 1], the broadcast shape.
    """
    speed = np.asarray(speed, dtype=float)
    band = np.asarray(band, dtype=float)
    if np.all(band > 0.0):
        return np.clip(speed / band, -1.0, 1.0)
    if not np.any(band > 0.0):
        return np.sign(speed)
    ramp = np.clip(speed / np.where(band > 0.0, band, 1.0), -1.0, 1.0)
    return np.where(band > 0.0, ramp, np.sign(speed))


def friction_magnitudes(pair: Pair, force_normal: Any, moment_normal: Any) -> tuple[np.ndarray, np.ndarray]:
    """Unsigned friction torque (eqs. (2)-(4)) and axial friction force (eq. (5)).

    Parameters
    ----------
    pair : Pair
        Friction coefficient ``f``, journal diameter ``d`` [m] and moment lever ``L`` [m].
    force_normal, moment_normal : array_like
        Magnitudes of the reaction force [N] and moment [N m] normal to the pair axis
        (broadcasting together).

    Returns
    -------
    torque : ndarray
        ``f d |M| / L + f d |F| / 2`` [N m].
    force : ndarray
        ``f (|F| + 2 |M| / L)`` [N].
    """
    f = pair.friction_coefficient
    d = pair.journal_diameter
    lever = pair.moment_lever
    force_normal = np.asarray(force_normal, dtype=float)
    moment_normal = np.asarray(moment_normal, dtype=float)
    torque = f * d * moment_normal / lever + 0.5 * f * d * force_normal
    force = f * (force_normal + 2.0 * moment_normal / lever)
    return torque, force


def slip_direction(surface_speed: Any, slide_speed: Any, band: Any) -> tuple[np.ndarray, np.ndarray]:
    """Regularised unit slip vector ``v / max(|v|, band)`` of ``v = (surface_speed, slide_speed)``.

    Parameters
    ----------
    surface_speed, slide_speed : array_like
        Circumferential (``omega_rel d / 2``) and axial slip speed [m/s], broadcasting together.
    band : array_like
        Ramp width [m/s], broadcasting with them (0: ``v / |v|``, and 0 where ``v = 0``).

    Returns
    -------
    circumferential, axial : ndarray
        The components [-], each in [-1, 1], their hypotenuse at most 1.
    """
    surface = np.asarray(surface_speed, dtype=float)
    slide = np.asarray(slide_speed, dtype=float)
    size = np.maximum(np.hypot(surface, slide), np.asarray(band, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        return (np.where(size > 0.0, surface / size, 0.0), np.where(size > 0.0, slide / size, 0.0))


def pair_friction(pair: Pair, kind: str, fx: Any, fy: Any, mx: Any, my: Any, omega_rel: Any,
                  slide_rel: Any, sign_band: float, slide_band: float | None = None,
                  resultant_band: float | None = None,
                  law: str = "paper") -> tuple[np.ndarray, np.ndarray]:
    """Friction torque about and force along the pair axis, acting on body ``b`` of the pair.

    A revolute pair gets no axial force (its sliding is constrained) and does not slide. A pair
    with zero coefficient gets zeros.

    Parameters
    ----------
    pair : Pair
        Friction coefficient, journal diameter and moment lever.
    kind : {"revolute", "cylindrical"}
        The pair's kind.
    fx, fy : array_like
        Reaction force components normal to the axis, in any frame whose z is the pair axis [N].
    mx, my : array_like
        Bending moment components in that frame [N m].
    omega_rel, slide_rel : array_like
        Angular [rad/s] and sliding [m/s] speed of ``b`` relative to ``a`` (all six broadcast).
    sign_band : float
        Width of the rotation's sign ramp, in surface speed [m/s].
    slide_band : float, optional
        Width of the sliding's sign ramp [m/s]; None: ``sign_band``.
    resultant_band : float, optional
        Width of the resultant slip's ramp [m/s]; None: ``sign_band``.
    law : {"paper", "resultant"}
        Eqs. (3), (5), one sign per direction; or one Coulomb force against the resultant slip
        (module doc).

    Returns
    -------
    torque, force : ndarray
        Friction torque about [N m] and force along [N] the pair axis on body ``b``.
    """
    if kind not in ("revolute", "cylindrical"):
        raise ValueError(f"unknown pair kind {kind!r}")
    if law not in ("paper", "resultant"):
        raise ValueError(f"`law` must be 'paper' or 'resultant', got {law!r}")
    force_normal = np.hypot(fx, fy)
    moment_normal = np.hypot(mx, my)
    torque_mag, force_mag = friction_magnitudes(pair, force_normal, moment_normal)
    surface = 0.5 * pair.journal_diameter * np.asarray(omega_rel, float)
    slide = np.zeros_like(surface) if kind == "revolute" else np.asarray(slide_rel, float)
    if law == "resultant":
        u_c, u_a = slip_direction(surface, slide, sign_band if resultant_band is None else resultant_band)
    else:
        u_c = regularised_sign(surface, sign_band)
        u_a = regularised_sign(slide, sign_band if slide_band is None else slide_band)
    torque = -u_c * torque_mag
    force = np.zeros_like(torque) if kind == "revolute" else -u_a * force_mag
    return torque, force


def friction_from_columns(scene: Scene,
                          columns: Mapping[str, Any]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Friction torque and force of every pair from result-schema columns.

    Parameters
    ----------
    scene : Scene
        Its pairs, sign bands (:func:`reference.physics.bands.sign_bands`) and friction law
        (``scene.friction.law``).
    columns : mapping
        ``<pair>_fx``, ``_fy`` [N], ``_mx``, ``_my`` [N m], ``_omega_rel`` [rad/s] and
        ``_slide_rel`` [m/s] of every pair with friction, arrays of one shape.

    Returns
    -------
    dict of str to (ndarray, ndarray)
        Per pair with friction: torque about [N m] and force along [N] its axis on body ``b``.
    """
    out = {}
    bands = sign_bands(scene)
    for name, pair in scene.joint.friction_pairs():
        c = {s: np.asarray(columns[f"{name}_{s}"], dtype=float)
             for s in ("fx", "fy", "mx", "my", "omega_rel", "slide_rel")}
        band = bands[name]
        out[name] = pair_friction(pair, PAIR_KIND[name], c["fx"], c["fy"], c["mx"], c["my"],
                                  c["omega_rel"], c["slide_rel"], sign_band=band.rotation,
                                  slide_band=band.sliding, resultant_band=band.resultant,
                                  law=scene.friction.law)
    return out


def pair_power_loss(torque: Any, force: Any, omega_rel: Any, slide_rel: Any) -> np.ndarray:
    """Power dissipated by friction in a pair: ``-(M_z omega_rel + F_z v_slide)``.

    Parameters
    ----------
    torque, force : array_like
        Friction torque about [N m] and force along [N] the pair axis on body ``b``.
    omega_rel, slide_rel : array_like
        Angular [rad/s] and sliding [m/s] speed of ``b`` relative to ``a`` (all four broadcast).

    Returns
    -------
    ndarray
        The dissipated power [W], >= 0 when friction opposes the motion.
    """
    return -(np.asarray(torque) * np.asarray(omega_rel) + np.asarray(force) * np.asarray(slide_rel))


__all__ = ["friction_from_columns", "friction_magnitudes", "pair_friction",
           "pair_power_loss", "regularised_sign", "slip_direction"]
