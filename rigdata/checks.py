"""Plausibility of a measurement, each threshold ``K`` times a stated standard uncertainty: the output
power's sign, both shafts' revolutions over the window, the efficiency in [0, 1], the shaft angle
against the recording's own (Hooke's speed ratio fit).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from rigdata.conditioning import Conditioned, Conditioning, condition, window_weights
from rigdata.efficiency import SQRT3, Measured
from rigdata.record import RigDataError, RigRecord
from rigdata.transducer import Transducer

__all__ = ["K", "RigDataWarning", "Finding", "check_output_sign", "revolutions_agree",
           "efficiency_in_range", "shaft_angle_agrees", "recorded_shaft_angle"]

K = 2.0
"""Coverage factor of every check: a deviation beyond ``K`` standard uncertainties is reported."""


class RigDataWarning(UserWarning):
    """A measurement that disagrees with what the model is run with (the shaft angle)."""


@dataclass(frozen=True)
class Finding:
    """The outcome of one check.

    Attributes
    ----------
    check : str
        Which check (``revolutions``, ``efficiency_range``, ``shaft_angle``).
    status : str
        ``ok`` or why not (``inconsistent``, ``unphysical``, ``unresolved``, ``mismatch``).
    message : str
        One line saying what was found and against which limit.
    """

    check: str
    status: str
    message: str

    @property
    def ok(self) -> bool:
        """True when the check passed."""
        return self.status == "ok"

    def as_dict(self) -> dict:
        """JSON-ready fields."""
        return asdict(self)


def check_output_sign(m: Measured, file: object = None) -> None:
    """RigDataError when the output work is negative beyond ``K`` u: an output torque (or speed) recorded
    with the opposite sign, the option that flips it named.
    """
    if m.efficiency + K * m.u < 0.0:
        raise RigDataError(
            f"the output power is negative over the window (W_out / W_in = {m.efficiency:.4f} +- {m.u:.4f}): "
            "the output torque is recorded with the opposite sign (a common convention); flip it with "
            "--sign torque_out=-1 (Python: signs={'torque_out': -1})", file=file, channel="torque_out")


def _turned(c: Conditioned, shaft: str) -> float:
    """Angle [rad] the conditioned speed of ``shaft`` turns over the window."""
    weights = window_weights(c.t, *c.window)
    return float(weights @ (c.speed_in if shaft == "in" else c.speed_out))


def _relative_u_turned(c: Conditioned, shaft: str, tr: Transducer, turned: float) -> float:
    """Relative standard uncertainty [-] of the angle a shaft turns over the window: a speed channel's
    gain (rectangular within its limit), or a counted angle's quantum at each end (``q / sqrt 12`` each).
    """
    source = c.speed_sources.get(shaft, {})
    if source.get("kind") == "channel":
        return tr.speed_accuracy / SQRT3
    return source.get("quantum", 0.0) / math.sqrt(6.0) / abs(turned)


def revolutions_agree(c: Conditioned, transducers: tuple[Transducer, Transducer]) -> Finding:
    """Both shafts turn the same whole revolutions over the window (a Cardan joint's output angle returns
    each input revolution); ``inconsistent`` beyond ``K`` times the speed transducers' combined u.
    """
    turned = {s: _turned(c, s) for s in ("in", "out")}
    rel = {s: _relative_u_turned(c, s, tr, turned[s])
           for s, tr in zip(("in", "out"), transducers, strict=True)}
    deviation = abs(turned["out"] / turned["in"]) - 1.0
    limit = K * math.hypot(rel["in"], rel["out"])
    revs = {s: abs(turned[s]) / (2 * math.pi) for s in turned}
    if abs(deviation) <= limit:
        return Finding("revolutions", "ok", f"output turns {revs['out']:.4f} revolutions, input "
                       f"{revs['in']:.4f} ({100 * deviation:+.3f} %, limit {100 * limit:.3f} %)")
    return Finding("revolutions", "inconsistent",
                   f"the output shaft turns {revs['out']:.4f} revolutions over the window while the input "
                   f"turns {revs['in']:.4f} ({100 * deviation:+.2f} %, beyond the {100 * limit:.2f} % the "
                   "speed transducers allow at k=2): a Cardan joint turns both alike, so a speed channel "
                   f"reads {100 * deviation:+.2f} % off (a gain error, likely speed_out), and so does the "
                   "efficiency")


def efficiency_in_range(m: Measured) -> Finding:
    """Efficiency in [0, 1]: ``unphysical`` when outside by more than ``K`` u (an error in the data),
    ``unresolved`` when outside within ``K`` u (the measurement cannot tell the efficiency).
    """
    eta = m.efficiency
    if 0.0 <= eta <= 1.0:
        return Finding("efficiency_range", "ok", f"efficiency {eta:.4f} within [0, 1]")
    side = "above 1" if eta > 1.0 else "below 0"
    if -K * m.u <= eta <= 1.0 + K * m.u:
        return Finding("efficiency_range", "unresolved",
                       f"the measured efficiency {eta:.4f} +- {m.u:.4f} is {side}, within 2u: the "
                       "measurement does not resolve the efficiency (see the uncertainty budget)")
    return Finding("efficiency_range", "unphysical",
                   f"the measured efficiency {eta:.4f} +- {m.u:.4f} is {side} by more than 2u: no joint "
                   "does that; check the torque channels' units, sensitivities and --map")


def shaft_angle_agrees(c: Conditioned, shaft_angle: float) -> Finding:
    """``mismatch`` when the recording's own shaft angle (the speed ratio fit) differs from ``shaft_angle``
    [rad] by more than ``K`` times the fit's standard uncertainty.
    """
    fit = c.phase_fit.get("shaft_angle_fit")
    u = c.phase_fit.get("shaft_angle_fit_u")
    if fit is None or u is None or not math.isfinite(u):
        return Finding("shaft_angle", "ok", "no shaft angle fit (phase given)")
    given = math.degrees(shaft_angle)
    found = math.degrees(fit)
    u_deg = math.degrees(u)
    if abs(found - given) <= K * u_deg:
        return Finding("shaft_angle", "ok", f"recording's shaft angle {found:.3f} +- {u_deg:.3f} deg, "
                       f"model {given:.3f} deg")
    return Finding("shaft_angle", "mismatch",
                   f"the recording's own shaft angle is {found:.3f} +- {u_deg:.3f} deg (Hooke's speed "
                   f"ratio fit), the model runs at {given:.3f} deg: give --angle {found:.3f} or --angle auto")


def recorded_shaft_angle(record: RigRecord, options: Conditioning | None = None) -> float:
    """The recording's own shaft angle [rad]: Hooke's speed ratio fit, phase found at 15 deg, then again at
    the angle found (``--angle auto``).
    """
    beta = math.radians(15.0)
    for _ in range(2):
        beta = float(condition(record, beta, options).phase_fit["shaft_angle_fit"])
    return beta
