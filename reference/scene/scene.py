"""The scene: one plain, validated description of a Cardan-joint simulation for every engine.

A scene is a tree of frozen dataclasses, SI units and radians inside: the joint
(:mod:`reference.scene.joint`), its drive, load, gravity, span, numerics, friction coupling and what to
record. It loads from and dumps to plain dictionaries (and so TOML / JSON): unknown keys are
rejected, angles, speeds and lengths may be given at the boundary with unit suffixes
(``shaft_angle_deg``, ``speed_rpm``, ``a1_mm``, :data:`UNIT_ALIASES`). The dictionary form lives
here because :func:`replace`, which the paper's scenes (:mod:`reference.paper.paper`) are built with,
goes through it; reading TOML files and starting from a named scene (``base = "paper"``), which
needs the paper, is :mod:`reference.scene.files`, one level up.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Union

import numpy as np

from reference.scene.histories import CubicPieces, LinearHistory, first_turn, largest_slope
from reference.scene.joint import PAIR_NAMES, Body, Geometry, Joint, MountingErrors, Pair, Pairs
from reference.scene.validation import (
    DEG,
    MAX_STEPS,
    RPM,
    SceneError,
    check_history,
    finite,
    float_array,
    is_sequence,
    non_negative,
    positive,
    require_instance,
    require_scene,
    set_field,
    vector,
)

MAX_ITERATIONS = 10_000
"""Most friction updates per step ``FrictionSettings.max_iterations`` may ask for."""

UNIT_ALIASES = {
    "shaft_angle": ("_deg", DEG),
    "speed": ("_rpm", RPM),
    "initial_speed": ("_rpm", RPM),
    **{f"a{k}": ("_mm", 1e-3) for k in range(1, 5)},
    **{f"alpha{k}": ("_deg", DEG) for k in range(1, 5)},
    "s1": ("_mm", 1e-3),
}
"""Fields that accept a unit-suffixed alias at the boundary: name -> (suffix, factor to SI)."""


@dataclass(frozen=True)
class SpeedDrive:
    """Input shaft held at constant angular speed ``speed`` [rad/s] (non-zero), from angle 0."""

    speed: float
    kind: str = field(default="speed", init=False)

    def __post_init__(self) -> None:
        speed = finite("speed", self.speed)
        if speed == 0.0:
            raise SceneError("`speed` of a constant-speed drive must be non-zero, got 0.0")
        set_field(self, "speed", speed)

    def max_speed(self) -> float:
        """The drive's speed magnitude [rad/s]."""
        return abs(self.speed)


@dataclass(frozen=True)
class AngleDrive:
    """Input angle prescribed by a history, interpolated by a C2 cubic spline.

    Attributes
    ----------
    time : tuple of float
        Sample times [s], strictly increasing, at least 4 samples. The run starts at the first
        (engines run on a clock that starts there: :func:`reference.scene.histories.run_clock`), so
        a history may start at any time.
    angle : tuple of float
        Input angle at those times [rad].
    """

    time: tuple
    angle: tuple
    kind: str = field(default="angle", init=False)

    def __post_init__(self) -> None:
        t = float_array("`time`", self.time)
        a = float_array("`angle`", self.angle)
        check_history(t, a, self.time, self.angle, "angle", minimum=4)
        set_field(self, "time", tuple(t.tolist()))
        set_field(self, "angle", tuple(a.tolist()))

    def spline(self) -> Any:
        """The history as a ``scipy.interpolate.CubicSpline``: angle [rad] of time [s] (built once,
        then cached)."""
        cached = self.__dict__.get("_spline")
        if cached is None:
            from scipy.interpolate import CubicSpline  # scipy.interpolate takes ~1 s to import

            cached = CubicSpline(np.asarray(self.time), np.asarray(self.angle))
            object.__setattr__(self, "_spline", cached)
        return cached

    def evaluator(self) -> CubicPieces:
        """The spline at one instant in plain floats, O(log n) per call (engines' user
        functions; :class:`reference.scene.histories.CubicPieces`)."""
        return CubicPieces(self.spline())

    def shifted(self, origin: float) -> AngleDrive:
        """The same history on a clock that reads ``t - origin`` [s]."""
        return AngleDrive(tuple((np.asarray(self.time) - origin).tolist()), self.angle)

    def max_speed(self) -> float:
        """Largest input speed of the history [rad/s] (exact, from the spline's pieces)."""
        return largest_slope(self.spline())

    def time_to_turn(self, angle: float) -> float:
        """First time [s] at which the input has turned ``angle`` [rad] either way from its
        start, to rounding; the history's last time if it never turns that far."""
        t = first_turn(self.spline(), angle)
        return float(self.time[-1]) if t is None else t


