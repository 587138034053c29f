"""The Cardan joint of a scene: its three bodies, geometry, four pairs and mounting errors.

The part of a scene that describes the mechanism; :mod:`reference.scene.scene` adds what is done with
it (drive, load, gravity, span, numerics). Every engine and the paper's data
(:mod:`reference.paper`) build on these types, so they sit below both. SI units and radians.

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
from dataclasses import dataclass, field

import numpy as np

from reference.scene.inertia import inertia_problems, rotate_inertia, shift_inertia_to_com
from reference.scene.validation import (
    DEG,
    SceneError,
    finite,
    non_negative,
    positive,
    require_instance,
    set_field,
    vector,
)

__all__ = ["BODY_NAMES", "PAIR_NAMES", "PAIR_KIND", "PAIR_BODIES", "Body", "GEOMETRY_LEVER", "Pair",
           "Pairs", "Geometry", "ERROR_NAMES", "MountingErrors", "Joint"]

BODY_NAMES = ("input", "spider", "output")
"""The moving bodies, in chain order."""
PAIR_NAMES = ("frame_input", "input_spider", "spider_output", "output_frame")
"""The kinematic pairs, in chain order (the order of every per-pair table and column)."""
PAIR_KIND = {
    "frame_input": "revolute",
    "input_spider": "cylindrical",
    "spider_output": "cylindrical",
    "output_frame": "cylindrical",
}
"""Each pair's kind: ``"revolute"`` or ``"cylindrical"``."""
PAIR_BODIES = {
    "frame_input": ("ground", "input"),
    "input_spider": ("input", "spider"),
    "spider_output": ("spider", "output"),
    "output_frame": ("output", "ground"),
}
"""Each pair's bodies ``(a, b)``: its reaction is what ``a`` exerts on ``b``."""

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
        set_field(self, "mass", positive("mass", self.mass))
        set_field(self, "inertia", vector("inertia", self.inertia, (3, 3)))
        set_field(self, "com", vector("com", self.com, (3,)))
        set_field(self, "local_origin", vector("local_origin", self.local_origin, (3,)))
        set_field(self, "local_axes", vector("local_axes", self.local_axes, (3, 3)))
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


GEOMETRY_LEVER = "geometry"
"""``Pair.moment_lever`` value meaning: derived from the joint's geometry (:meth:`Joint.lever`)."""


@dataclass(frozen=True)
class Pair:
    """Friction data of one kinematic pair (eqs. (1)-(5)).

    Attributes
    ----------
    friction_coefficient : float
        Coulomb coefficient f [-], >= 0; zero means the pair is frictionless.
    journal_diameter : float
        Journal diameter d [m] of eqs. (2), (3).
    moment_lever : float or "geometry"
        Lever L [m] that turns a bending moment into a couple of forces, eq. (1); ``"geometry"``
        (None is read as it): derived from the joint's geometry (:meth:`Joint.lever`): a spider
        pair stands for two trunnion
        bearings on opposite arms, which carry a bending moment as a couple over their spacing,
        ``2 * arm_radius``; a frame pair for a shaft's two support bearings, ``support_spacing``.
    """

    friction_coefficient: float = 0.0
    journal_diameter: float = 0.02
    moment_lever: float | str = 0.01

    def __post_init__(self) -> None:
        set_field(self, "friction_coefficient",
                  non_negative("friction_coefficient", self.friction_coefficient))
        set_field(self, "journal_diameter", positive("journal_diameter", self.journal_diameter))
        if self.moment_lever is None or self.moment_lever == GEOMETRY_LEVER:
            set_field(self, "moment_lever", GEOMETRY_LEVER)
        elif isinstance(self.moment_lever, str):
            raise SceneError(f"`moment_lever` must be a number [m] or {GEOMETRY_LEVER!r} (derived from "
                             f"the joint's geometry), got {self.moment_lever!r:.80}")
        else:
            set_field(self, "moment_lever", positive("moment_lever", self.moment_lever))


