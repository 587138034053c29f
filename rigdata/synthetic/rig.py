"""A synthetic rig: the reference engine's joint measured by a model of the paper's transducers.

Motor speed ``w0 (1 + e1 cos th + e2 cos 2th)`` (the motion repeats each revolution, so the true
efficiency over whole revolutions is the engine's mean efficiency), constant brake torque and an optional
constant drag between the joint and the output transducer; torques get lag, offset, drift, noise,
quantisation; speeds are pulse counts or rpm. Files say they are synthetic.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass, replace

import numpy as np
from scipy import signal
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import CubicSpline

from cardan_exudyn import engines
from reference.engine.motion import input_motion
from reference.engine.options import ReferenceOptions
from reference.engine.table import columns_at
from reference.results.result import Result
from reference.scene.drives import AngleDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.load import Load
from reference.scene.mapping import replace as replace_field
from reference.scene.scene import Scene
from rigdata import files
from rigdata.conversion import to_si
from rigdata.record import ChannelSource, RigRecord
from rigdata.transducer import Transducer
from rigdata.units import parse_unit

__all__ = ["GENERATOR", "FORMATS", "EXTENSIONS", "MAX_SAMPLES", "RigSettings", "Truth", "motor_angle",
           "true_signals", "measure", "joint_scene", "metadata", "record", "write"]

GENERATOR = "rigdata.synthetic 1"
"""The ``generator`` label of every synthetic file (name and version of this model)."""
FORMATS = ("csv", "lvm", "tdms", "mat", "parquet", "mdf")
"""The file formats :func:`write` writes."""
EXTENSIONS = {"csv": ".csv", "lvm": ".lvm", "tdms": ".tdms", "mat": ".mat", "parquet": ".parquet",
              "mdf": ".mf4"}
"""The file extension of each format."""
#: The decimal mark each format is written with when :func:`write` is given none.
DECIMAL = {"csv": ".", "lvm": ","}


@dataclass(frozen=True)
class RigSettings:
    """What the synthetic rig runs and how it measures; a bad setting raises TypeError/ValueError.

    Attributes
    ----------
    scene : str
        Named scene or scene TOML file of the joint; its drive and load are replaced by motor and brake.
    shaft_angle_deg : float or None
        Shaft angle [deg]; None: the scene's.
    speed : float
        Mean input speed [rad/s].
    ripple : tuple of float
        Relative motor speed ripple at 1x and 2x the input angle [-].
    input_torque : float
        Target mean input torque [N m]; sets the brake torque unless ``load_torque`` is given.
    load_torque : float or None
        Constant brake torque on the output shaft [N m]; None: from ``input_torque``.
    friction : float or None
        Friction coefficient of every pair [-]; None: the scene's.
    revolutions : float
        Input revolutions recorded [-].
    rate : float
        Sampling rate [Hz].
    phase : float
        True input yoke angle when the pulse count starts [rad].
    noise : float
        Torque noise standard deviation [N m].
    lag : float
        Time constant of each torque output's first-order filter [s].
    offsets, drifts : tuple of float or None
        Offsets and zero drifts (input, output) [N m]; None: drawn within the transducer's limits.
    speed_channel : {"pulses", "rpm"}
        Pulse counts or a speed channel in rpm.
    torque_out_sign : {1, -1}
        Sign convention of the output torque column: -1 records the brake's torque as negative.
    drag_torque : float
        Constant drag [N m] between the joint's output and the output torque transducer (a seal, say),
        opposing the output rotation: the joint is loaded by brake + drag, the output transducer measures
        the brake torque only. A model-form error: a joint model driven by the measured output torque
        lacks it, so the measured efficiency is lower than such a model's, by ``drag / input_torque``
        over whole revolutions (more at low load).
    seed : int
        Seed of the drawn errors and the noise.
    """

    scene: str = "rig"
    shaft_angle_deg: float | None = None
    speed: float = 6.0
    ripple: tuple = (0.01, 0.005)
    input_torque: float = 0.2
    load_torque: float | None = None
    friction: float | None = None
    revolutions: float = 5.0
    rate: float = 1000.0
    phase: float = 0.7
    noise: float = 0.005
    lag: float = 5e-4
    offsets: tuple | None = None
    drifts: tuple | None = None
    speed_channel: str = "pulses"
    torque_out_sign: int = 1
    drag_torque: float = 0.0
    seed: int = 1

    def __post_init__(self) -> None:
        self._check_types()
        if not math.isfinite(self.phase):
            raise ValueError(f"`phase` must be finite [rad], got {self.phase!r}")
        angle = self.shaft_angle_deg
        if angle is not None and (isinstance(angle, bool) or not isinstance(angle, (int, float))
                                  or not 0.0 <= angle < 90.0):
            raise ValueError(f"`shaft_angle_deg` must be in [0, 90) deg or None, got {angle!r:.80}")
        for name in ("speed", "input_torque", "revolutions", "rate"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"`{name}` must be positive, got {value!r}")
        for name in ("noise", "lag", "drag_torque"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ValueError(f"`{name}` must be >= 0, got {getattr(self, name)!r}")
        if self.speed_channel not in ("pulses", "rpm"):
            raise ValueError(f"`speed_channel` must be 'pulses' or 'rpm', got {self.speed_channel!r}")
        self._check_optional()
        self._check_size()

    def _check_optional(self) -> None:
        """ValueError for a load or friction that is not a positive/non-negative number, or a sign not +-1."""
        for name, low in (("load_torque", "positive"), ("friction", ">= 0")):
            value = getattr(self, name)
            if value is None:
                continue
            number = not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
            if not (number and math.isfinite(value) and (value > 0 or (low == ">= 0" and value == 0))):
                raise ValueError(f"`{name}` must be {low} or None, got {value!r:.80}")
        if isinstance(self.torque_out_sign, bool) or self.torque_out_sign not in (1, -1):
            raise ValueError(f"`torque_out_sign` must be 1 or -1, got {self.torque_out_sign!r:.80}")

    def _check_types(self) -> None:
        """TypeError/ValueError for a setting of the wrong type."""
        for name in ("speed", "input_torque", "revolutions", "rate", "phase", "noise", "lag", "drag_torque"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise TypeError(f"`{name}` must be a number, got {value!r:.80}")
        if not isinstance(self.scene, str):
            raise TypeError(f"`scene` must be a scene name, got {self.scene!r:.80}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) \
                or not 0 <= self.seed < 2**63:
            raise ValueError(f"`seed` must be an integer in [0, 2**63), got {self.seed!r:.80}")
        for name in ("ripple", "offsets", "drifts"):
            value = getattr(self, name)
            if (value is not None or name == "ripple") and not _pair_of_numbers(value):
                none = "" if name == "ripple" else " or None"
                raise ValueError(f"`{name}` must be two finite numbers [N m]{none}, got {value!r:.80}")

    def _check_size(self) -> None:
        """ValueError for less than one whole revolution after settling or over MAX_SAMPLES samples."""
        if self.revolutions < 1.6:
            raise ValueError(f"`revolutions` must be >= 1.6 (one whole revolution after settling), "
                             f"got {self.revolutions!r}")
        samples = self.revolutions * 2.0 * math.pi / self.speed * self.rate
        if samples > MAX_SAMPLES:
            raise ValueError(f"{self.revolutions:g} revolutions at {self.speed:g} rad/s and {self.rate:g} Hz "
                             f"are {samples:.3g} samples; at most {MAX_SAMPLES:.0e} are written")


def _pair_of_numbers(value: object) -> bool:
    """True for a sequence of two finite numbers (booleans excluded)."""
    return (isinstance(value, (tuple, list)) and len(value) == 2
            and all(not isinstance(v, bool) and isinstance(v, (int, float, np.integer, np.floating))
                    and math.isfinite(v) for v in value))


MAX_SAMPLES = 1_000_000
"""Most samples a synthetic record may have (the model is evaluated at every one of them)."""


@dataclass(frozen=True)
class Truth:
    """The true signals on the sampling grid and the true efficiency.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    angle_in, angle_out, speed_in, speed_out : ndarray, shape (n,)
        Shaft angles [rad] and speeds [rad/s].
    torque_in, torque_out : ndarray, shape (n,)
        Drive and brake torques [N m] (the torques the transducers see).
    efficiency : float
        Reference engine's mean efficiency over whole revolutions [-] (the joint's).
    brake_torque : float
        Constant brake torque [N m].
    drag_torque : float
        Constant drag between the joint and the output transducer [N m]; the joint's load is brake + drag.
    """

    t: np.ndarray
    angle_in: np.ndarray
    angle_out: np.ndarray
    speed_in: np.ndarray
    speed_out: np.ndarray
    torque_in: np.ndarray
    torque_out: np.ndarray
    efficiency: float
    brake_torque: float
    drag_torque: float = 0.0

    @property
    def brake_efficiency(self) -> float:
        """Brake over input work over whole revolutions [-]: what exact transducers measure (the joint's
        efficiency times brake / (brake + drag), the load being constant).
        """
        return self.efficiency * self.brake_torque / (self.brake_torque + self.drag_torque)


def motor_angle(settings: RigSettings, points_per_revolution: int = 240) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and input angles [rad] of a motor with speed ``w0 (1 + e1 cos th + e2 cos 2th)``.

    Angles start at the settings' phase and run half a revolution past the record;
    ``points_per_revolution`` knots per revolution.
    """
    e1, e2 = settings.ripple
    total = 2 * math.pi * (settings.revolutions + 0.5)
    theta = np.linspace(0.0, total, int((settings.revolutions + 0.5) * points_per_revolution) + 1)
    # t(theta) from d t / d theta = 1 / omega, integrated on a fine grid then sampled
    fine = np.linspace(0.0, total, 20 * theta.size)
    th_f = fine + settings.phase
    inv = 1.0 / (settings.speed * (1.0 + e1 * np.cos(th_f) + e2 * np.cos(2 * th_f)))
    t_fine = cumulative_trapezoid(inv, fine, initial=0.0)
    t = CubicSpline(fine, t_fine)(theta)
    return t, theta + settings.phase


