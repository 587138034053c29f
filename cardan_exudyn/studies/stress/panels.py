"""The panels of ``cardan stress``'s map: shaft angle (0 to 80 deg) against friction coefficient (per
coupling and node type), input speed or step; each cell one revolution of :func:`base_scene` at
constant input speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from reference.paper import named_scene
from reference.scene import replace
from reference.scene.joint import PAIR_NAMES
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM

__all__ = ["ENGINE", "REFERENCE", "BASE_SCENE", "REVOLUTIONS", "DEFAULT_STEPS", "DEFAULT_RPM",
           "PANEL_FRICTION", "X_LABELS", "Panel", "panels", "base_scene", "cell_id"]


ENGINE = "exudyn"
"""The engine the map tests."""
REFERENCE = "reference"
"""The engine it is tested against."""
BASE_SCENE = "paper-literal-10deg-2000rpm"
"""The joint of the map without a scene option."""
REVOLUTIONS = 1.0
"""Input revolutions of every cell."""
DEFAULT_STEPS = 200
"""Steps per input revolution of the panels that do not vary it."""
DEFAULT_RPM = 2000.0
"""Input speed of the panels that do not vary it [rpm]."""
PANEL_FRICTION = 0.2
"""Friction coefficient of every pair in the speed and step panels."""
X_LABELS = {"friction": "friction coefficient (all pairs)", "rpm": "input speed [rpm]",
            "steps": "steps per input revolution"}


@dataclass(frozen=True)
class Panel:
    """One 2-D slice of the map: shaft angle (rows) against ``x`` (columns)."""

    key: str
    title: str
    x: str                         # "friction", "rpm" or "steps"
    x_values: tuple[float, ...]
    angles: tuple[float, ...]      # [deg]
    node_type: str = "Rxyz"
    coupling: str = "converged"
    friction: float = PANEL_FRICTION
    rpm: float = DEFAULT_RPM
    steps: int = DEFAULT_STEPS

    def cell(self, angle: float, x: float) -> dict[str, Any]:
        """The settings of the cell at row ``angle`` [deg] and column ``x`` (friction coefficient [-], rpm
        or steps per revolution).
        """
        values = {"angle_deg": angle, "friction": self.friction, "rpm": self.rpm,
                  "steps": self.steps}
        values[self.x] = x
        values["steps"] = int(values["steps"])
        return values

    def overrides(self, angle: float, x: float) -> dict[str, Any]:
        """Scene overrides of the cell at ``angle`` [deg], ``x``: shaft angle, constant-speed drive, step,
        coupling, every pair's friction coefficient.
        """
        c = self.cell(angle, x)
        speed = c["rpm"] * RPM
        out: dict[str, Any] = {
            "joint.geometry.shaft_angle": c["angle_deg"] * DEG,
            "drive": {"kind": "speed", "speed": speed},
            "numerics.dt": 2.0 * math.pi / speed / c["steps"],
            "friction.coupling": self.coupling,
        }
        for pair in PAIR_NAMES:
            out[f"joint.pairs.{pair}.friction_coefficient"] = c["friction"]
        return out


def panels(quick: bool = False) -> list[Panel]:
    """The map's panels (``quick``: coarser, for CI)."""
    return quick_panels() if quick else full_panels()


def quick_panels() -> list[Panel]:
    """A few cells each side of the boundaries, one where the lagged coupling runs through a self-lock."""
    angles = (0.0, 10.0, 40.0, 80.0)
    few = (0.0, 40.0, 80.0)
    friction = (0.0, 0.2, 0.6)
    return [
        Panel("friction", "converged coupling, Rxyz", "friction", friction, angles),
        Panel("lagged", "lagged coupling, Rxyz", "friction", friction, angles, coupling="lagged"),
        Panel("extrapolated", "extrapolated coupling, Rxyz", "friction", friction, angles,
              coupling="extrapolated"),
        Panel("ep", "converged, Euler parameters", "friction", (0.0, 0.2), few, node_type="EP"),
        Panel("rotveclg", "converged, rotation vector (Lie group)", "friction", (0.0, 0.2),
              few, node_type="RotVecLG"),
        Panel("speed", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "rpm", (10.0, 10000.0), few),
        Panel("steps", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "steps", (25.0, 200.0), few),
    ]


def full_panels() -> list[Panel]:
    """Every 10 deg from 0 to 80 against the full range of each quantity."""
    angles = tuple(float(a) for a in range(0, 81, 10))
    friction = (0.0, 0.05, 0.1, 0.2, 0.3, 0.42, 0.6, 0.8, 1.0)
    return [
        Panel("friction", "converged coupling, Rxyz", "friction", friction, angles),
        Panel("lagged", "lagged coupling, Rxyz", "friction", friction, angles, coupling="lagged"),
        Panel("extrapolated", "extrapolated coupling, Rxyz", "friction", friction, angles,
              coupling="extrapolated"),
        Panel("ep", "converged, Euler parameters", "friction", friction, angles, node_type="EP"),
        Panel("rotveclg", "converged, rotation vector (Lie group)", "friction", friction, angles,
              node_type="RotVecLG"),
        Panel("speed", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "rpm",
              (10.0, 100.0, 500.0, 2000.0, 5000.0, 10000.0), angles),
        Panel("steps", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "steps",
              (12.0, 25.0, 50.0, 100.0, 200.0, 400.0, 800.0), angles),
    ]


def base_scene(scene: Scene | None = None) -> Scene:
    """The map's base scene: ``scene`` (default :data:`BASE_SCENE`) for :data:`REVOLUTIONS` revolution,
    every revolution averaged.
    """
    scene = named_scene(BASE_SCENE) if scene is None else scene
    return replace(scene, **{"revolutions": REVOLUTIONS, "record.skip_revolutions": 0.0})


def cell_id(panel: Panel, angle: float, x: float) -> str:
    """The case id of ``panel``'s cell at ``angle`` [deg], ``x``, e.g. ``friction/10deg/friction=0.2``."""
    return f"{panel.key}/{angle:g}deg/{panel.x}={x:g}"
