"""The scene: one plain, validated description of a Cardan-joint simulation for every engine, a tree
of frozen dataclasses in SI units and radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from reference.scene.drives import AngleDrive, Drive, SpeedDrive, TorqueDrive
from reference.scene.joint import Joint
from reference.scene.load import Load
from reference.scene.settings import FrictionSettings, Numerics, Record
from reference.scene.validation import SceneError, positive, require_instance, set_field, vector

__all__ = ["Scene"]


@dataclass(frozen=True)
class Scene:
    """A complete simulation case: joint, drive, load, gravity, span, numerics, recording.

    Attributes
    ----------
    revolutions : float
        Simulated span in input revolutions [-], >= 1 + ``record.skip_revolutions``.
    gravity : tuple, shape (3,)
        Gravitational acceleration, global frame [m/s^2].
    parameter_set : str
        The paper's parameter set the scene was built with (``"custom"`` for values given by hand,
        ``""`` for a scene not the paper's); every result carries it.
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