def joint_scene(settings: RigSettings) -> Scene:
    """The settings' scene (name or TOML file) at their shaft angle and friction."""
    from rigdata.validation import as_scene  # rigdata.validation loads the report code

    changes = {}
    if settings.shaft_angle_deg is not None:
        changes["joint.geometry.shaft_angle_deg"] = settings.shaft_angle_deg
    if settings.friction is not None:
        changes.update({f"joint.pairs.{p}.friction_coefficient": settings.friction for p in PAIR_NAMES})
    base = as_scene(settings.scene)
    return replace_field(base, **changes) if changes else base


def _run(scene: Scene) -> Result:
    """The reference engine's run of ``scene``; ValueError when it fails."""
    result = engines.run(scene, "reference")
    if not result.success:
        raise ValueError(f"the synthetic rig's model does not run: {result.message}")
    return result


def _joint_load(scene: Scene, target: float) -> tuple[float, Result]:
    """Output load [N m] for a mean input torque ``target`` [N m], and the engine's run with it.

    Efficiency barely depends on load level, so one correction step suffices.
    """
    load = target
    for _ in range(2):
        load *= target / _run(replace(scene, load=Load(load))).summary.mean_torque_in
    return load, _run(replace(scene, load=Load(load)))


def _loads(scene: Scene, settings: RigSettings) -> tuple[float, float, Result]:
    """Joint load and brake torque [N m] (load = brake + drag) and the engine's run; ValueError when the
    drag leaves no brake torque for the settings' input torque.
    """
    drag = settings.drag_torque
    if settings.load_torque is not None:
        load = settings.load_torque + drag
        return load, settings.load_torque, _run(replace(scene, load=Load(load)))
    load, result = _joint_load(scene, settings.input_torque)
    if not load - drag > 0:
        raise ValueError(f"`drag_torque` {drag!r} N m leaves no brake torque: an input torque of "
                         f"{settings.input_torque:g} N m loads the joint with {load:.4g} N m in all")
    return load, load - drag, result


