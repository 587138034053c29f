"""From a raw record to conditioned signals on whole input revolutions (:func:`condition`): angles,
one zero-phase low-pass for every channel (powers see no relative phase or gain error), speeds
(measured, else from the filtered angle), whole-revolution window, input yoke phase.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from rigdata.conditioning.angles import angle_on_grid
from rigdata.conditioning.filters import angular_speed, lowpass
from rigdata.conditioning.options import Conditioning
from rigdata.conditioning.phase import estimate_phase
from rigdata.conditioning.window import revolution_window
from rigdata.conversion import check_magnitudes
from rigdata.record import SHAFTS, RigDataError, RigRecord

__all__ = ["Conditioned", "condition"]


@dataclass(frozen=True)
class Conditioned:
    """Conditioned signals on the record's grid cut to the settled span.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times [s].
    angle_in : ndarray, shape (n,)
        Filtered input angle [rad] from the first pulse, not phase-corrected.
    speed_in, speed_out : ndarray, shape (n,)
        Filtered speeds [rad/s].
    torque_in, torque_out, raw_torque_in, raw_torque_out : ndarray, shape (n,)
        Filtered and unfiltered torques [N m].
    window : tuple of float
        Whole-revolution window ``(t_a, t_b)`` [s], on input pulse edges if any.
    revolutions : int
        Whole input revolutions in the window.
    phase : float
        Input yoke phase [rad]: model input angle ``angle_in + phase``.
    phase_fit : dict
        ``rms``, ``shaft_angle_fit`` [rad], ``source``.
    cutoff : float
        Low-pass cut-off [Hz].
    settings : dict
        The Conditioning used.
    speed_sources : dict
        Per shaft (``in``, ``out``) where its speed came from: ``kind`` (``channel``, ``pulses`` or
        ``angle``) and the pulse ``quantum`` [rad] (0.0 unless counted).
    """

    t: np.ndarray
    angle_in: np.ndarray
    speed_in: np.ndarray
    speed_out: np.ndarray
    torque_in: np.ndarray
    torque_out: np.ndarray
    raw_torque_in: np.ndarray
    raw_torque_out: np.ndarray
    window: tuple
    revolutions: int
    phase: float
    phase_fit: dict = field(default_factory=dict)
    cutoff: float = 0.0
    settings: dict = field(default_factory=dict)
    speed_sources: dict = field(default_factory=dict)

    @property
    def dt(self) -> float:
        """Sampling interval [s]."""
        return float(self.t[1] - self.t[0])

    def in_window(self) -> np.ndarray:
        """Boolean mask of the samples inside the whole-revolution window, shape (n,)."""
        return (self.t >= self.window[0]) & (self.t <= self.window[1])


def _check_arguments(record: RigRecord, shaft_angle: float, options: Conditioning | None) -> Conditioning:
    """Options of :func:`condition` (defaults for None); TypeError/ValueError for bad arguments."""
    if not isinstance(record, RigRecord):
        raise TypeError(f"`record` must be a RigRecord (rigdata.read(path) reads one), got "
                        f"{type(record).__name__} {record!r:.80}")
    if isinstance(shaft_angle, bool) or not isinstance(shaft_angle, (int, float, np.number)):
        raise TypeError(f"`shaft_angle` must be a number [rad], got {shaft_angle!r:.80}")
    if not (math.isfinite(shaft_angle) and 0.0 <= shaft_angle < 0.5 * math.pi):
        raise ValueError(f"`shaft_angle` must be in [0, pi/2) rad, got {shaft_angle!r}")
    options = Conditioning() if options is None else options
    if not isinstance(options, Conditioning):
        raise TypeError(f"`options` must be a Conditioning or None, got {type(options).__name__}")
    return options


def _check_record(record: RigRecord, options: Conditioning) -> None:
    """RigDataError for a record too short for the filter, with absurd values or a dead transducer."""
    fewest = 3 * (2 * math.ceil(options.filter_order / 2) + 1) + 1  # sosfiltfilt's padding + 1
    if record.time.size < fewest:
        raise RigDataError(f"too short: {record.time.size} samples; the zero-phase filter of order "
                           f"{options.filter_order} needs at least {fewest}", file=record.file,
                           channel="time")
    check_magnitudes(record.time, record.channels, file=record.file)
    for name in ("torque_in", "torque_out", "speed_in", "speed_out"):
        values = record.channels.get(name)
        if values is not None and not np.any(values):
            what = "the shaft does not turn, or " if name.startswith("speed") else ""
            raise RigDataError(f"reads 0 at every sample: {what}a dead or unplugged transducer (or the "
                               "wrong column: --map)", file=record.file, channel=name)


def _shafts_turn_together(record: RigRecord, angles: dict[str, np.ndarray]) -> None:
    """Refuse an output angle that does not follow the input within a quarter turn (dead, stuck,
    mis-scaled).
    """
    turned = {s: abs(float(angles[s][-1] - angles[s][0])) / (2 * math.pi) for s in SHAFTS}
    if not 0.5 * turned["in"] - 0.25 <= turned["out"] <= 2.0 * turned["in"] + 0.25:
        channel = "speed_out" if "speed_out" in record.channels else "angle_out"
        raise RigDataError(f"the output shaft turns {turned['out']:.3g} revolutions while the input turns "
                           f"{turned['in']:.3g}: the shafts of a Cardan joint turn together (a dead, stuck "
                           "or mis-scaled transducer, or the wrong unit: --unit)", file=record.file,
                           channel=channel)


def _speed(record: RigRecord, shaft: str, filtered_angle: Callable[[], np.ndarray], cutoff: float,
           options: Conditioning) -> np.ndarray:
    """Shaft speed [rad/s]: its speed channel filtered, else the speed of ``filtered_angle()``."""
    measured = record.channels.get(f"speed_{shaft}")
    if measured is not None:
        return lowpass(measured, cutoff, 1.0 / record.dt, options.filter_order)
    return angular_speed(filtered_angle(), record.dt, cutoff, options.derivative)


def _speed_source(record: RigRecord, shaft: str, edges: np.ndarray | None) -> dict:
    """``kind`` of a shaft's speed (``channel``, ``pulses``, ``angle``) and its pulse ``quantum`` [rad]."""
    if f"speed_{shaft}" in record.channels:
        return {"kind": "channel", "quantum": 0.0}
    if edges is not None:
        return {"kind": "pulses", "quantum": float(record.sources[f"angle_{shaft}"].quantum)}
    return {"kind": "angle", "quantum": 0.0}


