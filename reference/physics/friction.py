"""The friction law of the paper, eqs. (1)-(5), vectorised over time samples.

For a pair with coefficient ``f``, journal diameter ``d``, moment lever ``L`` and reaction
``(F_x, F_y)``, ``(M_x, M_y)`` normal to its axis, ``|F|``, ``|M|`` their norms:

- eqs. (1), (2), (4): bending moment as a couple of normal forces, ``tau_M = f d |M| / L``;
- eq. (3): torque on body ``b`` about the axis, ``M_z = -s(omega_rel) (tau_M + f d / 2 |F|)``;
- eq. (5), cylindrical pairs: force on ``b`` along the axis, ``F_z = -s(v_slide) f (|F| + 2 |M| / L)``;
- body ``a`` receives the opposite.

``s(v) = clip(v / band, -1, 1)`` in surface speed [m/s] (``omega_rel d / 2`` for the rotation),
the exact sign for ``band = 0``; bands: :func:`reference.physics.bands.sign_bands`.

Resultant-slip law (``FrictionSettings.law = "resultant"``): one Coulomb force ``f N``,
``N = |F| + 2 |M| / L``, opposes the slip ``v = (omega_rel d / 2, v_slide)``:
``M_z = -(d / 2) f N u_c``, ``F_z = -f N u_a``, ``u = v / max(|v|, band)``.

Dissipated power: ``-(M_z omega_rel + F_z v_slide) >= 0``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from reference.physics.bands import sign_bands
from reference.scene.joint import PAIR_KIND, Pair
from reference.scene.scene import Scene


def regularised_sign(speed: Any, band: Any) -> np.ndarray:
    """``clip(speed / band, -1, 1)`` [-] of ``speed`` [m/s]; the exact sign where ``band`` [m/s] is 0
    (``band`` a scalar or broadcasting with ``speed``).
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
    """Unsigned friction torque ``f d |M| / L + f d |F| / 2`` [N m] (eqs. (2)-(4)) and axial force
    ``f (|F| + 2 |M| / L)`` [N] (eq. (5)) of ``pair`` at the normal ``force_normal`` [N] and
    ``moment_normal`` [N m].
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
    """``(circumferential, axial)``: the regularised unit slip vector ``v / max(|v|, band)`` of
    ``v = (surface_speed, slide_speed)`` [m/s] (``band = 0``: ``v / |v|``, 0 where ``v = 0``).
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
    """Friction torque about [N m] and force along [N] the pair axis on body ``b`` (zeros for zero
    coefficient; a revolute pair gets no force).

    Parameters
    ----------
    pair : Pair
        Friction coefficient, journal diameter and moment lever.
    kind : {"revolute", "cylindrical"}
    fx, fy, mx, my : array_like
        Reaction force [N] and bending moment [N m] normal to the axis, in a frame whose z is the axis.
    omega_rel, slide_rel : array_like
        Angular [rad/s] and sliding [m/s] speed of ``b`` relative to ``a`` (all six broadcast).
    sign_band, slide_band, resultant_band : float
        Ramp widths [m/s] of the rotation, the sliding and the resultant slip (None: ``sign_band``).
    law : {"paper", "resultant"}
        One sign per direction (eqs. (3), (5)), or one Coulomb force against the resultant slip.
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
    """Per pair with friction, its torque [N m] and force [N] on body ``b`` from the result-schema
    ``columns`` (``<pair>_fx``, ``_fy``, ``_mx``, ``_my``, ``_omega_rel``, ``_slide_rel``), with
    ``scene``'s sign bands and friction law.
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
    """Power [W] dissipated in a pair, ``-(M_z omega_rel + F_z v_slide)``, from its friction
    ``torque`` [N m], ``force`` [N] on body ``b`` and relative speeds [rad/s], [m/s].
    """
    return -(np.asarray(torque) * np.asarray(omega_rel) + np.asarray(force) * np.asarray(slide_rel))


__all__ = ["friction_from_columns", "friction_magnitudes", "pair_friction",
           "pair_power_loss", "regularised_sign", "slip_direction"]
