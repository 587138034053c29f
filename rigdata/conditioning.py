"""From a raw record to conditioned signals on whole input revolutions.

Steps (each a parameter of :class:`Conditioning`, defaults justified in ``docs/rigdata.md``):

1. **Angles** of both shafts on the sample grid: from pulse counts by monotone cubic (PCHIP)
   interpolation through the pulse edges (an edge is placed midway between the two samples
   that bracket the count's change: there the shaft was exactly at a multiple of the pulse
   angle); from an angle channel as given; from a speed channel by the trapezoidal integral.
2. **Zero-phase low-pass** (Butterworth, forward and backward, ``scipy.signal.sosfiltfilt``) of
   angles, speeds and torques, the cut-off tied to the mean input shaft frequency
   (``cutoff_harmonics`` times it): every channel gets the same filter, so products such as
   powers see no relative phase or gain error.
3. **Derivatives**: speed and acceleration of the filtered angle by Savitzky-Golay (or a
   smoothing spline); a measured speed channel, where there is one, is used for the speed.
4. **Trimming** to whole input revolutions: ``settle_revolutions`` are dropped at each end
   (filter transients, start-up); the window starts at the first input pulse edge after them
   and ends a whole number of revolutions later, also on an edge.
5. **Input yoke phase**: the encoder has no index pulse, so the input angle's zero is unknown;
   it is estimated by fitting Hooke's speed ratio to the measured output/input speed ratio
   (determined modulo 180 deg: Hooke's ratio has that period).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy import signal
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import PchipInterpolator, make_smoothing_spline
from scipy.optimize import minimize_scalar

from reference.physics.kinematics import speed_ratio
from rigdata.record import SHAFTS, RigDataError, RigRecord
from rigdata.conversion import check_magnitudes

DERIVATIVES = ("savgol", "spline")


@dataclass(frozen=True)
class Conditioning:
    """Settings of :func:`condition`.

    Attributes
    ----------
    cutoff_harmonics : float
        Low-pass cut-off as a multiple of the mean input shaft frequency [-]. Hooke's joint
        puts the speed ratio's content at even harmonics decaying as tan^2(beta/2)^k: at 15 deg
        the 2nd harmonic is 3.4 %, the 6th 1e-5; 10 keeps every harmonic above 1e-6 and rejects
        the noise above.
    filter_order : int
        Butterworth order of one pass (the zero-phase filter applies it twice).
    derivative : {"savgol", "spline"}
        How speed and acceleration are taken from the filtered angle.
    settle_revolutions : float
        Input revolutions dropped at each end before the whole-revolution window [-].
    phase : float or None
        Input yoke phase [rad] if known (skips the estimate).
    """

    cutoff_harmonics: float = 10.0
    filter_order: int = 4
    derivative: str = "savgol"
    settle_revolutions: float = 0.25
    phase: float | None = None

    def __post_init__(self) -> None:
        for name in ("cutoff_harmonics", "settle_revolutions", "phase"):
            value = getattr(self, name)
            if (value is not None or name != "phase") and (
                    isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating))):
                raise TypeError(f"`{name}` must be a number, got {value!r:.80}")
        if self.phase is not None and not math.isfinite(self.phase):
            raise ValueError(f"`phase` must be finite [rad] or None, got {self.phase!r}")
        if not isinstance(self.derivative, str):
            raise TypeError(f"`derivative` must be one of {DERIVATIVES}, got {self.derivative!r:.80}")
        if not (math.isfinite(self.cutoff_harmonics) and self.cutoff_harmonics >= 2.0):
            raise ValueError(f"`cutoff_harmonics` must be >= 2 (Hooke's joint's 2nd harmonic), got "
                             f"{self.cutoff_harmonics!r}")
        if isinstance(self.filter_order, bool) or not isinstance(self.filter_order, int) \
                or not 1 <= self.filter_order <= 10:
            raise ValueError(f"`filter_order` must be an integer in 1..10, got {self.filter_order!r}")
        if self.derivative not in DERIVATIVES:
            raise ValueError(f"`derivative` must be one of {DERIVATIVES}, got {self.derivative!r}")
        if not (math.isfinite(self.settle_revolutions) and 0 <= self.settle_revolutions <= 1e6):
            raise ValueError(f"`settle_revolutions` must be in [0, 1e6], got {self.settle_revolutions!r}")
        if self.cutoff_harmonics > 1e6:
            raise ValueError(f"`cutoff_harmonics` must be at most 1e6, got {self.cutoff_harmonics!r}")


@dataclass(frozen=True)
class Conditioned:
    """Conditioned signals, on the record's grid cut to the settled span.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times [s].
    angle_in, angle_out : ndarray
        Filtered shaft angles [rad] (input: from the first pulse, not phase-corrected).
    speed_in, speed_out : ndarray
        Filtered speeds [rad/s].
    accel_in : ndarray
        Input acceleration [rad/s^2].
    torque_in, torque_out : ndarray
        Filtered torques [N m].
    raw_torque_in, raw_torque_out : ndarray
        Unfiltered torques on the same grid [N m] (for the noise estimate).
    window : tuple of float
        Whole-revolution window ``(t_a, t_b)`` [s], both on input pulse edges where there are
        pulses.
    revolutions : int
        Whole input revolutions in the window.
    phase : float
        Input yoke phase [rad]: the model's input angle is ``angle_in + phase``.
    phase_fit : dict
        How the phase was found: ``rms`` residual of the speed ratio, ``shaft_angle_fit`` [rad]
        (the shaft angle that fits best, for a plausibility check) and ``source``.
    cutoff : float
        Low-pass cut-off [Hz].
    settings : dict
        The :class:`Conditioning` used.
    """

    t: np.ndarray
    angle_in: np.ndarray
    angle_out: np.ndarray
    speed_in: np.ndarray
    speed_out: np.ndarray
    accel_in: np.ndarray
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

    @property
    def dt(self) -> float:
        """Sampling interval [s]."""
        return float(self.t[1] - self.t[0])

    def in_window(self) -> np.ndarray:
        """Boolean mask of the samples inside the whole-revolution window."""
        return (self.t >= self.window[0]) & (self.t <= self.window[1])


def pulse_edges(t: np.ndarray, angle: np.ndarray, quantum: float) -> tuple[np.ndarray, np.ndarray]:
    """Instants [s] and angles [rad] of the pulse edges of a counted (staircase) angle.

    The count changes between two samples; the edge is placed midway (its timing uncertainty
    is one sample interval, rectangular). Several pulses within one interval share the instant.
    """
    steps = np.flatnonzero(np.diff(angle) != 0.0)
    if steps.size < 2:
        return np.zeros(0), np.zeros(0)
    times = 0.5 * (t[steps] + t[steps + 1])
    levels = angle[steps + 1]
    # the angle at the edge is the level reached (crossing the multiple of the pulse angle)
    keep = np.concatenate([[True], np.diff(times) > 0])
    return times[keep], levels[keep]


def angle_on_grid(record: RigRecord, shaft: str) -> tuple[np.ndarray, np.ndarray | None]:
    """A shaft's angle on the record's grid [rad] and, for pulses, the edge instants [s].

    Outside the first and last edge the angle is extrapolated linearly (trimmed later).
    """
    t = record.time
    angle = record.channels.get(f"angle_{shaft}")
    source = record.sources.get(f"angle_{shaft}")
    if angle is not None and source is not None and source.quantum > 0:
        times, levels = pulse_edges(t, angle, source.quantum)
        if times.size < 4:
            raise RigDataError(f"fewer than 4 pulse edges ({times.size}): the shaft hardly turns",
                               file=record.file, channel=f"angle_{shaft}")
        if not (np.all(np.diff(levels) > 0) or np.all(np.diff(levels) < 0)):
            raise RigDataError("the pulse count goes back and forth: the shaft reverses or the "
                               "counter is not a cumulative count", file=record.file,
                               channel=f"angle_{shaft}")
        return PchipInterpolator(times, levels, extrapolate=True)(t), times
    if angle is not None:
        return np.asarray(angle, float), None
    return cumulative_trapezoid(record.channels[f"speed_{shaft}"], t, initial=0.0), None


def lowpass(x: np.ndarray, cutoff: float, rate: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth low-pass [same units as x]; cut-off [Hz], rate [Hz]."""
    nyquist = 0.5 * rate
    if cutoff >= nyquist:
        return np.asarray(x, float).copy()
    sos = signal.butter(order, cutoff / nyquist, output="sos")
    return signal.sosfiltfilt(sos, x)


