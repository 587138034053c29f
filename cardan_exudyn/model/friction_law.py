"""The friction law of the Exudyn model as pure float functions, no Exudyn; written apart from
:mod:`reference.physics.friction` on purpose (the reference catches mistakes here).

Pair with coefficient ``f``, journal diameter ``d``, moment lever ``L``, reaction magnitudes
``|F|`` (normal to the axis) and ``|M|`` (bending), eqs. (1)-(5):

    T = f d |M| / L + f (d / 2) |F|,      A = f (|F| + 2 |M| / L)  (cylindrical pairs).

Paper law: body b receives ``-s(omega_rel d / 2) T`` about the axis and ``-s(v_slide) A`` along
it (body a the opposite), ``s`` the sign regularised by a linear ramp of width ``band``
(``slide_band``) [m/s]. Resultant law: ``-(d / 2) A v_c / m`` and ``-A v_a / m``,
``(v_c, v_a) = (omega_rel d / 2, v_slide)``, ``m = max(|(v_c, v_a)|, resultant_band)``.

Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation": eqs. (1)-(5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

__all__ = ["PairLaw", "FrictionLoads", "ramp_sign", "pair_loads", "magnitude_loads", "bdf2_weights",
           "LawTable"]


@dataclass(frozen=True)
class PairLaw:
    """The constants of one pair's law: ``cylindrical`` (axial friction too), coefficient ``f`` [-],
    journal diameter ``d`` [m], moment ``lever`` L [m], ``resultant`` (the resultant-slip law)."""

    cylindrical: bool
    f: float
    d: float
    lever: float
    resultant: bool = False

    @classmethod
    def of(cls, kind: str, pair: Any, law: str = "paper") -> PairLaw:
        """The law of a scene's ``pair`` of ``kind`` ``"revolute"``/``"cylindrical"`` under ``law``
        ``"paper"``/``"resultant"``."""
        if law not in ("paper", "resultant"):
            raise ValueError(f"`law` must be 'paper' or 'resultant', got {law!r}")
        return cls(kind == "cylindrical", pair.friction_coefficient, pair.journal_diameter,
                   float(pair.moment_lever), law == "resultant")


class FrictionLoads(NamedTuple):
    """Friction on body b of a pair: ``torque`` [N m] about and ``force`` [N] along the axis, and
    ``sliding_scale`` [N m], the largest load it would carry sliding (the convergence tests' scale).
    A NamedTuple: a frozen dataclass costs a third of the law."""

    torque: float
    force: float
    sliding_scale: float


def ramp_sign(speed: float, band: float) -> float:
    """Sign of ``speed`` [m/s] regularised by a linear ramp of width ``band`` [m/s] (0: exact), in [-1, 1]."""
    if band <= 0.0:
        return float(speed > 0.0) - float(speed < 0.0)
    return max(-1.0, min(1.0, speed / band))


def pair_loads(law: PairLaw, force_x: float, force_y: float, moment_x: float, moment_y: float,
               omega_rel: float, slide_rel: float, band: float,
               slide_band: float | None = None,
               resultant_band: float | None = None) -> FrictionLoads:
    """Friction of one pair (eqs. (1)-(5)) from reaction components normal to the axis ``force_x, y``
    [N], ``moment_x, y`` [N m], relative ``omega_rel`` [rad/s] and ``slide_rel`` [m/s], and the ramp
    widths [m/s] (``slide_band``, ``resultant_band`` default ``band``)."""
    return FrictionLoads(*magnitude_loads(law, math.hypot(force_x, force_y), math.hypot(moment_x, moment_y),
                                          omega_rel, slide_rel, band, slide_band, resultant_band))


def magnitude_loads(law: PairLaw, force_n: float, moment_n: float, omega_rel: float, slide_rel: float,
                    band: float, slide_band: float | None = None,
                    resultant_band: float | None = None) -> tuple[float, float, float]:
    """:func:`pair_loads` from the magnitudes ``force_n`` [N], ``moment_n`` [N m], as a plain tuple
    ``(torque, force, sliding_scale)`` (the hot path)."""
    radius = 0.5 * law.d
    torque = law.f * law.d * moment_n / law.lever + law.f * radius * force_n
    magnitude = law.f * (force_n + 2.0 * moment_n / law.lever)
    scale = max(torque, radius * magnitude) if law.cylindrical else torque
    surface = radius * omega_rel
    if law.resultant:
        slide = slide_rel if law.cylindrical else 0.0
        width = band if resultant_band is None else resultant_band
        slip = max(math.hypot(surface, slide), width)
        if slip <= 0.0:
            return 0.0, 0.0, scale
        return -torque * surface / slip, (-magnitude * slide / slip if law.cylindrical else 0.0), scale
    axial = 0.0
    if law.cylindrical:
        axial = -ramp_sign(slide_rel, band if slide_band is None else slide_band) * magnitude
    return -ramp_sign(surface, band) * torque, axial, scale


def bdf2_weights(h1: float, h2: float) -> tuple[float, float]:
    """Weights ``(w1, w2)`` of BDF2 on a non-uniform grid: ``dc/dt(t_n) = (w1 d1 - w2 d2) / h1`` with
    ``d1``, ``d2`` the last two differences over steps ``h1``, ``h2`` [s] (exact for quadratics)."""
    w = h1 / h2
    return (1.0 + 2.0 * w) / (1.0 + w), w * w / (1.0 + w)


class LawTable:
    """The ``laws`` of a coupling's pairs evaluated together (the hot path), bit-identical to
    :func:`magnitude_loads` pair by pair. ``bands`` per pair: rotation, sliding, resultant ramp widths
    [m/s]; ``slides`` per pair: whether its axial force acts."""

    def __init__(self, laws: list[PairLaw], bands: list[tuple[float, float, float]],
                 slides: list[bool]) -> None:
        self.laws = list(laws)
        self.bands = [tuple(float(b) for b in band) for band in bands]
        self.slides = list(slides)
        self._rows = [(law, 0.5 * law.d, law.f * law.d, law.lever, law.f * (0.5 * law.d), law.f,
                       law.cylindrical, slide, band, band > 0.0, slide_band, slide_band > 0.0,
                       resultant if law.resultant else None)
                      for law, (band, slide_band, resultant), slide in zip(self.laws, self.bands,
                                                                           self.slides, strict=True)]

    def loads(self, inputs: list, older: list | None = None, a: float = 1.0,
              b: float = 0.0) -> tuple[tuple[float, ...], tuple[int, ...], float, float]:
        """``(friction, regime, sliding, size)`` on the ``inputs`` ``(|F|, |M|, omega_rel, slide_rel)`` per
        pair, or on ``a x - b x_older``: flat ``(M_z, F_z)`` per pair on body b [N m, N], flat per-pair
        ramp sides (-1, 0 inside, +1) of rotation and sliding, the largest ``sliding_scale`` [N m], the
        largest load magnitude. One loop with the law inlined: a call per pair costs more than the law."""
        friction: list[float] = []
        regime: list[int] = []
        sliding = size = 0.0
        for row, x, y in zip(self._rows, inputs, inputs if older is None else older, strict=True):
            law, radius, fd, lever, fr, f, cylindrical, slide, band, ramp, slide_band, slide_ramp, res = row
            force_n, moment_n, omega, slide_rel = x
            if older is not None:
                force_n = a * force_n - b * y[0]
                moment_n = a * moment_n - b * y[1]
                omega = a * omega - b * y[2]
                slide_rel = a * slide_rel - b * y[3]
            surface = radius * omega
            turn = (surface > band) - (surface < -band)
            axial_side = (slide_rel > slide_band) - (slide_rel < -slide_band)
            regime += (turn, axial_side)
            if res is not None:
                torque, axial, scale = magnitude_loads(law, force_n, moment_n, omega, slide_rel,
                                                       band, slide_band, res)
                if not slide:
                    axial = 0.0
            else:
                torque = fd * moment_n / lever + fr * force_n
                axial = 0.0
                if cylindrical:
                    magnitude = f * (force_n + 2.0 * moment_n / lever)
                    scale = radius * magnitude
                    if not scale > torque:
                        scale = torque
                    if slide:
                        side = axial_side if axial_side or not slide_ramp else slide_rel / slide_band
                        axial = -side * magnitude
                else:
                    scale = torque
                torque = -(turn if turn or not ramp else surface / band) * torque
            if scale > sliding:
                sliding = scale
            friction += (torque, axial)
            torque = abs(torque)
            axial = abs(axial)
            if torque > size:
                size = torque
            if axial > size:
                size = axial
        return tuple(friction), tuple(regime), sliding, size
