"""The Cardan joint of a scene: its three bodies, geometry, four pairs and mounting errors (SI, rad).

Conventions (every engine; README "Conventions"): origin at the joint centre, x along the input
axis towards the joint, output axis ``(cos(beta), sin(beta), 0)``. Canonical body frames (origin
at the joint centre, global at input angle 0 except the output's, turned by ``beta`` about z):
``input`` x along its axis, y along its yoke's trunnions; ``spider`` y on the arm the input yoke
holds, z on the output yoke's; ``output`` x along its axis away from the joint, z along its yoke's
trunnions. A :class:`Body` gives its mass properties in its own local frame (``local_origin``,
``local_axes``). Pairs in chain order (body ``a`` -> ``b``): ``frame_input`` (revolute, ground ->
input), ``input_spider``, ``spider_output``, ``output_frame`` (cylindrical, -> ground).
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
        Inertia tensor in the local frame [kg m^2], about ``inertia_about``: ``"com"`` or ``"origin"``.
    com, local_origin : tuple, shape (3,)
        Centre of mass in the local frame, local origin in the canonical body frame [m].
    local_axes : tuple, shape (3, 3)
        Columns: the local x, y, z axes in canonical coordinates.
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
        Coulomb coefficient f [-], >= 0 (0: frictionless).
    journal_diameter : float
        Journal diameter d [m] of eqs. (2), (3).
    moment_lever : float or "geometry"
        Lever L [m] of eq. (1); ``"geometry"`` (or None): :meth:`Joint.lever`, ``2 * arm_radius`` for a
        spider pair (two trunnion bearings on opposite arms), ``support_spacing`` for a frame pair.
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
        Angle beta between the shaft axes [rad], in [0, pi/2).
    input_bearing, output_bearing : float
        Joint centre to the frame-input / output-frame bearing along its shaft axis [m].
    arm_radius : float
        Joint centre to the middle of each trunnion bearing [m].
    support_spacing : float
        Spacing of each shaft's two support bearings [m] (the frame pairs' lumped bearings).
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
    """Manufacturing and mounting errors as Denavit-Hartenberg deviations (the paper's Figure 3).

    Link k carries pairs k and k + 1 (:mod:`reference.physics.rccc`): 1 the input, 2 the spider, 3 the
    output, 4 the frame. All zero is the ideal joint; ``a<k>_mm``, ``alpha<k>_deg``, ``s1_mm`` are
    accepted at the boundary.

    Attributes
    ----------
    a1, a2, a3, a4 : float
        Offsets [m]: each link's common normal between its pair axes (the paper's tolerance case:
        ``a1 = a2 = a3 = 0.5 mm``).
    alpha1, alpha2, alpha3, alpha4 : float
        Twist errors [rad] added to the ideal (90, 90, 90, -shaft angle) deg (paper: 6e-3 deg each of 1..3).
    s1 : float
        Axial offset of the input along x [m].
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
        """Moment lever [m] of pair ``name``: its ``moment_lever``, or under ``"geometry"`` ``2 * arm_radius``
        (spider pair) or ``support_spacing`` (frame pair).
        """
        pair = getattr(self.pairs, name)
        if pair.moment_lever != GEOMETRY_LEVER:
            return pair.moment_lever
        if name in ("input_spider", "spider_output"):
            return 2.0 * self.geometry.arm_radius
        return self.geometry.support_spacing

    def friction_pairs(self) -> list[tuple[str, Pair]]:
        """``(name, pair)`` in chain order with every moment lever resolved (:meth:`lever`)."""
        return [(name, dataclasses.replace(pair, moment_lever=self.lever(name)))
                for name, pair in self.pairs.items()]

    def bodies(self) -> list[tuple[str, Body]]:
        """``(name, body)`` of the three moving bodies, :data:`BODY_NAMES`."""
        return [(name, getattr(self, name)) for name in BODY_NAMES]
