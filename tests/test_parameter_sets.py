"""The paper's three parameter sets, their scene names, the levers derived from geometry and the
mean-input reading of the case's torque (issue 21)."""

from __future__ import annotations

import math

import pytest

from cardan_exudyn import run
from reference.paper.apply import apply_parameters
from reference.paper.loads import mean_input_load
from reference.paper.parameter_sets import (
    DEFAULT_PARAMETER_SET,
    PARAMETER_SETS,
    parameter_table,
    plausible_box,
    set_values,
)
from reference.paper.scenes import named_scene, paper_scene, rig_scene
from reference.scene.joint import GEOMETRY_LEVER, Pair
from reference.scene.mapping import replace, scene_from_dict, scene_to_dict
from reference.scene.validation import SceneError


def test_names_spell_out_the_set():
    assert DEFAULT_PARAMETER_SET == "physical"
    assert named_scene("paper-10deg").name == "paper-physical-10deg-2000rpm"
    assert named_scene("paper-literal-35deg-500rpm").name == "paper-literal-35deg-500rpm"
    assert named_scene("rig-matched-errors").name == "rig-matched-errors"
    for name in PARAMETER_SETS:
        scene = named_scene(f"paper-{name}-frictionless")
        assert scene.parameter_set == name and name in scene.description
        assert scene_to_dict(scene)["parameter_set"] == name


@pytest.mark.parametrize("old,new", [("paper-calibrated-10deg", "matched"), ("rig-plain", "literal")])
def test_renamed_sets_are_refused_with_the_new_name(old, new):
    with pytest.raises(SceneError, match=f"now called '{new}'"):
        named_scene(old)
    with pytest.raises(SceneError, match=f"now called '{new}'"):
        paper_scene(10.0, parameters=old.split("-")[1])


def test_unknown_names_list_the_sets():
    with pytest.raises(SceneError, match="physical, literal, matched"):
        named_scene("paper-foo-10deg")


def test_levers_follow_the_geometry():
    """A lever given as "geometry" is 2 x arm radius (spider pairs) or the support spacing (frame
    pairs), and follows a later change of either; a number stays as given."""
    scene = paper_scene(10.0, parameters={"arm_radius": 0.011, "support_spacing": 0.15})
    assert scene.joint.pairs.input_spider.moment_lever == GEOMETRY_LEVER
    assert scene.joint.lever("input_spider") == pytest.approx(0.022)
    assert scene.joint.lever("output_frame") == pytest.approx(0.15)
    moved = replace(scene, **{"joint.geometry.arm_radius": 0.02})
    assert moved.joint.lever("spider_output") == pytest.approx(0.04)
    assert dict(moved.joint.friction_pairs())["spider_output"].moment_lever == pytest.approx(0.04)
    literal = named_scene("paper-literal")
    assert literal.joint.lever("input_spider") == 0.006 and literal.joint.lever("frame_input") == 0.01
    assert scene_from_dict(scene_to_dict(scene)) == scene  # "geometry" survives a scene file
    assert Pair(0.1, 0.01, None).moment_lever == GEOMETRY_LEVER
    with pytest.raises(SceneError, match="'geometry'"):
        Pair(0.1, 0.01, "long")
    with pytest.raises(SceneError, match="not both"):
        paper_scene(10.0, parameters={"arm_radius": 0.01, "spider_lever": 0.02})


def test_physical_values_lie_in_the_plausible_box():
    box = plausible_box()
    rows = parameter_table("physical")
    assert {r["name"] for r in rows} - set(box) == {"friction_law"}  # a law, not a dimension
    for row in rows:
        assert row["plausible_value"] is (True if row["name"] in box else None), row
    matched = {r["name"]: r["plausible_value"] for r in parameter_table("matched")}
    assert matched["spider_com_offset"] is False  # 8.5 mm: the set says so itself
    # levers as the dimensions they stand for: 60 mm is a 30 mm arm radius, 0.59 m a bearing spacing
    assert matched["spider_lever"] is False and matched["frame_lever"] is False
    literal = {r["name"]: r["plausible_value"] for r in parameter_table("literal")}
    assert literal["spider_lever"] is False and literal["gravity"] is False


def test_mean_input_reading_gives_the_mean_input_torque():
    """Under the mean-input reading the output load is the one whose mean input torque over
    whole revolutions is the case's 2 N m (checked with the reference engine at 1e-4 of it)."""
    scene = replace(named_scene("paper-30deg"), **{"record.timeseries": False})
    assert set_values("physical")["torque_reading"] == "mean_input"
    assert scene.load.torque < 2.0
    summary = run(scene, "reference").summary
    assert summary.mean_torque_in == pytest.approx(2.0, rel=1e-4)
    assert summary.mean_efficiency == pytest.approx(scene.load.torque / 2.0, rel=1e-4)
    assert "mean input torque is 2 N m" in scene.description
    frictionless = named_scene("paper-30deg-frictionless")
    assert frictionless.load.torque == 2.0
    assert rig_scene(parameters="physical").load.torque < 0.2


def test_mean_input_reading_needs_a_constant_speed():
    scene = replace(named_scene("paper-literal"), drive={"kind": "torque", "torque": 2.0,
                                                         "initial_speed": 10.0})
    with pytest.raises(SceneError, match="constant-speed"):
        mean_input_load(scene)
    with pytest.raises(SceneError, match="torque_reading"):
        apply_parameters(named_scene("paper-literal"), {"torque_reading": "both"})


def test_literal_set_keeps_its_old_numbers():
    """The literal set keeps the former plain set's reading: gravity, 2 N m, Table 1's eccentricity."""
    scene = named_scene("paper-literal-10deg")
    assert scene.gravity == (0.0, 0.0, -9.81) and scene.load.torque == 2.0
    # Table 1's 8.6 mm eccentricity, to the digits stated (the scene has 8.568 mm)
    assert abs(math.hypot(*scene.joint.input.com[::2]) - 0.0086) <= 0.00005