def derivatives(angle: np.ndarray, dt: float, cutoff: float, method: str) -> tuple[np.ndarray, np.ndarray]:
    """Speed [rad/s] and acceleration [rad/s^2] of a filtered angle.

    Savitzky-Golay: cubic over a window of half a cut-off period (odd, >= 7 samples), whose own
    smoothing then stays above the cut-off. Spline: a cubic smoothing spline whose penalty puts
    its half-power frequency at the cut-off.
    """
    if method == "spline":
        t = np.arange(angle.size) * dt
        # the penalty lam int f''^2 makes the spline a low-pass with gain 1 / (1 + lam (2 pi f)^4
        # / dt) on a uniform grid: half power at the cut-off for this lam (generalised
        # cross-validation, the default, smooths the 2nd harmonic away on these records)
        spline = make_smoothing_spline(t, angle, lam=dt / (2 * math.pi * cutoff) ** 4)
        return spline(t, 1), spline(t, 2)
    window = max(7, int(round(0.5 / (cutoff * dt))) | 1)
    if window > angle.size:
        window = angle.size if angle.size % 2 else angle.size - 1
    if window < 5:
        raise RigDataError(f"too few samples ({angle.size}) for derivatives")
    speed = signal.savgol_filter(angle, window, 3, deriv=1, delta=dt, mode="interp")
    accel = signal.savgol_filter(angle, window, 3, deriv=2, delta=dt, mode="interp")
    return speed, accel


