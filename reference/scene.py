"""The scene: one plain, validated description of a Cardan-joint simulation for every engine.

A scene is a tree of frozen dataclasses, SI units and radians inside. It loads from and dumps to
plain dictionaries (and so TOML / JSON); unknown keys are rejected, angles and speeds may be given
at the boundary with unit suffixes (``shaft_angle_deg``, ``speed_rpm``).

Conventions (used by every engine, documented in README "Conventions")
-----------------------------------------------------------------------
Global frame: origin at the joint centre (spider centre), x along the input shaft axis pointing
towards the joint, gravity given as a global vector. The output shaft axis is
``(cos(beta), sin(beta), 0)`` with ``beta`` the shaft angle, so the joint bends in the x-y plane.

Canonical body frames (all with origin at the joint centre; they coincide with the global frame
at input angle 0, except the output's, which is rotated by ``beta`` about global z):

- ``input``: x along the input axis (towards the joint), y along the input yoke's trunnion axis.
- ``spider``: y along the arm held by the input yoke, z along the arm held by the output yoke.
- ``output``: x along the output axis (away from the joint), z along the output yoke's trunnions.

A :class:`Body` gives its mass properties in its own *local* frame (for the paper, Table 1's
frames), placed in the canonical frame by ``local_origin`` and ``local_axes``.

Pairs, in chain order, each between a body ``a`` and a body ``b``:
``frame_input`` (revolute, ground -> input), ``input_spider`` (cylindrical, input -> spider),
``spider_output`` (cylindrical, spider -> output), ``output_frame`` (cylindrical, output -> ground).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Union

import numpy as np

from reference.inertia import inertia_problems, rotate_inertia, shift_inertia_to_com

BODY_NAMES = ("input", "spider", "output")
PAIR_NAMES = ("frame_input", "input_spider", "spider_output", "output_frame")
PAIR_KIND = {
    "frame_input": "revolute",
    "input_spider": "cylindrical",
    "spider_output": "cylindrical",
    "output_frame": "cylindrical",
}
PAIR_BODIES = {
    "frame_input": ("ground", "input"),
    "input_spider": ("input", "spider"),
    "spider_output": ("spider", "output"),
    "output_frame": ("output", "ground"),
}

RPM = 2.0 * math.pi / 60.0
DEG = math.pi / 180.0
# Fields that accept a unit-suffixed alias at the boundary: name -> (suffix, factor to SI).
_UNIT_ALIASES = {
    "shaft_angle": ("_deg", DEG),
    "speed": ("_rpm", RPM),
    "initial_speed": ("_rpm", RPM),
    **{f"a{k}": ("_mm", 1e-3) for k in range(1, 5)},
    **{f"alpha{k}": ("_deg", DEG) for k in range(1, 5)},
    "s1": ("_mm", 1e-3),
}


class SceneError(ValueError):
    """A scene (or one of its parts) is invalid; the message names the field and the value."""


def _finite(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise SceneError(f"`{name}` must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(f"`{name}` must be finite, got {value!r}")
    return value


def _positive(name: str, value: Any) -> float:
    value = _finite(name, value)
    if value <= 0.0:
        raise SceneError(f"`{name}` must be positive, got {value!r}")
    return value


def _non_negative(name: str, value: Any) -> float:
    value = _finite(name, value)
    if value < 0.0:
        raise SceneError(f"`{name}` must be >= 0, got {value!r}")
    return value


def _vector(name: str, value: Any, shape: tuple[int, ...]) -> tuple:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"`{name}` must be numeric with shape {shape}, got {value!r}") from None
    if arr.shape != shape:
        raise SceneError(f"`{name}` must have shape {shape}, got shape {arr.shape}: {value!r}")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"`{name}` must be finite, got {value!r}")
    return tuple(map(tuple, arr.tolist())) if arr.ndim == 2 else tuple(arr.tolist())  # Python floats


def _float_array(name: str, value: Any) -> np.ndarray | None:
    """A sequence as a float array (None when ``value`` is not a sequence); a sample that is not
    a number is a :class:`SceneError` naming ``name``."""
    if not _is_seq(value):
        return None
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be numbers, got {value!r}") from None


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class Body:
    """Mass properties of one moving body.

    Attributes
    ----------
    mass : float
        Mass [kg], positive.
    inertia : tuple, shape (3, 3)
        Inertia tensor in the local frame [kg m^2], about the point named by ``inertia_about``.
    inertia_about : {"com", "origin"}
        Reference point of ``inertia``: the centre of mass or the local frame's origin.
    com : tuple, shape (3,)
        Centre of mass in the local frame [m].
    local_origin : tuple, shape (3,)
        Position of the local frame's origin in the canonical body frame [m].
    local_axes : tuple, shape (3, 3)
        Rotation matrix whose columns are the local x, y, z axes in canonical coordinates.
    """

    mass: float
    inertia: tuple
    inertia_about: str = "com"
    com: tuple = (0.0, 0.0, 0.0)
    local_origin: tuple = (0.0, 0.0, 0.0)
    local_axes: tuple = _IDENTITY

    def __post_init__(self) -> None:
        _set(self, "mass", _positive("mass", self.mass))
        _set(self, "inertia", _vector("inertia", self.inertia, (3, 3)))
        _set(self, "com", _vector("com", self.com, (3,)))
        _set(self, "local_origin", _vector("local_origin", self.local_origin, (3,)))
        _set(self, "local_axes", _vector("local_axes", self.local_axes, (3, 3)))
        if self.inertia_about not in ("com", "origin"):
            raise SceneError(
                f"`inertia_about` must be 'com' or 'origin', got {self.inertia_about!r}"
            )
        r = np.asarray(self.local_axes)
        if np.max(np.abs(r.T @ r - np.eye(3))) > 1e-9 or np.linalg.det(r) < 0:
            raise SceneError(f"`local_axes` must be a proper rotation matrix, got {self.local_axes!r}")
        problems = inertia_problems(self.centroidal_inertia_local())
        if problems:
            raise SceneError(
                f"`inertia` (about the centre of mass) is not physical: {'; '.join(problems)}; "
                f"got {self.inertia!r} about {self.inertia_about}"
            )

    def centroidal_inertia_local(self) -> np.ndarray:
        """Inertia about the centre of mass in local axes [kg m^2]."""
        j = np.asarray(self.inertia)
        if self.inertia_about == "origin":
            j = shift_inertia_to_com(j, self.mass, np.asarray(self.com))
        return j

    def canonical(self) -> tuple[float, np.ndarray, np.ndarray]:
        """Mass [kg], centre of mass [m] and inertia about it [kg m^2] in the canonical frame."""
        r = np.asarray(self.local_axes)
        com = np.asarray(self.local_origin) + r @ np.asarray(self.com)
        return self.mass, com, rotate_inertia(self.centroidal_inertia_local(), r)


@dataclass(frozen=True)
class Pair:
    """Friction data of one kinematic pair (eqs. (1)-(5)).

    Attributes
    ----------
    friction_coefficient : float
        Coulomb coefficient f [-], >= 0; zero means the pair is frictionless.
    journal_diameter : float
        Journal diameter d [m] of eqs. (2), (3).
    moment_lever : float
        Lever L [m] that turns a bending moment into a couple of forces, eq. (1).
    """

    friction_coefficient: float = 0.0
    journal_diameter: float = 0.02
    moment_lever: float = 0.01

    def __post_init__(self) -> None:
        _set(self, "friction_coefficient", _non_negative("friction_coefficient", self.friction_coefficient))
        _set(self, "journal_diameter", _positive("journal_diameter", self.journal_diameter))
        _set(self, "moment_lever", _positive("moment_lever", self.moment_lever))


@dataclass(frozen=True)
class Pairs:
    """The four kinematic pairs of the RCCC joint, in chain order."""

    frame_input: Pair = field(default_factory=Pair)
    input_spider: Pair = field(default_factory=Pair)
    spider_output: Pair = field(default_factory=Pair)
    output_frame: Pair = field(default_factory=Pair)

    def items(self) -> list[tuple[str, Pair]]:
        return [(name, getattr(self, name)) for name in PAIR_NAMES]


MAX_SHAFT_ANGLE_DEG = 90.0


@dataclass(frozen=True)
class Geometry:
    """Joint geometry.

    Attributes
    ----------
    shaft_angle : float
        Angle beta between input and output shaft axes [rad], in [0, pi/2).
    input_bearing : float
        Distance from the joint centre to the frame-input bearing along the input axis [m].
    output_bearing : float
        Distance from the joint centre to the output-frame bearing along the output axis [m].
    arm_radius : float
        Spider arm radius: joint centre to the middle of each trunnion bearing [m].
    """

    shaft_angle: float = 0.0
    input_bearing: float = 0.1
    output_bearing: float = 0.1
    arm_radius: float = 0.012

    def __post_init__(self) -> None:
        beta = _finite("shaft_angle", self.shaft_angle)
        if not 0.0 <= beta < 0.5 * math.pi:
            raise SceneError(
                f"`shaft_angle` must be in [0, 90) deg, got {beta / DEG!r} deg ({beta!r} rad)"
            )
        _set(self, "shaft_angle", beta)
        _set(self, "input_bearing", _positive("input_bearing", self.input_bearing))
        _set(self, "output_bearing", _positive("output_bearing", self.output_bearing))
        _set(self, "arm_radius", _positive("arm_radius", self.arm_radius))

    def output_axis(self) -> np.ndarray:
        """Unit vector of the output shaft axis in the global frame."""
        return np.array([math.cos(self.shaft_angle), math.sin(self.shaft_angle), 0.0])


ERROR_NAMES = ("a1", "a2", "a3", "a4", "alpha1", "alpha2", "alpha3", "alpha4", "s1")
"""Fields of :class:`MountingErrors`, in the order the tolerance studies report them."""


@dataclass(frozen=True)
class MountingErrors:
    """Manufacturing and mounting errors as Denavit-Hartenberg parameter deviations (Figure 3).

    Links are numbered as the pairs they carry (:mod:`reference.rccc`): link 1 the input (from
    the ``frame_input`` axis to the ``input_spider`` axis), 2 the spider (to ``spider_output``),
    3 the output (to ``output_frame``), 4 the frame (from ``output_frame`` back to
    ``frame_input``). All zero is the ideal joint. At the boundary ``a<k>_mm``,
    ``alpha<k>_deg`` and ``s1_mm`` are accepted.

    Attributes
    ----------
    a1, a2, a3, a4 : float
        Offsets [m]: length of each link's common normal between its two pair axes (ideal 0:
        the axes intersect at the joint centre). The paper's tolerance case has
        ``a1 = a2 = a3 = 0.5 mm``.
    alpha1, alpha2, alpha3, alpha4 : float
        Twist errors [rad], added to the ideal twists (90, 90, 90, -shaft angle) deg: the
        paper's case has ``alpha1 = alpha2 = alpha3 = 6e-3 deg``.
    s1 : float
        Axial offset of the input along its axis [m] (moves the input and its yoke along x).
    """

    a1: float = 0.0
    a2: float = 0.0
    a3: float = 0.0
    a4: float = 0.0
    alpha1: float = 0.0
    alpha2: float = 0.0
    alpha3: float = 0.0
    alpha4: float = 0.0
    s1: float = 0.0

    def __post_init__(self) -> None:
        for name in ERROR_NAMES:
            _set(self, name, _finite(name, getattr(self, name)))
        for k in (1, 2, 3):
            twist = getattr(self, f"alpha{k}")
            if not abs(twist) < 0.5 * math.pi:
                raise SceneError(f"`alpha{k}` must be in (-90, 90) deg (the link's twist stays in "
                                 f"(0, 180) deg), got {twist / DEG!r} deg")

    @property
    def any(self) -> bool:
        """True when some error is non-zero (the joint is not ideal)."""
        return any(getattr(self, name) != 0.0 for name in ERROR_NAMES)


@dataclass(frozen=True)
class Joint:
    """The RCCC Cardan joint: three bodies, geometry, four pairs and the mounting errors."""

    input: Body
    spider: Body
    output: Body
    geometry: Geometry = field(default_factory=Geometry)
    pairs: Pairs = field(default_factory=Pairs)
    errors: MountingErrors = field(default_factory=MountingErrors)

    def __post_init__(self) -> None:
        twist = self.errors.alpha4 - self.geometry.shaft_angle
        if not abs(twist) < 0.5 * math.pi:
            raise SceneError(f"`errors.alpha4` minus the shaft angle (the frame's twist) must be in "
                             f"(-90, 90) deg, got {twist / DEG!r} deg")

    def bodies(self) -> list[tuple[str, Body]]:
        return [(name, getattr(self, name)) for name in BODY_NAMES]


@dataclass(frozen=True)
class SpeedDrive:
    """Input shaft held at constant angular speed ``speed`` [rad/s] (non-zero), from angle 0."""

    speed: float
    kind: str = field(default="speed", init=False)

    def __post_init__(self) -> None:
        speed = _finite("speed", self.speed)
        if speed == 0.0:
            raise SceneError("`speed` of a constant-speed drive must be non-zero, got 0.0")
        _set(self, "speed", speed)

    def max_speed(self) -> float:
        return abs(self.speed)


@dataclass(frozen=True)
class AngleDrive:
    """Input angle prescribed by a history, interpolated by a C2 cubic spline.

    Attributes
    ----------
    time : tuple of float
        Sample times [s], strictly increasing, at least 4 samples.
    angle : tuple of float
        Input angle at those times [rad].
    """

    time: tuple
    angle: tuple
    kind: str = field(default="angle", init=False)

    def __post_init__(self) -> None:
        t = _float_array("`time`", self.time)
        a = _float_array("`angle`", self.angle)
        if t is None or t.ndim != 1 or t.size < 4:
            raise SceneError(f"`time` must be a sequence of at least 4 numbers, got {self.time!r}")
        if a is None or a.shape != t.shape:
            raise SceneError(
                f"`angle` must have one value per time sample ({t.size}), got "
                f"{np.shape(self.angle) if a is not None else self.angle!r}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
            raise SceneError("`time` and `angle` must be finite")
        if np.any(np.diff(t) <= 0):
            i = int(np.argmax(np.diff(t) <= 0))
            raise SceneError(f"`time` must be strictly increasing, got {float(t[i])!r} "
                             f"then {float(t[i + 1])!r}")
        _set(self, "time", tuple(t.tolist()))
        _set(self, "angle", tuple(a.tolist()))

    def spline(self):
        from scipy.interpolate import CubicSpline

        return CubicSpline(np.asarray(self.time), np.asarray(self.angle))

    def max_speed(self) -> float:
        s = self.spline().derivative()
        t = np.linspace(self.time[0], self.time[-1], 20 * len(self.time))
        return float(np.max(np.abs(s(t))))

    def time_to_turn(self, angle: float) -> float:
        """First time [s] at which the input has turned ``angle`` [rad] either way from its
        start, to rounding; the history's last time if it never turns that far."""
        from scipy.optimize import brentq

        spline = self.spline()
        t0 = self.time[0]
        grid = np.linspace(t0, self.time[-1], 50 * len(self.time))
        turned = np.maximum.accumulate(np.abs(spline(grid) - spline(t0)))
        k = int(np.searchsorted(turned, angle))
        if k >= grid.size:
            return float(grid[-1])
        if k == 0:
            return float(t0)
        return float(brentq(lambda t: abs(spline(t) - spline(t0)) - angle, grid[k - 1], grid[k],
                            xtol=1e-15, rtol=4 * np.finfo(float).eps))


