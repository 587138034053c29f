"""Labels that do not lie: a scene changed on the command line carries a name that says so
(issue 18), in ``cardan scene``, the run summary and the printed line."""

from __future__ import annotations

import json

import pytest

from cardan_exudyn.cli import build_parser, main
from cardan_exudyn.scene_options import override_name, scene_from_args
from reference.paper.scenes import named_scene
from reference.scene.files import scene_from_mapping
from reference.scene.validation import SceneError


def _scene(*argv: str):
    return scene_from_args(build_parser().parse_args(["scene", *argv]))


def test_issue_example_angle_and_friction():
    """`--angle 45 --friction-spider 0.42` on the frictionless paper scene (the default scene until
    issue 21): the name gives the new angle and both friction coefficients, and no longer 10 deg or
    frictionless."""
    scene = _scene("--name", "paper-10deg-frictionless", "--angle", "45", "--friction-spider", "0.42")
    assert scene.name == "paper-physical-45deg-2000rpm+f_spider=0.42+f_frame=0"
    assert "angle=45deg, f_spider=0.42, f_frame=0" in scene.description


def test_replaced_token_names_the_named_scene():
    """An angle or speed that replaces the part of a paper name gives that named scene's name, and
    the scene is that named scene."""
    scene = _scene("--name", "paper-literal-10deg-frictionless", "--angle", "35", "--rpm", "1000")
    assert scene.name == "paper-literal-35deg-1000rpm-frictionless"
    named = named_scene("paper-literal-35deg-1000rpm-frictionless")
    assert scene.joint == named.joint and scene.drive == named.drive


@pytest.mark.parametrize("argv, label", [
    (("--angle", "20"), "20deg"),
    (("--rpm", "500"), "500rpm"),
    (("--load-torque", "3"), "+load=3Nm"),
    (("--friction-spider", "0.1"), "+f_spider=0.1+f_frame=0.2"),
    (("--friction-frame", "0.3"), "+f_spider=0.42+f_frame=0.3"),
    (("--coupling", "lagged"), "+coupling=lagged"),
    (("--sign-band", "0.01"), "+sign_band=0.01"),
    (("--no-gravity",), "+no_gravity"),
    (("--dt", "1e-4"), "+dt=0.0001s"),
    (("--accuracy", "1e-6"), "+accuracy=1e-06"),
    (("--revolutions", "3"), "+revolutions=3"),
], ids=lambda v: v[0] if isinstance(v, tuple) else None)
def test_every_scene_option_shows_in_the_name(argv, label):
    """Each command-line scene option changes the name (from the default scene's) and shows its value."""
    scene = _scene(*argv)
    assert scene.name != "paper-physical-10deg-2000rpm"
    assert label in scene.name


def test_no_override_keeps_the_name():
    """Without overrides the scene is the named or loaded one, name included."""
    assert _scene("--name", "rig-literal").name == "rig-literal"


def test_scene_file_name_gets_the_overrides(tmp_path):
    """A scene file's own name (no angle part) gets the overrides appended."""
    path = tmp_path / "s.toml"
    path.write_text('base = "paper-literal"\nname = "my-joint"\n')
    scene = _scene("--scene", str(path), "--angle", "12.5", "--load-torque", "0.5")
    assert scene.name == "my-joint+12.5deg+load=0.5Nm"


def test_negative_speed_is_not_read_as_a_separator():
    assert override_name("paper-10deg-2000rpm", [("rpm", "-2000rpm")]) == "paper-10deg-(-2000rpm)"


def test_override_name_rules():
    """Token replaced when exactly one part gives it; appended otherwise; frictionless dropped only
    when the scene has friction."""
    assert override_name("rig-frictionless", [("angle", "20deg")], frictionless=True) \
        == "rig-frictionless+20deg"
    assert override_name("a-10deg-b-10deg", [("angle", "20deg")]) == "a-10deg-b-10deg+20deg"
    assert override_name("paper-10deg-frictionless", [("f_spider", "0.1"), ("f_frame", "0")],
                         frictionless=False) == "paper-10deg+f_spider=0.1+f_frame=0"


def test_run_summary_carries_the_override_name(capsys):
    """`cardan run --load-torque` (reference engine, one revolution): the summary's scene name and the
    printed line say the load was overridden."""
    status = main(["run", "--name", "rig-literal-frictionless", "--engine", "reference", "--revolutions", "1",
                   "--load-torque", "0.3", "--json"])
    out = capsys.readouterr().out
    assert status == 0
    assert json.loads(out)["scene"]["name"] == "rig-literal-frictionless+load=0.3Nm+revolutions=1"


def test_drive_typo_lists_every_allowed_key():
    """A misspelt drive key: the message lists `kind` and the unit-suffixed alias, not `speed` alone."""
    with pytest.raises(SceneError, match=r"allowed: \['kind', 'speed', 'speed_rpm'\]"):
        scene_from_mapping({"base": "paper-literal", "drive": {"sped": 100}})
    with pytest.raises(SceneError, match=r"allowed: \['initial_speed', 'initial_speed_rpm', 'kind', "
                                         r"'torque'\]"):
        scene_from_mapping({"base": "paper-literal", "drive": {"kind": "torque", "torque": 1.0,
                                                        "initial_speed": 1.0, "tork": 1}})