@dataclass(frozen=True)
class TorqueDrive:
    """Constant torque ``torque`` [N m] on the input shaft about its axis, free speed.

    ``initial_speed`` [rad/s] is the input speed at t = 0 (non-zero so that the time span, given in
    revolutions, is finite).
    """

    torque: float
    initial_speed: float
    kind: str = field(default="torque", init=False)

    def __post_init__(self) -> None:
        set_field(self, "torque", finite("torque", self.torque))
        speed = finite("initial_speed", self.initial_speed)
        if speed == 0.0:
            raise SceneError("`initial_speed` of a torque drive must be non-zero, got 0.0")
        set_field(self, "initial_speed", speed)

    def max_speed(self) -> float:
        """The initial speed's magnitude [rad/s] (the speed engines size their steps for)."""
        return abs(self.initial_speed)

    def time_allowed(self, angle: float) -> float:
        """Time [s] every engine allows the drive to turn ``angle`` [rad]: four times the time
        at the initial speed (the joint may decelerate); engines stop earlier once it has."""
        return 4.0 * angle / abs(self.initial_speed)


Drive = Union[SpeedDrive, AngleDrive, TorqueDrive]  # noqa: UP007 (runtime alias, py3.10)
DRIVES = {"speed": SpeedDrive, "angle": AngleDrive, "torque": TorqueDrive}


@dataclass(frozen=True)
class Load:
    """Resisting torque on the output shaft [N m]; positive opposes positive output rotation.

    Attributes
    ----------
    torque : float or tuple of float
        A constant torque [N m], or with ``time`` its history: one value per sample,
        interpolated linearly in between and held at the end values outside (a measured brake
        torque, :mod:`rigdata`; linear so that the load never overshoots its samples).
    time : tuple of float or None
        Sample times [s] of a torque history, strictly increasing, at least 2. The load shares
        the scene's clock with an angle history (the run starts at the angle history's first
        sample); with any other drive the run starts at the load history's first sample
        (:func:`reference.scene.histories.time_origin`), so histories may start at any time.
    """

    torque: float | tuple = 0.0
    time: tuple | None = None

    def __post_init__(self) -> None:
        if self.time is None:
            if is_sequence(self.torque):
                raise SceneError("a torque history (`torque` as a list) needs `time`, one per value")
            set_field(self, "torque", finite("torque", self.torque))
            return
        t = float_array("load `time`", self.time)
        v = float_array("load `torque`", self.torque)
        check_history(t, v, self.time, self.torque, "torque", minimum=2, prefix="load ")
        set_field(self, "time", tuple(t.tolist()))
        set_field(self, "torque", tuple(v.tolist()))

    @property
    def constant(self) -> bool:
        """True for a constant torque, False for a history."""
        return self.time is None

    def at(self, t: Any) -> np.ndarray:
        """Load torque [N m] at the instants ``t`` [s] (any shape)."""
        if self.time is None:
            return np.full(np.shape(t), self.torque)
        return self.evaluator().at(t)

    def evaluator(self) -> LinearHistory | None:
        """A history at one instant in plain floats, O(log n) per call (engines' user
        functions; :class:`reference.scene.histories.LinearHistory`, built once); None when constant."""
        if self.time is None:
            return None
        cached = self.__dict__.get("_history")
        if cached is None:
            cached = LinearHistory(self.time, self.torque)
            object.__setattr__(self, "_history", cached)
        return cached

    def shifted(self, origin: float) -> Load:
        """The same load on a clock that reads ``t - origin`` [s] (a constant: itself)."""
        if self.time is None:
            return self
        return Load(self.torque, tuple((np.asarray(self.time) - origin).tolist()))

    @property
    def knots(self) -> np.ndarray:
        """Instants [s] where a history's slope changes (empty for a constant torque)."""
        return np.zeros(0) if self.time is None else self.evaluator().time

    def mean(self) -> float:
        """The constant torque, or the time average of the history [N m]."""
        if self.time is None:
            return float(self.torque)
        from scipy.integrate import trapezoid  # scipy.integrate takes ~0.5 s to import

        t = np.asarray(self.time)
        return float(trapezoid(np.asarray(self.torque), t) / (t[-1] - t[0]))


