"""Units of measured channels: an explicit table of spellings (:data:`UNITS`) and header unit parsing.

Hand-written because unit libraries read ``"Nm"`` as nanometre. ``Hz`` is refused for speeds
(revolutions or 60-pulse frequency per second?): write ``rev/s`` or ``pulses/s``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from rigdata.record import RigDataError

__all__ = ["SI", "ACCEPTS", "AMBIGUOUS", "UNITS", "Unit", "normalise", "lookup", "accepted", "parse_unit",
           "split_header"]

#: SI unit of each quantity.
SI = {"time": "s", "torque": "N m", "speed": "rad/s", "angle": "rad",
      "voltage": "V", "counts": "pulses", "pulse_rate": "pulses/s"}

#: Quantities a unit may have for each kind of record channel.
ACCEPTS = {"time": ("time",), "torque": ("torque", "voltage"),
           "speed": ("speed", "pulse_rate"), "angle": ("angle", "counts")}

_RPM = 2.0 * math.pi / 60.0
_LBF_IN = 0.1129848290276167      # 1 lbf in = 4.4482216152605 N x 0.0254 m
_LBF_FT = 1.3558179483314004      # 1 lbf ft = 4.4482216152605 N x 0.3048 m
_OZF_IN = 0.007061551814226046    # 1 ozf in = 1/16 lbf in

# canonical symbol -> (quantity, factor to SI, other spellings). Spellings are compared after
# normalise(): lower case, no blanks, no product signs (* · ⋅ ×) or dots, micro as "u".
_TABLE: dict[str, tuple[str, float, tuple[str, ...]]] = {
    "s": ("time", 1.0, ("sec", "secs", "second", "seconds")),
    "ms": ("time", 1e-3, ("msec", "millisecond", "milliseconds")),
    "us": ("time", 1e-6, ("usec", "microsecond", "microseconds")),
    "ns": ("time", 1e-9, ("nanosecond", "nanoseconds")),
    "min": ("time", 60.0, ("minute", "minutes")),
    "N m": ("torque", 1.0, ("Nm", "N*m", "N·m", "N.m", "N-m", "newton metre", "newton meter",
                            "newton metres", "newton meters")),
    "mN m": ("torque", 1e-3, ("mNm", "mN*m", "mN·m", "mN.m", "mN-m")),
    "N cm": ("torque", 1e-2, ("Ncm", "N*cm", "N·cm", "N.cm", "N-cm")),
    "N mm": ("torque", 1e-3, ("Nmm", "N*mm", "N·mm", "N.mm", "N-mm")),
    "kN m": ("torque", 1e3, ("kNm", "kN*m", "kN·m", "kN.m", "kN-m")),
    "lbf in": ("torque", _LBF_IN, ("lb in", "lb-in", "lbf-in", "in lb", "in-lb", "in lbf", "in-lbf")),
    "lbf ft": ("torque", _LBF_FT, ("lb ft", "lb-ft", "lbf-ft", "ft lb", "ft-lb", "ft lbf", "ft-lbf")),
    "ozf in": ("torque", _OZF_IN, ("oz in", "oz-in", "ozf-in", "in oz", "in-oz")),
    "rad/s": ("speed", 1.0, ("rad/sec", "rad s^-1", "rad s-1", "rad*s^-1", "radian/s",
                             "radians/s")),
    "rpm": ("speed", _RPM, ("1/min", "/min", "min^-1", "min-1", "min⁻¹", "r/min", "rev/min",
                            "revs/min", "U/min", "tr/min", "revolutions per minute")),
    "rev/s": ("speed", 2.0 * math.pi, ("rps", "r/s", "revs/s", "rev/sec", "revolutions per second")),
    "deg/s": ("speed", math.pi / 180.0, ("°/s", "degree/s", "degrees/s", "deg/sec")),
    "rad": ("angle", 1.0, ("radian", "radians")),
    "deg": ("angle", math.pi / 180.0, ("°", "degree", "degrees")),
    "rev": ("angle", 2.0 * math.pi, ("revs", "revolution", "revolutions", "turn", "turns")),
    "V": ("voltage", 1.0, ("volt", "volts")),
    "mV": ("voltage", 1e-3, ("millivolt", "millivolts")),
    "counts": ("counts", 1.0, ("count", "cnt", "cnts", "pulses", "pulse", "imp", "impulse",
                               "impulses", "ticks", "tick")),
    "pulses/s": ("pulse_rate", 1.0, ("pulse/s", "pulses/sec", "imp/s", "counts/s", "count/s",
                                     "cnt/s", "cps", "pps")),
}

#: Spellings refused because they are ambiguous on this rig, with the reason.
AMBIGUOUS = {
    "hz": "'Hz' is ambiguous for a speed (revolutions per second or the 60-pulse frequency of "
          "the speed output); write 'rev/s' or 'pulses/s'",
    "1/s": "'1/s' is ambiguous for a speed (rad/s, rev/s or pulses/s); write one of those",
}


def normalise(spelling: str) -> str:
    """Comparison key of a unit spelling: lower case, no blanks, product signs or dots (``N·m`` -> ``nm``)."""
    s = spelling.strip().lower().replace("µ", "u").replace("μ", "u").replace("⁻¹", "^-1")
    return re.sub(r"[\s*·⋅×.]", "", s)


@dataclass(frozen=True)
class Unit:
    """A recognised unit.

    Attributes
    ----------
    spelling : str
        As written.
    symbol : str
        Canonical symbol (``"N m"``).
    quantity : str
        A key of :data:`SI`.
    factor : float
        Multiplier to the quantity's SI unit (``rpm``: 2 pi / 60).
    """

    spelling: str
    symbol: str
    quantity: str
    factor: float


def _build() -> dict[str, tuple[str, str, float]]:
    table = {}
    for symbol, (quantity, factor, others) in _TABLE.items():
        for spelling in (symbol, *others):
            table[normalise(spelling)] = (symbol, quantity, factor)
    return table


#: Normalised spelling -> (canonical symbol, quantity, factor to SI).
UNITS: dict[str, tuple[str, str, float]] = _build()


def lookup(spelling: str) -> Unit | None:
    """The unit of a spelling, or None when the table does not know it (no error)."""
    entry = UNITS.get(normalise(spelling))
    return None if entry is None else Unit(spelling.strip(), *entry)


def accepted(quantities: tuple[str, ...] | None = None) -> str:
    """Accepted spellings grouped by quantity on one line (only ``quantities`` when given)."""
    groups = []
    for quantity in quantities or tuple(SI):
        spellings = [s for sym, (q, _, others) in _TABLE.items() if q == quantity for s in (sym, *others)]
        groups.append(f"{quantity}: {', '.join(spellings)}")
    return "; ".join(groups)


def parse_unit(spelling: str, *, kind: str | None = None, column: str | None = None,
               file: object = None, channel: str | None = None) -> Unit:
    """Unit of ``spelling``, whose quantity must be in ``ACCEPTS[kind]`` when ``kind`` is given.

    RigDataError (naming ``column``, ``file``, ``channel``) for an unknown, ambiguous or wrong-quantity
    unit.
    """
    where = f" in column {column!r}" if column is not None else ""
    allowed = ACCEPTS[kind] if kind is not None else None
    key = normalise(spelling)
    if key in AMBIGUOUS:
        raise RigDataError(f"unit {spelling!r}{where}: {AMBIGUOUS[key]}", file=file, channel=channel)
    unit = lookup(spelling)
    if unit is None:
        raise RigDataError(f"unknown unit {spelling!r}{where}; accepted units are {accepted(allowed)}",
                           file=file, channel=channel)
    if allowed is not None and unit.quantity not in allowed:
        raise RigDataError(f"unit {spelling!r}{where} is a {unit.quantity} unit, a {kind} channel needs "
                           f"{accepted(allowed)}", file=file, channel=channel)
    return unit


_BRACKETED = re.compile(r"^(?P<name>.*?)\s*(?:\[(?P<a>[^\[\]]*)\]|\((?P<b>[^()]*)\)|\{(?P<c>[^{}]*)\}"
                        r"|<(?P<d>[^<>]*)>)\s*$")
_SLASHED = re.compile(r"^(?P<name>.*?\S)\s+/\s*(?P<unit>\S.*?)\s*$")


def split_header(header: str) -> tuple[str, str | None]:
    """Bare name and unit as written (None if none) of a column header.

    Forms: ``Torque In [N m]``, ``torque_in (Nm)``, ``Speed In {rpm}``, ``angle <deg>`` (last
    bracket), ``speed_out / rpm``.
    """
    text = header.strip()
    m = _BRACKETED.match(text)
    if m and m.group("name"):
        unit = next(g for g in m.group("a", "b", "c", "d") if g is not None).strip()
        return m.group("name").strip(), unit or None
    m = _SLASHED.match(text)
    if m:
        return m.group("name").strip(), m.group("unit")
    return text, None
