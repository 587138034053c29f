"""The friction law of the Exudyn model as pure functions: floats in, floats out, no Exudyn.

Written separately from :mod:`reference.physics.friction` on purpose (the reference exists to catch
mistakes here; neither calls the other). Plain ``float`` arithmetic, because the coupling calls
it once per pair after every Newton solve and numpy on scalars costs more than the law itself.

A pair with friction coefficient ``f``, journal diameter ``d`` and moment lever ``L`` carries a
reaction with the magnitudes ``|F|`` (force normal to its axis) and ``|M|`` (bending moment).
The bending moment acts as a couple of normal forces ``|M| / L`` (eq. (1)); each rubs at the
journal radius, so the friction torque magnitude is (eqs. (2)-(4))

    T = f d |M| / L + f (d / 2) |F|

and a cylindrical pair also resists sliding with the axial force magnitude (eq. (5))

    A = f (|F| + 2 |M| / L).

Body ``b`` of the pair receives ``-s(v_rot) T`` about the axis and ``-s(v_slide) A`` along it,
body ``a`` the opposite, where ``s`` is the sign of the relative surface speed of ``b`` with
respect to ``a``, regularised by a linear ramp of width ``band`` [m/s] (the rotation's; the
sliding has its own, ``slide_band``); for the rotation the surface speed is ``omega_rel d / 2``.
The widths are scene data, the same for every engine (:func:`reference.physics.bands.sign_bands`).

That is the paper's law (``FrictionSettings.law = "paper"``). Since ``T = (d / 2) A``, both are
one Coulomb force ``A`` at the journal surface; the resultant-slip law (``"resultant"``) lets that
one force oppose the contact's slip velocity ``(v_c, v_a) = (omega_rel d / 2, v_slide)`` instead of
acting in full in each direction: body ``b`` receives ``-(d / 2) A v_c / m`` about the axis and
``-A v_a / m`` along it, ``m = max(sqrt(v_c^2 + v_a^2), resultant_band)`` (the unit slip direction
outside the band, linear inside). A revolute pair has ``v_a = 0``.

References
----------
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
    """The constants of one pair's law.

    Attributes
    ----------
    cylindrical : bool
        True for a cylindrical pair (axial friction too), False for a revolute.
    f : float
        Friction coefficient [-].
    d : float
        Journal diameter [m].
    lever : float
        Moment lever ``L`` of eqs. (1)-(2) [m].
    resultant : bool
        True: one Coulomb force against the resultant slip (``FrictionSettings.law ==
        "resultant"``); False: the paper's eqs. (3), (5), one sign per direction.
    """

    cylindrical: bool
    f: float
    d: float
    lever: float
    resultant: bool = False

    @classmethod
    def of(cls, kind: str, pair: Any, law: str = "paper") -> PairLaw:
        """The law of a scene's pair.

        Parameters
        ----------
        kind : {"revolute", "cylindrical"}
            The pair's kind.
        pair : reference.scene.joint.Pair
            Its ``moment_lever`` resolved to a number [m].
        law : {"paper", "resultant"}
            ``FrictionSettings.law``.

        Returns
        -------
        PairLaw
        """
        if law not in ("paper", "resultant"):
            raise ValueError(f"`law` must be 'paper' or 'resultant', got {law!r}")
        return cls(kind == "cylindrical", pair.friction_coefficient, pair.journal_diameter,
                   float(pair.moment_lever), law == "resultant")


class FrictionLoads(NamedTuple):
    """Friction on body ``b`` of a pair (a NamedTuple: built once per pair after every Newton
    solve, where a frozen dataclass costs a third of the law).

    Attributes
    ----------
    torque : float
        About the pair axis [N m].
    force : float
        Along the pair axis [N] (0 for a revolute pair).
    sliding_scale : float
        The largest load the pair would carry sliding, axial force counted as the torque it makes
        at the journal radius [N m]: the scale of the coupling's convergence tests.
    """

    torque: float
    force: float
    sliding_scale: float


def ramp_sign(speed: float, band: float) -> float:
    """Sign of a speed, regularised by a linear ramp.

    Parameters
    ----------
    speed : float
        Relative surface or sliding speed [m/s].
    band : float
        Width of the ramp [m/s]; 0: the exact sign.

    Returns
    -------
    float
        In ``[-1, 1]`` [-].
    """
    if band <= 0.0:
        return float(speed > 0.0) - float(speed < 0.0)
    return max(-1.0, min(1.0, speed / band))


def pair_loads(law: PairLaw, force_x: float, force_y: float, moment_x: float, moment_y: float,
               omega_rel: float, slide_rel: float, band: float,
               slide_band: float | None = None,
               resultant_band: float | None = None) -> FrictionLoads:
    """Friction of one pair from its reaction and relative motion (eqs. (1)-(5)).

    Parameters
    ----------
    law : PairLaw
    force_x, force_y : float
        Reaction force components normal to the pair axis, in any frame whose z is the axis [N].
    moment_x, moment_y : float
        Bending moment components in such a frame [N m].
    omega_rel : float
        Angular speed of body ``b`` relative to ``a`` about the axis [rad/s].
    slide_rel : float
        Sliding speed of ``b`` relative to ``a`` along the axis [m/s] (ignored for a revolute).
    band : float
        Width of the rotation's sign ramp, in relative surface speed [m/s] (0: the exact sign).
    slide_band : float or None
        Width of the sliding's sign ramp [m/s]; None: ``band``.
    resultant_band : float or None
        Resultant-slip law: width of the ramp of the slip speed ``hypot(omega_rel d / 2,
        slide_rel)`` [m/s]; None: ``band``.

    Returns
    -------
    FrictionLoads
    """
    return FrictionLoads(*magnitude_loads(law, math.hypot(force_x, force_y), math.hypot(moment_x, moment_y),
                                          omega_rel, slide_rel, band, slide_band, resultant_band))


def magnitude_loads(law: PairLaw, force_n: float, moment_n: float, omega_rel: float, slide_rel: float,
                    band: float, slide_band: float | None = None,
                    resultant_band: float | None = None) -> tuple[float, float, float]:
    """:func:`pair_loads` from the reaction's magnitudes, as a plain tuple (the coupling's hot path).

    Parameters
    ----------
    law : PairLaw
    force_n : float
        Magnitude of the reaction force normal to the axis [N].
    moment_n : float
        Magnitude of the bending moment [N m].
    omega_rel, slide_rel, band, slide_band, resultant_band : float
        As for :func:`pair_loads` [rad/s, m/s, m/s, m/s, m/s].

    Returns
    -------
    torque, force, sliding_scale : float
        The fields of :class:`FrictionLoads` [N m, N, N m]; ``force`` is 0 for a revolute pair.
    """
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
    """Weights of the second-order backward difference on a non-uniform grid.

    With ``d1 = c_n - c_{n-1}`` over the last step ``h1`` and ``d2 = c_{n-1} - c_{n-2}`` over the
    one before, ``h2``, the derivative at ``t_n`` is ``(w1 d1 - w2 d2) / h1`` (exact for
    quadratics).

    Parameters
    ----------
    h1, h2 : float or ndarray
        The last step and the one before [s].

    Returns
    -------
    w1, w2 : float or ndarray
        The weights [-].
    """
    w = h1 / h2
    return (1.0 + 2.0 * w) / (1.0 + w), w * w / (1.0 + w)


class LawTable:
    """The laws of a coupling's pairs, evaluated together on the law's inputs (the hot path).

    Gives, to the last bit, what :func:`magnitude_loads` gives pair by pair (the same operations in
    the same order), and in the same pass each pair's regime and the largest loads.

    Parameters
    ----------
    laws : list of PairLaw
    bands : list of (float, float, float)
        Per pair the widths of the sign ramps: rotation, sliding, resultant [m/s].
    slides : list of bool
        Per pair whether its axial force acts (else it is 0, whatever the law gives).
    """

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
        """The friction on the law's ``inputs`` or, with ``older``, on ``a x - b x_older``.

        One loop with the law inlined on purpose: it runs after every Newton solve, where a call
        per pair costs more than the law.

        Parameters
        ----------
        inputs, older : list of (float, float, float, float)
            Per pair ``(|F| [N], |M| [N m], omega_rel [rad/s], slide_rel [m/s])``.
        a, b : float
            Weights of the extrapolation through ``inputs`` and ``older`` [-].

        Returns
        -------
        friction : tuple of float
            Flat ``(M_z_0, F_z_0, M_z_1, ...)`` on body b of each pair [N m, N].
        regime : tuple of int
            Per pair the side of its two sign ramps the motion the law was evaluated on is on
            (-1, 0 inside, +1), flat: ``(rotation_0, sliding_0, rotation_1, ...)``.
        sliding : float
            The largest ``sliding_scale`` of the pairs [N m].
        size : float
            The largest ``|M_z|`` or ``|F_z|`` [N m or N].
        """
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