@dataclass(frozen=True)
class Numerics:
    """Engine-independent accuracy settings.

    Attributes
    ----------
    dt : float or None
        Time step [s]; None lets the engine choose it from ``accuracy`` and the scene.
    accuracy : float
        Target absolute error of the mean efficiency [-] (the headline number), also the target
        relative error of omega_out/omega_in. A time-stepping engine chooses its step to meet
        both when ``dt`` is None, and every run reports its estimated mean-efficiency error
        (``Summary.efficiency_error_estimate``, ``accuracy_met``; ``docs/accuracy.md``).
    richardson : bool
        Time stepping at ``h`` and ``h / 2``, extrapolated (``docs/bench.md``); reference: ignored.
    """

    dt: float | None = None
    accuracy: float = 1e-3
    richardson: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.richardson, bool):
            raise SceneError(f"`richardson` must be true or false, got {self.richardson!r}")
        if self.dt is not None:
            set_field(self, "dt", positive("dt", self.dt))
        acc = positive("accuracy", self.accuracy)
        if acc >= 1.0:
            raise SceneError(f"`accuracy` must be < 1, got {acc!r}")
        set_field(self, "accuracy", acc)


COUPLINGS = ("converged", "lagged", "uncoupled", "extrapolated")
FRICTION_LAWS = ("paper", "resultant")
DEFAULT_SIGN_BAND_RELATIVE = 1e-3
"""Default ``FrictionSettings.sign_band_relative`` [-] (``docs/paper.md``, "Friction at every speed")."""