def true_signals(settings: RigSettings) -> Truth:
    """Reference engine on the rig driven by :func:`motor_angle` and loaded by brake + drag for the settings'
    input torque, sampled on the rig's grid.
    """
    t_knots, angle = motor_angle(settings)
    base = joint_scene(settings)
    scene = replace(base, drive=AngleDrive(tuple(t_knots), tuple(angle)),
                    revolutions=1.0, record=replace(base.record, timeseries=False))
    load, brake, result = _loads(scene, settings)
    scene = replace(scene, load=Load(load))
    t = np.arange(0.0, t_knots[-1] - 0.25 * 2 * math.pi / settings.speed, 1.0 / settings.rate)
    # the true signals on the rig's grid, from the engine's own closed-form input motion
    motion = input_motion(scene, ReferenceOptions())
    cols = columns_at(scene, motion, t)
    return Truth(t=t, angle_in=cols["theta_in"], angle_out=cols["theta_out"],
                 speed_in=cols["omega_in"], speed_out=cols["omega_out"],
                 torque_in=cols["torque_in"], torque_out=cols["torque_out"] - settings.drag_torque,
                 efficiency=float(result.mean_efficiency), brake_torque=float(brake),
                 drag_torque=float(settings.drag_torque))


def _errors(settings: RigSettings, transducer: Transducer,
            rng: np.random.Generator) -> tuple[tuple[float, float], tuple[float, float]]:
    """Offsets and zero drifts (input, output) [N m]: the settings', else drawn within the transducer's
    limits.
    """
    offsets = settings.offsets if settings.offsets is not None else \
        tuple(rng.uniform(-1, 1, 2) * transducer.accuracy_limit)
    drifts = settings.drifts if settings.drifts is not None else \
        tuple(rng.uniform(-1, 1, 2) * transducer.zero_drift)
    return tuple(float(x) for x in offsets), tuple(float(x) for x in drifts)


