"""Channel values to SI (raw volts, pulse counts and rates included), counter wraps undone, magnitudes
checked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigdata.record import RigDataError
from rigdata.transducer import PULSES_PER_REV, SENSITIVITY
from rigdata.units import SI, Unit

__all__ = ["LIMITS", "check_magnitudes", "Converted", "to_si", "unwrap_counter"]

#: Largest magnitude of each kind in SI: time 1e11 s (LabVIEW clocks count from 1904), torque 1e8 N m,
#: speed 1e5 rad/s, angle 1e9 rad; beyond is a wrong unit or corrupt file (and the budget's squares overflow).
LIMITS = {"time": 1e11, "torque": 1e8, "speed": 1e5, "angle": 1e9}


def check_magnitudes(time: np.ndarray, channels: dict[str, np.ndarray], file: object = None) -> None:
    """RigDataError naming channel, sample and limit for values beyond :data:`LIMITS` (wrong unit or corrupt
    file).
    """
    for name, values in (("time", time), *channels.items()):
        kind = name.split("_")[0]
        limit = LIMITS.get(kind)
        values = np.asarray(values, dtype=float)
        if limit is None or values.size == 0:
            continue
        i = int(np.argmax(np.abs(values)))
        if abs(values[i]) > limit:
            raise RigDataError(f"{values[i]:.3g} {SI[kind]} at sample {i} exceeds the plausible {limit:g} "
                               f"{SI[kind]} in magnitude: a wrong unit or scale (--unit, --sensitivity) "
                               "or a corrupt file", file=file, channel=name)


@dataclass(frozen=True)
class Converted:
    """Values of one channel in SI and how they got there.

    Attributes
    ----------
    values : ndarray, shape (n,)
    conversion : str
        The conversion in words.
    quantum : float
        Resolution in SI (2 pi / pulses per revolution for counts), 0.0 when continuous.
    notes : tuple of str
        Counter wraps and resets undone.
    """

    values: np.ndarray
    conversion: str
    quantum: float = 0.0
    notes: tuple[str, ...] = ()


def _factor_text(unit: Unit, si: str) -> str:
    if unit.factor == 1.0:
        return "none"
    return f"x {unit.factor:.10g} ({unit.symbol} -> {si})"


def to_si(values: np.ndarray, unit: Unit, *, sensitivity: float = SENSITIVITY,
          pulses_per_rev: int = PULSES_PER_REV) -> Converted:
    """Channel ``values`` in ``unit`` to SI: volts / ``sensitivity`` [V/(N m)] -> torque; counts (unwrapped)
    and pulse rates via ``pulses_per_rev`` -> angle, speed; else the factor.
    """
    v = np.asarray(values, dtype=float) * unit.factor
    if unit.quantity == "voltage":
        text = f"{unit.symbol} x {unit.factor:g} / {sensitivity:g} V/(N m)" if unit.factor != 1.0 \
            else f"V / {sensitivity:g} V/(N m)"
        return Converted(v / sensitivity, text)
    step = 2.0 * math.pi / pulses_per_rev
    if unit.quantity == "pulse_rate":
        return Converted(v * step, f"pulses/s x 2 pi / {pulses_per_rev} pulses per revolution")
    if unit.quantity == "counts":
        counts, notes = unwrap_counter(v, pulses_per_rev)
        return Converted(counts * step, f"counts x 2 pi / {pulses_per_rev} pulses per revolution",
                         step, notes)
    return Converted(v, _factor_text(unit, SI[unit.quantity]))


def unwrap_counter(counts: np.ndarray,
                   pulses_per_rev: int = PULSES_PER_REV) -> tuple[np.ndarray, tuple[str, ...]]:
    """Continuous ``counts`` from the first reading, and notes on each wrap or reset undone.

    A step over half a revolution backwards is a wrap (an 8-32 bit power of two, within two pulses,
    added back) or else a reset (replaced by the median of the ten steps around it).
    """
    c = np.asarray(counts, dtype=float)
    if c.size < 2 or not np.all(np.isfinite(c)):
        return c, ()
    d = np.diff(c)
    direction = np.sign(np.median(d)) or np.sign(d.sum()) or 1.0
    jumps = np.flatnonzero(d * direction < -pulses_per_rev / 2.0)
    if jumps.size == 0:
        return c, ()
    fixed = d.copy()
    notes = []
    for k in jumps:
        near = np.delete(d[max(0, k - 5):k + 6], min(k, 5))
        near = near[near * direction >= -pulses_per_rev / 2.0]
        typical = float(np.median(near)) if near.size else 0.0
        modulus = abs(typical - d[k])
        bits = round(math.log2(modulus)) if modulus > 0 else 0
        if 8 <= bits <= 32 and abs(modulus - 2.0 ** bits) <= 2.0:
            fixed[k] = d[k] + direction * 2.0 ** bits
            notes.append(f"counter wrapped at 2^{bits} between samples {k} and {k + 1}; undone exactly")
        else:
            fixed[k] = typical
            notes.append(f"counter reset between samples {k} and {k + 1} (jump of {d[k]:g} pulses); "
                         f"step replaced by the local median {typical:g} pulses (angle known to about "
                         f"one step from there on)")
    return np.concatenate(([c[0]], c[0] + np.cumsum(fixed))), tuple(notes)