@dataclass(frozen=True)
class FrictionSettings:
    """How the friction of eqs. (1)-(5) is coupled to the reactions and regularised.

    Attributes
    ----------
    coupling : str
        ``"extrapolated"`` (default): one Newton solve per step, the law on extrapolated inputs
        (``cardan_exudyn.model.coupling``); ``"converged"``: within each time step, friction and
        reactions are iterated to a fixed point (the friction of the step's own reactions);
        ``"lagged"``: the paper's scheme (section 3.1), the reactions at the end of a step set the
        friction applied during the next step; ``"uncoupled"``: friction is *not* applied to the
        dynamics, eqs. (3), (5) are evaluated on the frictionless reactions and their power is
        the loss (a first-order estimate, used to explain the paper's tolerance figure; the energy
        balance then misses the loss). The reference solves the fixed point for the others.
    sign_band : float or None
        One absolute ramp width [m/s] for every pair: below it ``sign()`` of eqs. (3), (5) is
        replaced by a linear ramp ``clip(v / sign_band, -1, 1)`` of the relative surface speed
        ``v`` (``omega_rel d / 2`` for the rotation of a journal, the sliding speed for axial
        friction); 0 means the exact sign. None (default): the relative band below.
    sign_band_relative : float or None
        Ramp width of each pair as a fraction of the pair's characteristic speed [-] (its RMS
        surface, or sliding, speed over an input revolution at the drive's speed;
        :func:`reference.physics.bands.sign_bands`), so that the regularisation removes the same share
        of friction at every speed; 0 means the exact sign. None: 1e-3
        (:data:`DEFAULT_SIGN_BAND_RELATIVE`) unless ``sign_band`` is given. Give at most
        one of the two.
    tolerance : float
        Converged coupling: the fixed point is accepted when the largest change of a friction
        load is below ``tolerance`` times the largest friction load (forces counted as the
        torque they make at the journal radius, ``F d / 2``).
    max_iterations : int
        Converged coupling: friction updates per step before the step is declared not converged.
    law : str
        Direction of the friction of a pair that rotates and slides (a cylindrical pair of a joint
        with mounting errors). ``"paper"`` (default): eqs. (3), (5) as written, a Coulomb torque
        ``-s(omega_rel d/2) f (d/2) N`` about the axis and, independently, a Coulomb force
        ``-s(v_slide) f N`` along it, ``N = |F| + 2 |M| / L`` (the full load in both directions at
        once). ``"resultant"``: one Coulomb force ``f N`` opposing the resultant slip velocity
        ``v = (omega_rel d/2, v_slide)`` of the contact, regularised as a vector,
        ``-f N v / max(|v|, band)``: torque ``(d/2)`` times its circumferential, axial force its
        axial component (:func:`reference.physics.bands.sign_bands`, ``resultant`` band). Both laws agree
        for a revolute pair and a pair that does not slide (``docs/scenes.md``, "Friction law").
    """

    coupling: str = "extrapolated"
    sign_band: float | None = None
    sign_band_relative: float | None = None
    tolerance: float = 1e-6
    max_iterations: int = 20
    law: str = "paper"

    def __post_init__(self) -> None:
        if not isinstance(self.coupling, str) or self.coupling not in COUPLINGS:
            raise SceneError(f"`coupling` must be one of {list(COUPLINGS)}, got {self.coupling!r}")
        if not isinstance(self.law, str) or self.law not in FRICTION_LAWS:
            raise SceneError(f"`law` must be one of {list(FRICTION_LAWS)}, got {self.law!r:.80}")
        if self.sign_band is not None and self.sign_band_relative is not None:
            raise SceneError(
                f"give either `sign_band` (absolute, m/s) or `sign_band_relative` (fraction of each "
                f"pair's speed), not both; got {self.sign_band!r} and {self.sign_band_relative!r}")
        for name in ("sign_band", "sign_band_relative"):
            if getattr(self, name) is not None:
                set_field(self, name, non_negative(name, getattr(self, name)))
        tol = positive("tolerance", self.tolerance)
        if tol >= 1.0:
            raise SceneError(f"`tolerance` must be < 1, got {tol!r}")
        set_field(self, "tolerance", tol)
        if (isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int)
                or not 2 <= self.max_iterations <= MAX_ITERATIONS):
            raise SceneError(f"`max_iterations` must be an integer in [2, {MAX_ITERATIONS}], "
                             f"got {self.max_iterations!r:.40}")

    @property
    def relative_band(self) -> float | None:
        """The relative ramp width in effect [-]: ``sign_band_relative``, its default 1e-3, or
        None when the absolute ``sign_band`` is given."""
        if self.sign_band is not None:
            return None
        return DEFAULT_SIGN_BAND_RELATIVE if self.sign_band_relative is None else self.sign_band_relative


@dataclass(frozen=True)
class Record:
    """What to record.

    Attributes
    ----------
    timeseries : bool
        Return the time table; when False only the summary is produced.
    every : int
        Keep every n-th step in the time table (the summary always uses every step).
    skip_revolutions : float
        Input revolutions at the start excluded from the mean values [-], >= 0.
    """

    timeseries: bool = True
    every: int = 1
    skip_revolutions: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.timeseries, bool):
            raise SceneError(f"`timeseries` must be true or false, got {self.timeseries!r}")
        if isinstance(self.every, bool) or not isinstance(self.every, int) \
                or not 1 <= self.every <= MAX_STEPS:
            raise SceneError(f"`every` must be an integer in [1, {MAX_STEPS}], got {self.every!r:.40}")
        set_field(self, "skip_revolutions", non_negative("skip_revolutions", self.skip_revolutions))