def _torque_volts(torque: np.ndarray, offset: float, drift: np.ndarray, settings: RigSettings,
                  transducer: Transducer, rng: np.random.Generator) -> np.ndarray:
    """One torque as the card reads it [V]: first-order lag, offset, drift, noise, sensitivity,
    range clip, quantisation.
    """
    if settings.lag > 0:
        b, a = signal.bilinear([1.0], [settings.lag, 1.0], fs=settings.rate)
        torque = signal.lfilter(b, a, torque, zi=signal.lfilter_zi(b, a) * torque[0])[0]
    measured = torque + offset + drift + rng.normal(0.0, settings.noise, torque.size)
    volts = np.clip(measured * transducer.sensitivity, -transducer.adc_range, transducer.adc_range)
    step = 2 * transducer.adc_range / 2 ** transducer.adc_bits
    return np.round(volts / step) * step


def measure(truth: Truth, settings: RigSettings,
            transducer: Transducer | None = None) -> tuple[dict, dict, dict]:
    """Apply the transducer model to the true signals.

    Parameters
    ----------
    truth : Truth
    settings : RigSettings
    transducer : Transducer, optional
        Default: :class:`Transducer`.

    Returns
    -------
    table : dict of str to ndarray
        Raw columns: ``Time`` [s], ``Torque In/Out`` [V], ``Pulses In/Out`` [counts] or ``Speed In/Out``
        [rpm].
    units : dict of str to str
        Each column's unit.
    used : dict
        Settings, drawn errors, encoder start, true phase, true efficiency of the joint
        (``true_efficiency``) and of brake over input (``true_brake_efficiency``), brake torque,
        transducer.
    """
    transducer = transducer or Transducer()
    rng = np.random.default_rng(settings.seed)
    offsets, drifts = _errors(settings, transducer, rng)
    t = truth.t
    ramp = (t - t[0]) / (t[-1] - t[0])
    table = {"Time": t - t[0]}
    units = {"Time": "s"}
    out = settings.torque_out_sign * truth.torque_out
    for k, (name, torque) in enumerate((("In", truth.torque_in), ("Out", out))):
        table[f"Torque {name}"] = _torque_volts(torque, offsets[k], drifts[k] * ramp, settings,
                                                transducer, rng)
        units[f"Torque {name}"] = "V"
    q = transducer.pulse_angle
    encoder_start = rng.uniform(0.0, q)  # where in a pulse interval the counter starts
    for name, angle, speed in (("In", truth.angle_in, truth.speed_in),
                               ("Out", truth.angle_out, truth.speed_out)):
        if settings.speed_channel == "pulses":
            counts = np.floor((angle - angle[0] + (encoder_start if name == "In" else 0.0)) / q)
            table[f"Pulses {name}"] = counts.astype(np.int64)
            units[f"Pulses {name}"] = "counts"
        else:
            table[f"Speed {name}"] = speed * 60.0 / (2 * math.pi) + rng.normal(0.0, 0.01, t.size)
            units[f"Speed {name}"] = "rpm"
    # at an input edge the count reaches k q where the true angle is k q + angle[0] - start
    true_phase = float(truth.angle_in[0] - (encoder_start if settings.speed_channel == "pulses" else 0.0))
    input_torque = None if settings.load_torque is not None else settings.input_torque
    used = {**asdict(settings), "input_torque": input_torque,
            "offsets": list(offsets), "drifts": list(drifts),
            "encoder_start": float(encoder_start), "true_phase": true_phase,
            "true_efficiency": truth.efficiency, "true_brake_efficiency": truth.brake_efficiency,
            "brake_torque": truth.brake_torque,
            "transducer": transducer.as_dict()}
    return table, units, used