def estimate_phase(angle_in: np.ndarray, ratio: np.ndarray, shaft_angle: float) -> dict:
    """Input yoke phase [rad] in [0, pi) that best fits Hooke's speed ratio to the measured one.

    Least squares over the phase (a 360-point scan, then a bounded refinement); the shaft angle
    that fits best at that phase is reported as a plausibility check.
    """
    def residual(phase: float, beta: float = shaft_angle) -> float:
        return float(np.mean((ratio - speed_ratio(angle_in + phase, beta)) ** 2))

    scan = np.linspace(0.0, math.pi, 360, endpoint=False)
    best = scan[int(np.argmin([residual(p) for p in scan]))]
    step = scan[1] - scan[0]
    fit = minimize_scalar(residual, bounds=(best - step, best + step), method="bounded",
                          options={"xatol": 1e-7})
    phase = float(fit.x) % math.pi
    beta = minimize_scalar(lambda b: residual(phase, b), bounds=(0.0, 1.4), method="bounded",
                           options={"xatol": 1e-7})
    amplitude = float(np.ptp(speed_ratio(np.linspace(0, math.pi, 181), shaft_angle)))
    return {"phase": phase, "rms": math.sqrt(fit.fun), "ratio_ripple": amplitude,
            "shaft_angle_fit": float(beta.x), "source": "Hooke's speed ratio fit"}


def _trim_to_revolutions(t: np.ndarray, angle: np.ndarray, edges: np.ndarray | None,
                         settle: float, file) -> tuple[float, float, int]:
    sign = 1.0 if angle[-1] >= angle[0] else -1.0
    a = sign * angle
    first, last = a[0] + 2 * math.pi * settle, a[-1] - 2 * math.pi * settle
    if edges is not None:
        edge_angle = np.interp(edges, t, a)
        usable = edges[(edge_angle >= first) & (edge_angle <= last)]
        if usable.size < 2:
            raise RigDataError("less than one whole input revolution after trimming "
                               f"{settle:g} revolutions at each end", file=file, channel="angle_in")
        t_a = float(usable[0])
    else:
        t_a = float(np.interp(first, a, t))
    a_a = float(np.interp(t_a, t, a))
    n = int(math.floor((last - a_a) / (2 * math.pi) + 1e-9))
    if n < 1:
        raise RigDataError(
            f"less than one whole input revolution: the record turns {(a[-1] - a[0]) / (2 * math.pi):.3g} "
            f"revolutions and {2 * settle:g} are trimmed for settling (--settle)", file=file,
            channel="angle_in")
    target = a_a + 2 * math.pi * n
    if edges is not None:  # the end is an edge too: the angle there is exact
        edge_angle = np.interp(edges, t, a)
        t_b = float(edges[int(np.argmin(np.abs(edge_angle - target)))])
    else:
        t_b = float(np.interp(target, a, t))
    return t_a, t_b, n


