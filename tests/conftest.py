"""Shared fixtures: small, balanced test joints whose reactions can be computed by hand."""

from __future__ import annotations

import math

import pytest

from reference.paper.scenes import named_scene
from reference.scene.drives import SpeedDrive
from reference.scene.joint import Body, Geometry, Joint, Pair, Pairs
from reference.scene.load import Load
from reference.scene.scene import Scene
from reference.scene.settings import Numerics, Record

M_IN, M_SPIDER, M_OUT = 0.9, 0.05, 0.8
B_IN, B_OUT = 0.12, 0.09


def balanced_joint(shaft_angle: float = 0.0) -> Joint:
    """Bodies with centres of mass on their axes, at the frame bearings, diagonal inertia."""
    return Joint(
        input=Body(M_IN, [[2e-4, 0, 0], [0, 4e-3, 0], [0, 0, 4e-3]], com=(-B_IN, 0.0, 0.0)),
        spider=Body(M_SPIDER, [[2e-6, 0, 0], [0, 3e-6, 0], [0, 0, 3e-6]]),
        output=Body(M_OUT, [[1.8e-4, 0, 0], [0, 3.5e-3, 0], [0, 0, 3.5e-3]], com=(B_OUT, 0.0, 0.0)),
        geometry=Geometry(shaft_angle=shaft_angle, input_bearing=B_IN, output_bearing=B_OUT),
        pairs=Pairs(),
    )


def balanced_scene(shaft_angle_deg: float = 0.0, rpm: float = 600.0, load: float = 1.5,
                   gravity=(0.0, 0.0, -9.81), revolutions: float = 1.0, **numerics) -> Scene:
    return Scene(
        joint=balanced_joint(math.radians(shaft_angle_deg)),
        drive=SpeedDrive(rpm * 2 * math.pi / 60),
        load=Load(load),
        gravity=gravity,
        revolutions=revolutions,
        numerics=Numerics(**numerics),
        record=Record(),
        name="balanced",
    )


@pytest.fixture
def paper_10deg_frictionless() -> Scene:
    return named_scene("paper-literal-10deg-frictionless")


__all__ = ["balanced_scene", "balanced_joint", "Pair"]