def metadata(used: dict) -> dict:
    """Label of every synthetic file: ``synthetic``, ``generator``, ``settings`` (JSON of ``used``),
    ``description``.
    """
    return {"synthetic": "true", "generator": GENERATOR, "settings": json.dumps(used, sort_keys=True),
            "description": "SYNTHETIC rig data: reference-engine joint + transducer model, not a measurement"}


def record(settings: RigSettings | None = None, transducer: Transducer | None = None,
           truth: Truth | None = None) -> tuple[RigRecord, dict]:
    """A synthetic measurement as an in-memory record (SI units, provenance labelled synthetic).

    Parameters
    ----------
    settings : RigSettings, optional
    transducer : Transducer, optional
    truth : Truth, optional
        True signals already computed for ``settings``.

    Returns
    -------
    record : RigRecord
    used : dict
        As :func:`measure` returns it.
    """
    settings = settings or RigSettings()
    transducer = transducer or Transducer()
    truth = truth or true_signals(settings)
    table, units, used = measure(truth, settings, transducer)
    channels = {}
    sources = {}
    names = {"Torque": "torque", "Pulses": "angle", "Speed": "speed"}
    for column, values in table.items():
        if column == "Time":
            continue
        kind, side = column.split()
        unit = parse_unit(units[column], column=column)
        converted = to_si(values, unit, sensitivity=transducer.sensitivity,
                          pulses_per_rev=transducer.pulses_per_rev)
        channel = f"{names[kind]}_{side.lower()}"
        channels[channel] = converted.values
        sources[channel] = ChannelSource(column, units[column], converted.conversion, converted.quantum)
    prov = {"file": "<synthetic>", "format": "memory", "synthetic": metadata(used)}
    return RigRecord(table["Time"], channels, sources, prov), used


def write(path, fmt: str, settings: RigSettings | None = None, transducer: Transducer | None = None,
          truth: Truth | None = None, *, decimal: str | None = None) -> dict:
    """Write a synthetic measurement file labelled as such; return ``used`` (:func:`measure`).

    Parameters
    ----------
    path : str or path-like
        The file (replaced atomically).
    fmt : {"csv", "lvm", "tdms", "mat", "parquet", "mdf"}
        ``mat`` is MATLAB v5 (scipy), ``parquet`` needs pyarrow, ``mdf`` (ASAM MDF 4, ``.mf4``) asammdf.
    settings, transducer, truth : optional
        As for :func:`record`.
    decimal : {".", ","}, optional
        Decimal mark of ``csv`` (``","``: fields apart by ``;``) and ``lvm``; None: ``.`` for csv, ``,``
        for lvm. The other formats store numbers, not text, and take none.
    """
    _check_write(path, fmt, decimal, settings, transducer, truth)
    settings = settings or RigSettings()
    truth = truth or true_signals(settings)
    table, units, used = measure(truth, settings, transducer)
    meta = metadata(used)
    mark = decimal or DECIMAL.get(fmt)
    if fmt == "csv":
        files.write_csv(path, table, units, meta, sep=";" if mark == "," else ",", decimal=mark)
    elif fmt == "lvm":
        files.write_lvm(path, table, units, meta, decimal=mark)
    else:
        writers = {"tdms": files.write_tdms, "mat": files.write_mat, "parquet": files.write_parquet,
                   "mdf": files.write_mdf}
        writers[fmt](path, table, units, meta)
    return used


def _check_write(path: object, fmt: object, decimal: object, settings: object, transducer: object,
                 truth: object) -> None:
    """TypeError/ValueError naming the argument of :func:`write` that is wrong."""
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise TypeError(f"`path` must be a str or path naming the file to write, got {path!r:.80}")
    if not isinstance(fmt, str) or fmt not in FORMATS:
        raise ValueError(f"`fmt` must be one of {FORMATS}, got {fmt!r:.80}")
    if decimal is not None and (fmt not in DECIMAL or decimal not in (".", ",")):
        raise ValueError(f"`decimal` must be '.' or ',' for csv and lvm and None for the other formats, "
                         f"got {decimal!r:.80} for {fmt}")
    for name, value, cls in (("settings", settings, RigSettings), ("transducer", transducer, Transducer),
                             ("truth", truth, Truth)):
        if value is not None and not isinstance(value, cls):
            raise TypeError(f"`{name}` must be a {cls.__name__} or None, got {type(value).__name__}")