@dataclass(frozen=True)
class Scene:
    """A complete simulation case: joint, drive, load, gravity, span, numerics, recording.

    Attributes
    ----------
    revolutions : float
        Simulated span in input revolutions [-] (>= 1 + ``record.skip_revolutions`` so that at
        least one whole revolution is averaged).
    gravity : tuple, shape (3,)
        Gravitational acceleration in the global frame [m/s^2].
    parameter_set : str
        The paper's parameter set the scene was built with (:data:`reference.paper.paper.PARAMETER_SETS`,
        ``"custom"`` for values given by hand), or ``""`` for a scene that is not the paper's;
        every result carries it, and ``cardan run`` prints it.
    """

    joint: Joint
    drive: Drive
    load: Load = field(default_factory=Load)
    gravity: tuple = (0.0, 0.0, -9.81)
    revolutions: float = 2.0
    numerics: Numerics = field(default_factory=Numerics)
    friction: FrictionSettings = field(default_factory=FrictionSettings)
    record: Record = field(default_factory=Record)
    name: str = "scene"
    description: str = ""
    parameter_set: str = ""

    def __post_init__(self) -> None:
        require_instance("joint", self.joint, Joint, "a Joint")
        require_instance("drive", self.drive, (SpeedDrive, AngleDrive, TorqueDrive),
                         "a speed, angle or torque drive (SpeedDrive, AngleDrive, TorqueDrive)")
        for name, cls in (("load", Load), ("numerics", Numerics), ("friction", FrictionSettings),
                          ("record", Record)):
            require_instance(name, getattr(self, name), cls, f"a {cls.__name__}")
        for name in ("name", "description", "parameter_set"):
            if not isinstance(getattr(self, name), str):
                raise SceneError(f"`{name}` must be a string, got {getattr(self, name)!r}")
        set_field(self, "gravity", vector("gravity", self.gravity, (3,)))
        revs = positive("revolutions", self.revolutions)
        if revs < 1.0 + self.record.skip_revolutions:
            raise SceneError(
                f"`revolutions` must be at least 1 + record.skip_revolutions "
                f"= {1.0 + self.record.skip_revolutions!r} (one whole revolution to average), "
                f"got {revs!r}"
            )
        set_field(self, "revolutions", revs)
        if isinstance(self.drive, AngleDrive):
            span = abs(self.drive.angle[-1] - self.drive.angle[0]) / (2 * math.pi)
            if span + 1e-9 < revs:
                raise SceneError(
                    f"`revolutions` = {revs!r} exceeds the {span:.4g} revolutions covered by the "
                    "prescribed angle history"
                )

    @property
    def has_friction(self) -> bool:
        """True when some pair has a non-zero friction coefficient."""
        return any(p.friction_coefficient > 0.0 for _, p in self.joint.pairs.items())

    @property
    def has_gravity(self) -> bool:
        """True when the gravity vector is not zero."""
        return any(g != 0.0 for g in self.gravity)


_SECTIONS: dict[type, dict[str, Any]] = {
    Scene: {"joint": Joint, "load": Load, "numerics": Numerics, "friction": FrictionSettings,
            "record": Record},
    Joint: {"input": Body, "spider": Body, "output": Body, "geometry": Geometry, "pairs": Pairs,
            "errors": MountingErrors},
    Pairs: {name: Pair for name in PAIR_NAMES},
}


def _to_si(data: dict[str, Any], names: set[str], where: str) -> None:
    """Replace the unit-suffixed keys of ``data`` (those of :data:`UNIT_ALIASES` that ``names``
    has) by their SI fields, in place."""
    for key in list(data):
        for base, (suffix, factor) in UNIT_ALIASES.items():
            if key == base + suffix and base in names:
                if base in data:
                    raise SceneError(f"[{where}] give either `{base}` or `{key}`, not both")
                value = data.pop(key)
                data[base] = finite(key, value) * factor if not is_sequence(value) else value