def _filtered(record: RigRecord, angles: dict[str, np.ndarray], cutoff: float,
              options: Conditioning) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Low-passed input angle [rad], and per shaft speed [rad/s] and torque [N m], at ``cutoff`` [Hz]."""
    rate = 1.0 / record.dt
    angle_in = lowpass(angles["in"], cutoff, rate, options.filter_order)
    speeds = {"in": _speed(record, "in", lambda: angle_in, cutoff, options),
              "out": _speed(record, "out", lambda: lowpass(angles["out"], cutoff, rate, options.filter_order),
                            cutoff, options)}
    torques = {s: lowpass(record.channels[f"torque_{s}"], cutoff, rate, options.filter_order)
               for s in SHAFTS}
    return angle_in, speeds, torques


def condition(record: RigRecord, shaft_angle: float, options: Conditioning | None = None) -> Conditioned:
    """Condition a record (see the module docstring).

    Parameters
    ----------
    record : RigRecord
    shaft_angle : float
        Shaft angle [rad], for the phase estimate.
    options : Conditioning, optional

    Returns
    -------
    Conditioned

    Raises
    ------
    RigDataError
        A record that cannot be conditioned.
    """
    options = _check_arguments(record, shaft_angle, options)
    _check_record(record, options)
    t = record.time
    angles = {}
    edges = {}
    for shaft in SHAFTS:
        angles[shaft], edges[shaft] = angle_on_grid(record, shaft)
    mean_speed = abs(angles["in"][-1] - angles["in"][0]) / (t[-1] - t[0])
    if mean_speed <= 0:
        raise RigDataError("the input shaft does not turn", file=record.file, channel="angle_in")
    _shafts_turn_together(record, angles)
    cutoff = options.cutoff_harmonics * mean_speed / (2 * math.pi)
    angle_in, speeds, torques = _filtered(record, angles, cutoff, options)
    t_a, t_b, n = revolution_window(t, angles["in"], edges["in"], options.settle_revolutions, record.file)
    settle_time = options.settle_revolutions * 2 * math.pi / mean_speed
    keep = (t >= min(t_a, t[0] + settle_time) - 1e-12) & (t <= max(t_b, t[-1] - settle_time) + 1e-12)
    inside = (t >= t_a) & (t <= t_b)
    if options.phase is not None:
        phase_fit = {"phase": float(options.phase), "source": "given"}
    else:
        ratio = speeds["out"][inside] / speeds["in"][inside]
        # a low-pass at ``cutoff`` leaves two independent values per cut-off period
        phase_fit = estimate_phase(angles["in"][inside], ratio, float(shaft_angle),
                                   independent=2.0 * cutoff * (t_b - t_a))
    return Conditioned(
        t=t[keep], angle_in=angle_in[keep],
        speed_in=speeds["in"][keep], speed_out=speeds["out"][keep],
        torque_in=torques["in"][keep], torque_out=torques["out"][keep],
        raw_torque_in=np.asarray(record.channels["torque_in"])[keep],
        raw_torque_out=np.asarray(record.channels["torque_out"])[keep],
        window=(t_a, t_b), revolutions=n, phase=float(phase_fit["phase"]), phase_fit=phase_fit,
        cutoff=float(cutoff), settings=asdict(options),
        speed_sources={s: _speed_source(record, s, edges[s]) for s in SHAFTS})
