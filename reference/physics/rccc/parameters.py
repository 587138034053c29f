"""Denavit-Hartenberg parameters of the RCCC loop: the ideal joint's, plus mounting errors."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from reference.physics.dual import Dual
from reference.scene.joint import Joint

__all__ = ["LINK_NAMES", "DHParameters", "finite_number", "four_numbers"]

LINK_NAMES = ("input", "spider", "output", "ground")
"""Links 1..4 of the loop: link k carries joints k and k + 1."""


def finite_number(name: str, value) -> float:
    """``value`` as a float; ValueError naming ``name`` unless a finite real number (a bool is none)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"`{name}` must be a number, got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"`{name}` must be finite, got {value!r}")
    return float(value)


def four_numbers(name: str, values) -> tuple[float, float, float, float]:
    """``values`` as four finite floats, one per link; ValueError naming ``name`` otherwise."""
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)) \
            or len(values) != 4:
        raise ValueError(f"`{name}` must be a sequence of 4 numbers (one per link), got {values!r}")
    return tuple(finite_number(f"{name}[{k}]", v) for k, v in enumerate(values))


@dataclass(frozen=True)
class DHParameters:
    """Denavit-Hartenberg parameters of the single RCCC loop.

    Attributes
    ----------
    alpha : tuple of 4 float
        Twists of the input, spider, output and frame links [rad] (joint k's axis to joint k + 1's about
        link k's common normal): the first three in (0, 180) deg, the frame's in (-90, 90) deg.
    a : tuple of 4 float
        Signed lengths of the same links' common normals [m].
    s1 : float
        Axial offset of the revolute joint 1 [m], from the frame link's normal to the input's.
    """

    alpha: tuple[float, float, float, float]
    a: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    s1: float = 0.0

    def __post_init__(self) -> None:
        alpha = four_numbers("alpha", self.alpha)
        for k in range(3):
            if not 0.0 < alpha[k] < math.pi:
                raise ValueError(f"`alpha[{k}]` (twist of the {LINK_NAMES[k]}) must be in (0, 180) "
                                 f"deg, got {math.degrees(alpha[k])!r} deg")
        if not abs(alpha[3]) < 0.5 * math.pi:
            raise ValueError(f"`alpha[3]` (twist of the ground, minus the shaft angle) must be in "
                             f"(-90, 90) deg, got {math.degrees(alpha[3])!r} deg")
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "a", four_numbers("a", self.a))
        object.__setattr__(self, "s1", finite_number("s1", self.s1))

    @classmethod
    def ideal(cls, shaft_angle: float) -> DHParameters:
        """The ideal Cardan joint at ``shaft_angle`` [rad] in [0, pi/2): twists (90, 90, 90, -shaft_angle)
        deg, no offsets.
        """
        beta = finite_number("shaft_angle", shaft_angle)
        if not 0.0 <= beta < 0.5 * math.pi:
            raise ValueError(f"`shaft_angle` must be in [0, 90) deg, got {math.degrees(beta)!r} deg")
        return cls(alpha=(0.5 * math.pi, 0.5 * math.pi, 0.5 * math.pi, -beta))

    def with_errors(self, a: Sequence[float] = (0.0,) * 4, alpha: Sequence[float] = (0.0,) * 4,
                    s1: float = 0.0) -> DHParameters:
        """These parameters plus link offset errors ``a`` [m], twist errors ``alpha`` [rad] (4 each) and
        ``s1`` [m].
        """
        d_a = four_numbers("a", a)
        d_alpha = four_numbers("alpha", alpha)
        d_s1 = finite_number("s1", s1)
        return DHParameters(alpha=tuple(x + y for x, y in zip(self.alpha, d_alpha, strict=True)),
                            a=tuple(x + y for x, y in zip(self.a, d_a, strict=True)), s1=self.s1 + d_s1)

    @classmethod
    def of_joint(cls, joint: Joint) -> DHParameters:
        """The scene joint's loop: the ideal joint of its shaft angle plus its mounting errors."""
        e = joint.errors
        return cls.ideal(joint.geometry.shaft_angle).with_errors(
            a=(e.a1, e.a2, e.a3, e.a4), alpha=(e.alpha1, e.alpha2, e.alpha3, e.alpha4), s1=e.s1)

    def twists(self) -> Dual:
        """Dual link twists ``alpha_k + eps a_k``, shape (4,)."""
        return Dual(np.array(self.alpha), np.array(self.a))
