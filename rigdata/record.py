"""One validated record of a rig measurement: time, the four transducer channels, provenance.

SI units throughout; each channel's conversion from the raw signal is kept in its :class:`ChannelSource`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["CHANNELS", "SHAFTS", "RATE_TOLERANCE", "RigDataError", "ChannelSource", "RigRecord", "with_signs"]

#: Channels a record may hold; SI units. ``angle_*`` come from pulse counts or an angle channel.
CHANNELS = {
    "torque_in": "N m", "torque_out": "N m",
    "speed_in": "rad/s", "speed_out": "rad/s",
    "angle_in": "rad", "angle_out": "rad",
}
SHAFTS = ("in", "out")
#: Relative spread of the sampling interval above which a record counts as mixed-rate.
RATE_TOLERANCE = 1e-3


class RigDataError(ValueError):
    """Bad measured data; the one-line message names file, channel and problem (CLI exit status 2)."""

    def __init__(self, problem: str, *, file: Any = None, channel: str | None = None) -> None:
        self.problem = problem
        self.file = file
        self.channel = channel
        where = [f"{file}" if file is not None else None,
                 f"channel {channel!r}" if channel is not None else None]
        prefix = ": ".join(w for w in where if w)
        super().__init__(f"{prefix}: {problem}" if prefix else problem)


@dataclass(frozen=True)
class ChannelSource:
    """Where a channel of a record came from.

    Attributes
    ----------
    column : str
        Column / channel name in the file.
    unit : str
        Unit as stated or given (``"V"``, ``"rpm"``, ``"counts"``).
    conversion : str
        Conversion to SI in words (``"V / 0.1 V/(N m)"``).
    quantum : float
        Resolution in SI, 0.0 when continuous.
    """

    column: str
    unit: str
    conversion: str = "none"
    quantum: float = 0.0


@dataclass(frozen=True)
class RigRecord:
    """A measurement on a uniform time grid; RigDataError on construction when invalid.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s], increasing, uniform to :data:`RATE_TOLERANCE`, n >= 4.
    channels : mapping of str to ndarray, shape (n,)
        Keys from :data:`CHANNELS`: both torques and per shaft ``speed_*`` and/or ``angle_*``; finite SI.
    sources : mapping of str to ChannelSource
        One per channel.
    provenance : mapping
        ``file``, ``format``, ``reader``, ``sha256``, ``header`` and, if synthetic, ``synthetic``.
    """

    time: np.ndarray
    channels: Mapping[str, np.ndarray]
    sources: Mapping[str, ChannelSource]
    provenance: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        file = self.provenance.get("file") if isinstance(self.provenance, Mapping) else None
        t = _checked_time(self.time, file)
        _check_channel_names(self.channels, file)
        channels = {name: _checked_values(name, values, t, file) for name, values in self.channels.items()}
        if set(self.sources) != set(channels):
            raise RigDataError(f"sources {sorted(self.sources)} do not match channels "
                               f"{sorted(channels)}", file=file)
        t.flags.writeable = False
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "channels", dict(channels))
        object.__setattr__(self, "sources", dict(self.sources))
        object.__setattr__(self, "provenance", dict(self.provenance))

    @property
    def dt(self) -> float:
        """Sampling interval [s] (median)."""
        return float(np.median(np.diff(self.time)))

    @property
    def sample_rate(self) -> float:
        """Sampling rate [Hz]."""
        return 1.0 / self.dt

    @property
    def duration(self) -> float:
        """Time span [s]."""
        return float(self.time[-1] - self.time[0])

    @property
    def file(self) -> Any:
        """The file read (``provenance["file"]``), None if not known."""
        return self.provenance.get("file")

    def turned(self, shaft: str = "in") -> float:
        """Angle turned by ``shaft`` [rad]: its angle channel, else the trapezoidal integral of its speed
        (by hand: scipy's import would cost ``cardan rig inspect`` 0.3 s).
        """
        angle = self.channels.get(f"angle_{shaft}")
        if angle is not None:
            return float(angle[-1] - angle[0])
        speed = self.channels[f"speed_{shaft}"]
        return float(np.sum(np.diff(self.time) * (speed[1:] + speed[:-1]) / 2.0))

    def revolutions(self, shaft: str = "in") -> float:
        """Revolutions turned by ``shaft``, absolute [-]."""
        return abs(self.turned(shaft)) / (2.0 * math.pi)


def with_signs(record: RigRecord, signs: Mapping[str, float] | None) -> RigRecord:
    """``record`` with channels multiplied by ``signs`` (channel -> +1 or -1, a sign convention); itself when
    None or empty. ValueError naming a channel the record lacks or a sign not +-1.
    """
    if not signs:
        return record
    channels = dict(record.channels)
    sources = dict(record.sources)
    for name, sign in signs.items():
        if name not in channels:
            raise ValueError(f"`signs`: no channel {name!r} in the record (it has {sorted(channels)})")
        if isinstance(sign, bool) or sign not in (1, -1):
            raise ValueError(f"`signs`: the sign of {name!r} must be +1 or -1, got {sign!r:.40}")
        channels[name] = channels[name] * float(sign)
        if sign == -1:
            s = sources[name]
            sources[name] = ChannelSource(s.column, s.unit, f"-({s.conversion})", s.quantum)
    return RigRecord(record.time, channels, sources, {**record.provenance, "signs": dict(signs)})


def _checked_time(time: Any, file: Any) -> np.ndarray:
    """``time`` as floats (>= 4 samples, finite, increasing, uniform); RigDataError naming the sample."""
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise RigDataError(f"needs at least 4 samples, got {t.size}", file=file, channel="time")
    if not np.all(np.isfinite(t)):
        raise RigDataError("time has non-finite values", file=file, channel="time")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise RigDataError(f"time does not increase at sample {i + 1} ({float(t[i])!r} then "
                           f"{float(t[i + 1])!r})", file=file, channel="time")
    step = float(np.median(dt))
    spread = float(np.max(np.abs(dt - step)) / step)
    if spread > RATE_TOLERANCE:
        i = int(np.argmax(np.abs(dt - step)))
        raise RigDataError(
            f"mixed sampling rates: interval {dt[i]:.6g} s at sample {i + 1} against the median "
            f"{step:.6g} s (the conditioning needs one rate; resample or split the file)",
            file=file, channel="time")
    return t


def _check_channel_names(channels: Mapping[str, Any], file: Any) -> None:
    """RigDataError for an unknown channel or a missing torque or shaft speed/angle."""
    unknown = set(channels) - set(CHANNELS)
    if unknown:
        raise RigDataError(f"unknown channels {sorted(unknown)}; expected {sorted(CHANNELS)}", file=file)
    for need in ("torque_in", "torque_out"):
        if need not in channels:
            raise RigDataError("missing (a record needs both torques)", file=file, channel=need)
    for shaft in SHAFTS:
        if f"speed_{shaft}" not in channels and f"angle_{shaft}" not in channels:
            raise RigDataError(f"missing: neither speed_{shaft} nor angle_{shaft} found",
                               file=file, channel=f"speed_{shaft}")


def _checked_values(name: str, values: Any, t: np.ndarray, file: Any) -> np.ndarray:
    """Channel ``name`` as read-only floats on grid ``t``; RigDataError for wrong length or a non-finite
    value.
    """
    v = np.asarray(values, dtype=float)
    if v.shape != t.shape:
        raise RigDataError(f"has {v.size} samples, time has {t.size}", file=file, channel=name)
    bad = ~np.isfinite(v)
    if bad.any():
        i = int(np.argmax(bad))
        raise RigDataError(f"{int(bad.sum())} non-finite values (NaN or non-numeric), the "
                           f"first at t = {t[i]:.6g} s (sample {i})", file=file, channel=name)
    v.flags.writeable = False
    return v