@dataclass(frozen=True)
class Pairs:
    """The four kinematic pairs of the RCCC joint, in chain order."""

    frame_input: Pair = field(default_factory=Pair)
    input_spider: Pair = field(default_factory=Pair)
    spider_output: Pair = field(default_factory=Pair)
    output_frame: Pair = field(default_factory=Pair)

    def __post_init__(self) -> None:
        for name in PAIR_NAMES:
            require_instance(name, getattr(self, name), Pair, "a Pair")

    def items(self) -> list[tuple[str, Pair]]:
        """``(name, pair)`` in chain order, :data:`PAIR_NAMES`."""
        return [(name, getattr(self, name)) for name in PAIR_NAMES]


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
        Spider arm radius: joint centre to the middle of each trunnion bearing [m]. The moment
        lever of a spider pair whose ``moment_lever`` is ``"geometry"`` is ``2 * arm_radius``.
    support_spacing : float
        Distance between the two support bearings of each shaft [m], the frame pair's lumped
        bearings; the moment lever of a frame pair whose ``moment_lever`` is ``"geometry"``.
    """

    shaft_angle: float = 0.0
    input_bearing: float = 0.1
    output_bearing: float = 0.1
    arm_radius: float = 0.012
    support_spacing: float = 0.1

    def __post_init__(self) -> None:
        beta = finite("shaft_angle", self.shaft_angle)
        if not 0.0 <= beta < 0.5 * math.pi:
            raise SceneError(
                f"`shaft_angle` must be in [0, 90) deg, got {beta / DEG!r} deg ({beta!r} rad)"
            )
        set_field(self, "shaft_angle", beta)
        set_field(self, "input_bearing", positive("input_bearing", self.input_bearing))
        set_field(self, "output_bearing", positive("output_bearing", self.output_bearing))
        set_field(self, "arm_radius", positive("arm_radius", self.arm_radius))
        set_field(self, "support_spacing", positive("support_spacing", self.support_spacing))

    def output_axis(self) -> np.ndarray:
        """Unit vector of the output shaft axis in the global frame."""
        return np.array([math.cos(self.shaft_angle), math.sin(self.shaft_angle), 0.0])


ERROR_NAMES = ("a1", "a2", "a3", "a4", "alpha1", "alpha2", "alpha3", "alpha4", "s1")
"""Fields of :class:`MountingErrors`, in the order the tolerance studies report them."""


@dataclass(frozen=True)
class MountingErrors:
    """Manufacturing and mounting errors as Denavit-Hartenberg parameter deviations (Figure 3).

    Links are numbered as the pairs they carry (:mod:`reference.physics.rccc`): link 1 the input (from
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
            set_field(self, name, finite(name, getattr(self, name)))
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
        for name, cls in (("input", Body), ("spider", Body), ("output", Body), ("geometry", Geometry),
                          ("pairs", Pairs), ("errors", MountingErrors)):
            require_instance(name, getattr(self, name), cls, f"a {cls.__name__}")
        twist = self.errors.alpha4 - self.geometry.shaft_angle
        if not abs(twist) < 0.5 * math.pi:
            raise SceneError(f"`errors.alpha4` minus the shaft angle (the frame's twist) must be in "
                             f"(-90, 90) deg, got {twist / DEG!r} deg")

    def lever(self, name: str) -> float:
        """Moment lever of pair ``name`` [m]: its ``moment_lever``, or when that is ``"geometry"``
        the one the joint's geometry gives (``2 * arm_radius`` for a spider pair,
        ``support_spacing`` for a frame
        pair; see :class:`Pair`)."""
        pair = getattr(self.pairs, name)
        if pair.moment_lever != GEOMETRY_LEVER:
            return pair.moment_lever
        if name in ("input_spider", "spider_output"):
            return 2.0 * self.geometry.arm_radius
        return self.geometry.support_spacing

    def friction_pairs(self) -> list[tuple[str, Pair]]:
        """``(name, pair)`` in chain order with every moment lever resolved (:meth:`lever`): the
        pairs as the friction law sees them."""
        return [(name, dataclasses.replace(pair, moment_lever=self.lever(name)))
                for name, pair in self.pairs.items()]

    def bodies(self) -> list[tuple[str, Body]]:
        """``(name, body)`` of the three moving bodies, :data:`BODY_NAMES`."""
        return [(name, getattr(self, name)) for name in BODY_NAMES]