def _checked(record: RigRecord, shaft_angle: float,
             options: Conditioning | None) -> tuple[RigRecord, float, Conditioning]:
    """The arguments of :func:`condition`, refused when of the wrong type or out of range, and the
    record when it is too short, has a dead transducer or absurd values."""
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
    return record, float(shaft_angle), options


def _shafts_turn_together(record: RigRecord, angles: dict[str, np.ndarray]) -> None:
    """A Cardan joint's output turns as far as its input (to within the Hooke error, under a
    quarter turn): refuse an output channel that says otherwise (dead, stuck or mis-scaled)."""
    turned = {s: abs(float(angles[s][-1] - angles[s][0])) / (2 * math.pi) for s in SHAFTS}
    if not 0.5 * turned["in"] - 0.25 <= turned["out"] <= 2.0 * turned["in"] + 0.25:
        channel = "speed_out" if "speed_out" in record.channels else "angle_out"
        raise RigDataError(f"the output shaft turns {turned['out']:.3g} revolutions while the input turns "
                           f"{turned['in']:.3g}: the shafts of a Cardan joint turn together (a dead, stuck "
                           "or mis-scaled transducer, or the wrong unit: --unit)", file=record.file,
                           channel=channel)


def condition(record: RigRecord, shaft_angle: float, options: Conditioning | None = None) -> Conditioned:
    """Condition a record (see the module docstring).

    Parameters
    ----------
    record : RigRecord
    shaft_angle : float
        The joint's shaft angle [rad] (for the phase estimate).
    options : Conditioning, optional
    """
    record, shaft_angle, options = _checked(record, shaft_angle, options)
    t = record.time
    dt = record.dt
    angles, edges = {}, {}
    for shaft in SHAFTS:
        angles[shaft], edges[shaft] = angle_on_grid(record, shaft)
    duration = t[-1] - t[0]
    mean_speed = abs(angles["in"][-1] - angles["in"][0]) / duration
    if mean_speed <= 0:
        raise RigDataError("the input shaft does not turn", file=record.file, channel="angle_in")
    _shafts_turn_together(record, angles)
    cutoff = options.cutoff_harmonics * mean_speed / (2 * math.pi)
    rate = 1.0 / dt
    filt = {name: lowpass(angles[s], cutoff, rate, options.filter_order)
            for name, s in (("angle_in", "in"), ("angle_out", "out"))}
    speeds, accel = {}, None
    for shaft in SHAFTS:
        w, a = derivatives(filt[f"angle_{shaft}"], dt, cutoff, options.derivative)
        measured = record.channels.get(f"speed_{shaft}")
        speeds[shaft] = lowpass(measured, cutoff, rate, options.filter_order) if measured is not None else w
        if shaft == "in":
            accel = a
    torques = {s: lowpass(record.channels[f"torque_{s}"], cutoff, rate, options.filter_order)
               for s in SHAFTS}
    t_a, t_b, n = _trim_to_revolutions(t, angles["in"], edges["in"], options.settle_revolutions,
                                       record.file)
    settle_time = options.settle_revolutions * 2 * math.pi / mean_speed
    keep = (t >= min(t_a, t[0] + settle_time) - 1e-12) & (t <= max(t_b, t[-1] - settle_time) + 1e-12)
    inside = (t >= t_a) & (t <= t_b)
    if options.phase is not None:
        phase_fit = {"phase": float(options.phase), "source": "given"}
    else:
        ratio = speeds["out"][inside] / speeds["in"][inside]
        phase_fit = estimate_phase(angles["in"][inside], ratio, shaft_angle)
    return Conditioned(
        t=t[keep], angle_in=filt["angle_in"][keep], angle_out=filt["angle_out"][keep],
        speed_in=speeds["in"][keep], speed_out=speeds["out"][keep], accel_in=accel[keep],
        torque_in=torques["in"][keep], torque_out=torques["out"][keep],
        raw_torque_in=np.asarray(record.channels["torque_in"])[keep],
        raw_torque_out=np.asarray(record.channels["torque_out"])[keep],
        window=(t_a, t_b), revolutions=n, phase=float(phase_fit["phase"]), phase_fit=phase_fit,
        cutoff=float(cutoff), settings=asdict(options))
