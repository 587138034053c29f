"""The friction values of a scene (its slots): their wrenches, the law of eqs. (3), (5), their speeds.

A pair with friction gets a torque about its axis, a cylindrical one also an axial force: each is a
*slot*, linear in the pair's normal force and moment magnitudes, with a factor in [-1, 1] (the
regularised sign of the slot's speed, or its component of the pair's unit slip vector under the
resultant-slip law).
"""

from __future__ import annotations

import numpy as np

from reference.engine.law_values import friction_law_values, reduced_law_values
from reference.engine.newton_euler import unknowns, wrench_columns
from reference.physics.bands import sign_bands
from reference.physics.friction import friction_magnitudes, regularised_sign
from reference.physics.joint_motion import JointMotion
from reference.scene.joint import PAIR_KIND
from reference.scene.scene import Scene

__all__ = ["FrictionLaw", "friction_matrix", "friction_slots", "ramp_bands", "ramp_speeds", "slip_speeds",
           "slot_bands", "slot_signs", "slot_speeds"]


def friction_slots(scene: Scene) -> list[tuple[str, str]]:
    """The friction values of ``scene``: ``(pair, "torque" | "force")`` in solution order (none for a
    frictionless pair).
    """
    slots = []
    for pair, data in scene.joint.pairs.items():
        if data.friction_coefficient > 0.0:
            slots.append((pair, "torque"))
            if PAIR_KIND[pair] == "cylindrical":
                slots.append((pair, "force"))
    return slots


def friction_matrix(motion: JointMotion, slots: list[tuple[str, str]]) -> np.ndarray:
    """Body wrenches (..., 18, K) of unit friction values of ``slots`` on the pair frames of
    ``motion``, rows as :func:`reference.engine.newton_euler.reaction_system`'s: a torque on body b about
    the pair axis, a force along it at the pair origin, the opposite on body a.
    """
    return wrench_columns(motion, [(pair, "mz" if kind == "torque" else "fz") for pair, kind in slots])


class FrictionLaw:
    """Eqs. (3) and (5) of ``scene`` as a function of the reaction vector, with its Jacobian, per slot of
    ``slots``; coefficients from :func:`reference.physics.friction.friction_magnitudes`.
    """

    def __init__(self, scene: Scene, slots: list[tuple[str, str]]) -> None:
        position = {key: j for j, key in enumerate(unknowns()[:-1])}
        self.index = np.array([[position[(pair, c)] for c in ("fx", "fy", "mx", "my")]
                               for pair, _ in slots], dtype=int).reshape(len(slots), 4)
        coefficients = []
        pairs = dict(scene.joint.friction_pairs())
        for pair, kind in slots:
            which = 0 if kind == "torque" else 1  # eq. (3) torque or eq. (5) axial force
            data = pairs[pair]
            coefficients.append((float(friction_magnitudes(data, 1.0, 0.0)[which]),
                                 float(friction_magnitudes(data, 0.0, 1.0)[which])))
        self.k_force, self.k_moment = np.array(coefficients, float).reshape(len(slots), 2).T

    def __call__(self, x: np.ndarray, signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(values, jacobian)``: friction values ``G(x)`` (n, K) [N m or N] on body b and ``dG/dx``
        (n, K, 18) at the reactions ``x`` (n, 18) with the slots' factors ``signs`` (n, K)
        (:func:`slot_signs`); the zero subgradient where a norm is exactly zero.
        """
        return friction_law_values(x, self.index, signs, self.k_force, self.k_moment)

    def reduced(self, c: np.ndarray, signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(values, slopes)``: :func:`reduced_law_values` on each slot's fx, fy [N], mx, my [N m]
        ``c`` (n, K, 4) with ``signs`` (n, K).
        """
        return reduced_law_values(c, signs, self.k_force, self.k_moment)


def slot_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """Speeds (..., K) [m/s] whose sign the law takes: surface speed ``omega_rel d / 2`` or sliding
    speed per slot, from the pairs' ``omega_rel`` [rad/s] and ``slide_rel`` [m/s].
    """
    out = []
    for pair, kind in slots:
        if kind == "torque":
            out.append(0.5 * getattr(scene.joint.pairs, pair).journal_diameter * omega_rel[pair])
        else:
            out.append(slide_rel[pair])
    return np.stack(out, -1)


def slot_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Width (K,) [m/s] of each slot's sign ramp from ``bands`` (None: the scene's
    :func:`reference.physics.bands.sign_bands`); under the resultant-slip law a pair's slots share its
    slip speed's.
    """
    bands = sign_bands(scene) if bands is None else bands
    if scene.friction.law == "resultant":
        return np.array([bands[pair].resultant for pair, _ in slots], dtype=float)
    return np.array([bands[pair].rotation if kind == "torque" else bands[pair].sliding
                     for pair, kind in slots], dtype=float)


def slip_speeds(slots: list[tuple[str, str]], speeds: np.ndarray) -> np.ndarray:
    """Per slot, its pair's resultant slip speed [m/s]: the hypotenuse of the pair's slot ``speeds``."""
    out = np.empty_like(speeds)
    for pair in dict.fromkeys(pair for pair, _ in slots):
        mine = [j for j, (p, _) in enumerate(slots) if p == pair]
        out[..., mine] = np.sqrt(np.sum(np.square(speeds[..., mine]), -1))[..., None]
    return out


def slot_signs(scene: Scene, slots: list[tuple[str, str]], speeds: np.ndarray,
               bands: np.ndarray) -> np.ndarray:
    """Factors (..., K) in [-1, 1] of each slot's Coulomb magnitude from ``speeds`` and ``bands`` [m/s]:
    the regularised sign (the paper's law) or the slot's component of ``v / max(|v|, band)``
    (resultant slip).
    """
    if scene.friction.law != "resultant":
        return regularised_sign(speeds, bands)
    size = np.maximum(slip_speeds(slots, speeds), bands)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(size > 0.0, speeds / size, 0.0)


def ramp_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """Speeds (..., K') [m/s] whose crossings of ``+-`` :func:`ramp_bands` are the kinks of the
    factors: the slot speeds, plus the pairs' slip speeds under the resultant-slip law (K' = 2 K).
    """
    speeds = slot_speeds(scene, slots, omega_rel, slide_rel)
    if scene.friction.law != "resultant":
        return speeds
    return np.concatenate([speeds, slip_speeds(slots, speeds)], -1)


def ramp_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Ramp widths (K',) [m/s] of :func:`ramp_speeds`; arguments as for :func:`slot_bands`."""
    bands = slot_bands(scene, slots, bands)
    return np.concatenate([bands, bands]) if scene.friction.law == "resultant" else bands