def _is_seq(x: Any) -> bool:
    return isinstance(x, (list, tuple, np.ndarray))


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
        _set(self, "torque", _finite("torque", self.torque))
        speed = _finite("initial_speed", self.initial_speed)
        if speed == 0.0:
            raise SceneError("`initial_speed` of a torque drive must be non-zero, got 0.0")
        _set(self, "initial_speed", speed)

    def max_speed(self) -> float:
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
        Sample times [s] of a torque history, strictly increasing, at least 2.
    """

    torque: float | tuple = 0.0
    time: tuple | None = None

    def __post_init__(self) -> None:
        if self.time is None:
            if _is_seq(self.torque):
                raise SceneError("a torque history (`torque` as a list) needs `time`, one per value")
            _set(self, "torque", _finite("torque", self.torque))
            return
        t = _float_array("load `time`", self.time)
        v = _float_array("load `torque`", self.torque)
        if t is None or t.ndim != 1 or t.size < 2:
            raise SceneError(f"load `time` must be a sequence of at least 2 numbers, got {self.time!r}")
        if v is None or v.shape != t.shape:
            raise SceneError(f"load `torque` must have one value per time sample ({t.size}), got "
                             f"{np.shape(self.torque) if v is not None else self.torque!r}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise SceneError("load `time` and `torque` must be finite")
        if np.any(np.diff(t) <= 0):
            i = int(np.argmax(np.diff(t) <= 0))
            raise SceneError(f"load `time` must be strictly increasing, got {float(t[i])!r} "
                             f"then {float(t[i + 1])!r}")
        _set(self, "time", tuple(t.tolist()))
        _set(self, "torque", tuple(v.tolist()))

    @property
    def constant(self) -> bool:
        """True for a constant torque, False for a history."""
        return self.time is None

    def at(self, t: Any) -> np.ndarray:
        """Load torque [N m] at the instants ``t`` [s] (any shape)."""
        if self.time is None:
            return np.full(np.shape(t), self.torque)
        return np.interp(t, self.time, self.torque)

    @property
    def knots(self) -> np.ndarray:
        """Instants [s] where a history's slope changes (empty for a constant torque)."""
        return np.zeros(0) if self.time is None else np.asarray(self.time)

    def mean(self) -> float:
        """The constant torque, or the time average of the history [N m]."""
        if self.time is None:
            return float(self.torque)
        from scipy.integrate import trapezoid

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
        Target for the maximum relative error of omega_out/omega_in [-] when ``dt`` is None.
    """

    dt: float | None = None
    accuracy: float = 1e-5

    def __post_init__(self) -> None:
        if self.dt is not None:
            _set(self, "dt", _positive("dt", self.dt))
        acc = _positive("accuracy", self.accuracy)
        if acc >= 1.0:
            raise SceneError(f"`accuracy` must be < 1, got {acc!r}")
        _set(self, "accuracy", acc)


MAX_STEPS = 10_000_000
"""Most time steps (or table rows) one run may take. More is refused as bad input by every engine
before it starts: e.g. ``dt = 1e-12`` s would take days and more memory than a machine has."""


def check_steps(steps: float, what: str) -> None:
    """Raise :class:`SceneError` when ``steps`` (any number, inf and NaN included) exceeds
    :data:`MAX_STEPS`; ``what`` says what needs them (e.g. "2 revolutions at dt = 1e-12 s")."""
    if not steps <= MAX_STEPS:
        raise SceneError(f"{what} needs {steps:.3g} steps; at most {MAX_STEPS:.0e} are allowed: give a "
                         "larger `numerics.dt` (or `numerics.accuracy`) or fewer `revolutions`")


COUPLINGS = ("converged", "lagged", "uncoupled")


@dataclass(frozen=True)
class FrictionSettings:
    """How the friction of eqs. (1)-(5) is coupled to the reactions and regularised.

    Attributes
    ----------
    coupling : str
        ``"converged"``: within each time step, friction and reactions are iterated to a fixed
        point (the friction applied is the friction of the step's own reactions);
        ``"lagged"``: the paper's scheme (section 3.1), the reactions at the end of a step set the
        friction applied during the next step; ``"uncoupled"``: friction is *not* applied to the
        dynamics, eqs. (3), (5) are evaluated on the frictionless reactions and their power is
        the loss (a first-order estimate, used to explain the paper's tolerance figure; the
        energy balance then misses the loss). The reference engine has no time step: it solves
        the converged fixed point for ``"converged"`` and ``"lagged"`` alike.
    sign_band : float
        Relative surface speed [m/s] below which ``sign()`` of eqs. (3), (5) is replaced by a
        linear ramp ``clip(v / sign_band, -1, 1)``. The surface speed of a rotating journal is
        ``|omega_rel| d / 2``; a sliding pair uses its sliding speed. 0 means the exact sign.
    tolerance : float
        Converged coupling: the fixed point is accepted when the largest change of a friction
        load is below ``tolerance`` times the largest friction load (forces counted as the
        torque they make at the journal radius, ``F d / 2``).
    max_iterations : int
        Converged coupling: friction updates per step before the step is declared not converged.
    """

    coupling: str = "converged"
    sign_band: float = 1e-3
    tolerance: float = 1e-6
    max_iterations: int = 20

    def __post_init__(self) -> None:
        if self.coupling not in COUPLINGS:
            raise SceneError(f"`coupling` must be one of {list(COUPLINGS)}, got {self.coupling!r}")
        _set(self, "sign_band", _non_negative("sign_band", self.sign_band))
        tol = _positive("tolerance", self.tolerance)
        if tol >= 1.0:
            raise SceneError(f"`tolerance` must be < 1, got {tol!r}")
        _set(self, "tolerance", tol)
        if (isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int)
                or self.max_iterations < 2):
            raise SceneError(f"`max_iterations` must be an integer >= 2, got {self.max_iterations!r}")


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
        if isinstance(self.every, bool) or not isinstance(self.every, int) or self.every < 1:
            raise SceneError(f"`every` must be an integer >= 1, got {self.every!r}")
        _set(self, "skip_revolutions", _non_negative("skip_revolutions", self.skip_revolutions))


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

    def __post_init__(self) -> None:
        if not isinstance(self.drive, (SpeedDrive, AngleDrive, TorqueDrive)):
            raise SceneError(f"`drive` must be a speed, angle or torque drive, got {self.drive!r}")
        for name in ("name", "description"):
            if not isinstance(getattr(self, name), str):
                raise SceneError(f"`{name}` must be a string, got {getattr(self, name)!r}")
        _set(self, "gravity", _vector("gravity", self.gravity, (3,)))
        revs = _positive("revolutions", self.revolutions)
        if revs < 1.0 + self.record.skip_revolutions:
            raise SceneError(
                f"`revolutions` must be at least 1 + record.skip_revolutions "
                f"= {1.0 + self.record.skip_revolutions!r} (one whole revolution to average), "
                f"got {revs!r}"
            )
        _set(self, "revolutions", revs)
        if isinstance(self.drive, AngleDrive):
            span = abs(self.drive.angle[-1] - self.drive.angle[0]) / (2 * math.pi)
            if span + 1e-9 < revs:
                raise SceneError(
                    f"`revolutions` = {revs!r} exceeds the {span:.4g} revolutions covered by the "
                    "prescribed angle history"
                )

    @property
    def has_friction(self) -> bool:
        return any(p.friction_coefficient > 0.0 for _, p in self.joint.pairs.items())

    @property
    def has_gravity(self) -> bool:
        return any(g != 0.0 for g in self.gravity)


# --------------------------------------------------------------------------- dict / TOML I/O

_SECTIONS: dict[type, dict[str, Any]] = {
    Scene: {"joint": Joint, "load": Load, "numerics": Numerics, "friction": FrictionSettings,
            "record": Record},
    Joint: {"input": Body, "spider": Body, "output": Body, "geometry": Geometry, "pairs": Pairs,
            "errors": MountingErrors},
    Pairs: {name: Pair for name in PAIR_NAMES},
}


def _build(cls: type, data: Mapping[str, Any], path: str):
    if not isinstance(data, Mapping):
        raise SceneError(f"[{path or 'scene'}] must be a table, got {data!r}")
    data = dict(data)
    names = {f.name for f in dataclasses.fields(cls) if f.init}
    for key in list(data):
        for base, (suffix, factor) in _UNIT_ALIASES.items():
            if key == base + suffix and base in names:
                if base in data:
                    raise SceneError(f"[{path or 'scene'}] give either `{base}` or `{key}`, not both")
                value = data.pop(key)
                data[base] = _finite(key, value) * factor if not _is_seq(value) else value
    unknown = sorted(set(data) - names - {"kind"})
    if unknown:
        raise SceneError(f"[{path or 'scene'}] unknown key(s) {unknown}; allowed: {sorted(names)}")
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
        raise SceneError(f"[{path or 'scene'}] missing required key(s) {missing}"
                         + (" (or start from a named scene with `base = \"paper\"`)" if cls is Scene else ""))
    try:
        return cls(**kwargs)
    except SceneError as exc:
        raise SceneError(f"[{path or 'scene'}] {exc}") from None
    except TypeError as exc:
        raise SceneError(f"[{path or 'scene'}] {exc}") from None


def _build_drive(data: Mapping[str, Any], path: str) -> Drive:
    if not isinstance(data, Mapping):
        raise SceneError(f"[{path}] must be a table, got {data!r}")
    kind = data.get("kind")
    if kind not in DRIVES:
        raise SceneError(f"[{path}] `kind` must be one of {sorted(DRIVES)}, got {kind!r}")
    return _build(DRIVES[kind], data, path)


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """Build and validate a scene from a (TOML-shaped) dictionary; unknown keys are errors."""
    return _build(Scene, data, "")


def scene_to_dict(obj: Any) -> Any:
    """The fully resolved scene (or part) as plain JSON/TOML-ready data, SI units."""
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


def _merge(base: dict, over: Mapping) -> dict:
    out = dict(base)
    for alias_base, (suffix, _) in _UNIT_ALIASES.items():
        if alias_base + suffix in over:
            out.pop(alias_base, None)  # the override's unit-suffixed value replaces the base's
    for key, value in over.items():
        if (key == "drive" and isinstance(value, Mapping) and isinstance(out.get(key), Mapping)
                and "kind" in value and value["kind"] != out[key].get("kind")):
            out[key] = dict(value)  # another kind of drive replaces the base's, keys and all
        elif isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = _merge(out[key], value)
        elif key == "drive" and isinstance(value, Mapping) and "kind" not in value:
            out[key] = _merge(out.get(key, {}), value)
        else:
            out[key] = value
    return out


def load_scene(path) -> Scene:
    """Load a scene from a TOML file.

    A file may start from a named scene with ``base = "paper-10deg"`` and override any part.
    """
    import pathlib

    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib

    path = pathlib.Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"cannot read scene file {str(path)!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"scene file {str(path)!r} is not UTF-8 text (byte {exc.start}); a scene is a "
                         "TOML file") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"scene file {str(path)!r} is not valid TOML: {exc}") from None
    try:
        return scene_from_mapping(data)
    except SceneError as exc:
        raise SceneError(f"{path}: {exc}") from None


def scene_from_mapping(data: Mapping[str, Any]) -> Scene:
    """Like :func:`scene_from_dict`, resolving an optional ``base`` named scene first."""
    data = dict(data)
    base = data.pop("base", None)
    if base is not None:
        from reference.paper import named_scene

        data = _merge(scene_to_dict(named_scene(base)), data)
    return scene_from_dict(data)


def replace(scene: Scene, **changes: Any) -> Scene:
    """Copy of ``scene`` with dotted-path fields changed, validated again.

    Example: ``replace(scene, **{"joint.geometry.shaft_angle": 0.2, "load.torque": 1.0})``.
    Unknown leaf names are rejected by the validation of the rebuilt scene.
    """
    data = scene_to_dict(scene)
    for dotted, value in changes.items():
        node = data
        *parents, leaf = dotted.split(".")
        for key in parents:
            if not isinstance(node.get(key), dict):
                raise SceneError(f"unknown scene field {dotted!r}")
            node = node[key]
        for base, (suffix, _) in _UNIT_ALIASES.items():
            if leaf == base + suffix:
                node.pop(base, None)
        node[leaf] = value
    return scene_from_dict(data)