def _build(cls: type, data: Mapping[str, Any], path: str) -> Any:
    """An instance of the scene part ``cls`` from its table at dotted ``path`` ("" for the scene)."""
    where = path or "scene"
    if not isinstance(data, Mapping):
        raise SceneError(f"[{where}] must be a table, got {data!r}")
    data = dict(data)
    names = {f.name for f in dataclasses.fields(cls) if f.init}
    _to_si(data, names, where)
    unknown = sorted(set(data) - names - {"kind"})
    if unknown:
        raise SceneError(f"[{where}] unknown key(s) {unknown}; allowed: {_allowed_keys(cls, names)}")
    kwargs = {}
    for key, value in data.items():
        if key == "kind":
            continue
        sub = _SECTIONS.get(cls, {}).get(key)
        if key == "drive" and cls is Scene:
            kwargs[key] = _build_drive(value, f"{path}.drive".lstrip("."))
        elif sub is not None:
            kwargs[key] = _build(sub, value, f"{path}.{key}".lstrip("."))
        else:
            kwargs[key] = value
    missing = sorted(f.name for f in dataclasses.fields(cls) if f.init and f.name not in kwargs
                     and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
    if missing:
        raise SceneError(f"[{where}] missing required key(s) {missing}"
                         + (" (or start from a named scene with `base = \"paper\"`)" if cls is Scene else ""))
    try:
        return cls(**kwargs)
    except (SceneError, TypeError) as exc:  # TypeError: a value of the wrong kind for a field
        raise SceneError(f"[{where}] {exc}") from None


def _allowed_keys(cls: type, names: set[str]) -> list[str]:
    """The keys a table of ``cls`` takes, for messages: its fields, their unit-suffixed aliases
    and, for a drive, ``kind``."""
    aliases = {base + suffix for base, (suffix, _) in UNIT_ALIASES.items() if base in names}
    return sorted(names | aliases | ({"kind"} if cls in DRIVES.values() else set()))


def _build_drive(data: Mapping[str, Any], path: str) -> Drive:
    """The drive of the kind its table names (``kind = "speed" | "angle" | "torque"``)."""
    if not isinstance(data, Mapping):
        raise SceneError(f"[{path}] must be a table, got {data!r}")
    kind = data.get("kind")
    if kind not in DRIVES:
        raise SceneError(f"[{path}] `kind` must be one of {sorted(DRIVES)}, got {kind!r}")
    return _build(DRIVES[kind], data, path)


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """Build and validate a scene from a (TOML-shaped) dictionary; unknown keys are errors.

    Parameters
    ----------
    data : Mapping
        Tables and values as in a scene TOML file: SI units, or the unit-suffixed aliases of
        :data:`UNIT_ALIASES` (``shaft_angle_deg``, ``speed_rpm``, ...). A named ``base`` is not
        resolved here (:func:`reference.scene.files.scene_from_mapping` does).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        An unknown, missing or invalid key; the message names its table and the value.
    """
    return _build(Scene, data, "")


def scene_to_dict(obj: Any) -> Any:
    """The fully resolved scene (or part) as plain JSON/TOML-ready data, SI units.

    Dataclasses become dictionaries (fields that are None are left out) and tuples lists;
    :func:`scene_from_dict` reads the result back to an equal scene.
    """
    if dataclasses.is_dataclass(obj):
        out = {}
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if value is None:
                continue
            out[f.name] = scene_to_dict(value)
        return out
    if isinstance(obj, tuple):
        return [scene_to_dict(v) for v in obj]
    return obj


def replace(scene: Scene, **changes: Any) -> Scene:
    """Copy of ``scene`` with dotted-path fields changed, validated again.

    Example: ``replace(scene, **{"joint.geometry.shaft_angle": 0.2, "load.torque": 1.0})``.
    Unknown leaf names are rejected by the validation of the rebuilt scene.

    Parameters
    ----------
    scene : Scene
    **changes
        Dotted field path to new value, SI units (or a unit-suffixed alias of
        :data:`UNIT_ALIASES` as the leaf, e.g. ``"joint.geometry.shaft_angle_deg"``).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        An unknown path or an invalid value.
    """
    data = scene_to_dict(require_scene(scene))
    for dotted, value in changes.items():
        node = data
        *parents, leaf = dotted.split(".")
        if not all(parents) or not leaf:
            raise SceneError(f"unknown scene field {dotted!r}")
        for key in parents:
            if not isinstance(node.get(key), dict):
                raise SceneError(f"unknown scene field {dotted!r}")
            node = node[key]
        for base, (suffix, _) in UNIT_ALIASES.items():
            if leaf == base + suffix:
                node.pop(base, None)
        node[leaf] = value
    return scene_from_dict(data)
