"""The friction values of a scene (its slots): their wrenches, the law of eqs. (3), (5), their speeds.

A pair with friction gets a torque about its axis; a cylindrical one also an axial force. Each is
a *slot*: its value is linear in the pair's normal force and moment magnitudes, its factor in
[-1, 1] the regularised sign of the slot's speed (the paper's law) or the slot's component of the
pair's regularised unit slip vector (the resultant-slip law).

References
----------
Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": eqs. (3), (5) (friction from the reactions).
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
    """The friction values the scene produces: ``(pair, "torque" | "force")`` in solution order.

    A pair with friction gets a torque about its axis; a cylindrical one also an axial force.
    Frictionless pairs get none, so a frictionless scene has no friction unknowns at all.
    """
    slots = []
    for pair, data in scene.joint.pairs.items():
        if data.friction_coefficient > 0.0:
            slots.append((pair, "torque"))
            if PAIR_KIND[pair] == "cylindrical":
                slots.append((pair, "force"))
    return slots


def friction_matrix(motion: JointMotion, slots: list[tuple[str, str]]) -> np.ndarray:
    """Body wrenches of unit friction values.

    A friction torque acts on body b about the pair axis, an axial force along it at the pair
    origin; body a receives the opposite.

    Parameters
    ----------
    motion : JointMotion
        Pair frames and origins, per sample.
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.

    Returns
    -------
    ndarray, shape (..., 18, K)
        Rows as :func:`reference.engine.newton_euler.reaction_system`'s [N, N m per unit value].
    """
    return wrench_columns(motion, [(pair, "mz" if kind == "torque" else "fz") for pair, kind in slots])


class FrictionLaw:
    """Eqs. (3) and (5) as a function of the reaction vector, with its Jacobian.

    The law is linear in the normal force and moment magnitudes ``|F|``, ``|M|``; its
    coefficients per slot are taken from :func:`reference.physics.friction.friction_magnitudes`.

    Parameters
    ----------
    scene : Scene
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
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
        """Friction values ``G(x)`` and Jacobian ``dG/dx``.

        Parameters
        ----------
        x : ndarray, shape (n, 18)
            Reactions (and the drive unknown, unused), ordered as :func:`unknowns`.
        signs : ndarray, shape (n, K)
            Regularised sign of the relative motion for each slot, or under the resultant-slip
            law the slot's component of the regularised unit slip vector (:func:`slot_signs`;
            fixed by the kinematics).

        Returns
        -------
        values : ndarray, shape (n, K)
            Friction torque [N m] / axial force [N] on body b.
        jacobian : ndarray, shape (n, K, 18)
            Derivatives with respect to ``x``; where a norm is exactly zero, the zero
            subgradient.
        """
        return friction_law_values(x, self.index, signs, self.k_force, self.k_moment)

    def reduced(self, c: np.ndarray, signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`reduced_law_values` on the components the law reads.

        Parameters
        ----------
        c : ndarray, shape (n, K, 4)
            ``x[:, index]``: each slot's fx, fy [N], mx, my [N m].
        signs : ndarray, shape (n, K)
            As for :meth:`__call__`.

        Returns
        -------
        values : ndarray, shape (n, K)
            Friction values [N m or N].
        slopes : ndarray, shape (n, K, 4)
            Their derivatives with respect to ``c``.
        """
        return reduced_law_values(c, signs, self.k_force, self.k_moment)


def slot_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """The speeds whose sign the friction law takes: relative surface speed (rotation,
    ``omega_rel d / 2``) or sliding speed of each slot.

    Parameters
    ----------
    scene : Scene
        Journal diameters [m].
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
    omega_rel, slide_rel : dict of str to ndarray, shape (...)
        Per pair the relative angular speed [rad/s] and sliding speed [m/s].

    Returns
    -------
    ndarray, shape (..., K)
        Speeds [m/s].
    """
    out = []
    for pair, kind in slots:
        if kind == "torque":
            out.append(0.5 * getattr(scene.joint.pairs, pair).journal_diameter * omega_rel[pair])
        else:
            out.append(slide_rel[pair])
    return np.stack(out, -1)


def slot_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Width of each slot's sign ramp.

    Under the resultant-slip law (``scene.friction.law``) both slots of a pair share the ramp of
    its resultant slip speed.

    Parameters
    ----------
    scene : Scene
        Its friction law (and bands, when ``bands`` is None).
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
    bands : dict or None
        Per pair :class:`reference.physics.bands.PairBands`; None:
        :func:`reference.physics.bands.sign_bands` of the scene.

    Returns
    -------
    ndarray, shape (K,)
        Widths [m/s].
    """
    bands = sign_bands(scene) if bands is None else bands
    if scene.friction.law == "resultant":
        return np.array([bands[pair].resultant for pair, _ in slots], dtype=float)
    return np.array([bands[pair].rotation if kind == "torque" else bands[pair].sliding
                     for pair, kind in slots], dtype=float)


def slip_speeds(slots: list[tuple[str, str]], speeds: np.ndarray) -> np.ndarray:
    """Per slot, the resultant slip speed of its pair: the hypotenuse of the pair's slot speeds.

    Parameters
    ----------
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
    speeds : ndarray, shape (..., K)
        :func:`slot_speeds` [m/s].

    Returns
    -------
    ndarray, shape (..., K)
        Slip speeds [m/s].
    """
    out = np.empty_like(speeds)
    for pair in dict.fromkeys(pair for pair, _ in slots):
        mine = [j for j, (p, _) in enumerate(slots) if p == pair]
        out[..., mine] = np.sqrt(np.sum(np.square(speeds[..., mine]), -1))[..., None]
    return out


def slot_signs(scene: Scene, slots: list[tuple[str, str]], speeds: np.ndarray,
               bands: np.ndarray) -> np.ndarray:
    """The factor of each slot's Coulomb magnitude.

    The paper's law: the regularised sign of each slot's speed
    (:func:`reference.physics.friction.regularised_sign`). The resultant-slip law: the slot's
    component of its pair's regularised unit slip vector ``v / max(|v|, band)``.

    Parameters
    ----------
    scene : Scene
        Its friction law.
    slots : list of (pair, "torque" | "force")
        From :func:`friction_slots`.
    speeds : ndarray, shape (..., K)
        :func:`slot_speeds` [m/s].
    bands : ndarray, shape (K,) or (..., K)
        :func:`slot_bands` [m/s].

    Returns
    -------
    ndarray, shape (..., K)
        Factors in [-1, 1].
    """
    if scene.friction.law != "resultant":
        return regularised_sign(speeds, bands)
    size = np.maximum(slip_speeds(slots, speeds), bands)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(size > 0.0, speeds / size, 0.0)


def ramp_speeds(scene: Scene, slots: list[tuple[str, str]], omega_rel: dict[str, np.ndarray],
                slide_rel: dict[str, np.ndarray]) -> np.ndarray:
    """Speeds whose crossings of ``+-`` :func:`ramp_bands` are the kinks of the friction factors.

    The slot speeds, and under the resultant-slip law also the pairs' slip speeds (the slot
    speeds' zero crossings stay: with a zero band the factor jumps there when the pair does not
    slide).

    Parameters
    ----------
    scene, slots, omega_rel, slide_rel
        As for :func:`slot_speeds`.

    Returns
    -------
    ndarray, shape (..., K')
        Speeds [m/s]; K' = K, or 2 K under the resultant-slip law.
    """
    speeds = slot_speeds(scene, slots, omega_rel, slide_rel)
    if scene.friction.law != "resultant":
        return speeds
    return np.concatenate([speeds, slip_speeds(slots, speeds)], -1)


def ramp_bands(scene: Scene, slots: list[tuple[str, str]], bands: dict | None = None) -> np.ndarray:
    """Ramp widths of :func:`ramp_speeds`.

    Parameters
    ----------
    scene, slots, bands
        As for :func:`slot_bands`.

    Returns
    -------
    ndarray, shape (K',)
        Widths [m/s].
    """
    bands = slot_bands(scene, slots, bands)
    return np.concatenate([bands, bands]) if scene.friction.law == "resultant" else bands
