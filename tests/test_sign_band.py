"""The friction sign ramp scales with the scene (``reference.physics.bands``): relative band by default,
the same bands in every engine, the mean efficiency at its sharp-sign limit at every speed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cardan_exudyn import engines
from reference.paper.scenes import named_scene
from reference.physics.bands import SPEED_FLOOR, characteristic_speeds, nominal_speed, sign_bands
from reference.scene.drives import AngleDrive, TorqueDrive
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace, scene_from_dict, scene_to_dict
from reference.scene.settings import DEFAULT_SIGN_BAND_RELATIVE, FrictionSettings
from reference.scene.validation import SceneError


def efficiency(scene, **changes) -> float:
    """Mean efficiency of the reference engine."""
    return engines.run(replace(scene, **changes), "reference").summary.mean_efficiency


def test_frame_pair_band_by_hand():
    """Constant speed: the input frame journal rubs at ``omega d / 2`` all the time, so its band
    is ``1e-3 omega d / 2`` (2000 rpm, d = 20 mm: 2.094e-4 m/s)."""
    scene = named_scene("paper-literal-10deg-2000rpm")
    omega = 2000 * 2 * math.pi / 60
    d = scene.joint.pairs.frame_input.journal_diameter
    assert sign_bands(scene)["frame_input"].rotation == pytest.approx(
        DEFAULT_SIGN_BAND_RELATIVE * omega * d / 2, rel=1e-12)


def test_band_is_relative_to_the_speed():
    """Every band at 1 rpm is 1/2000 of the band at 2000 rpm (the kinematics are linear in the
    speed), and 1e-3 of its pair's RMS speed where that speed is above the floor."""
    slow = sign_bands(named_scene("paper-literal-10deg-1rpm"))
    fast = sign_bands(named_scene("paper-literal-10deg-2000rpm"))
    for pair in PAIR_NAMES:
        assert np.allclose(np.array(fast[pair]), 2000 * np.array(slow[pair]), rtol=1e-12, atol=0)
    speeds = characteristic_speeds(named_scene("paper-literal-10deg-1rpm"))
    for pair in PAIR_NAMES:
        assert slow[pair].rotation == pytest.approx(1e-3 * speeds[pair].rotation, rel=1e-12)


def test_floor_for_pairs_that_do_not_move():
    """At 0 deg the spider pairs do not turn and no pair slides: their bands are the floor,
    ``1e-3 * SPEED_FLOOR`` of the fastest surface speed, positive (so rounding-level speeds in
    Exudyn never get the full friction)."""
    scene = named_scene("paper-literal-0deg")
    fastest = max(max(s) for s in characteristic_speeds(scene).values())
    floor = DEFAULT_SIGN_BAND_RELATIVE * SPEED_FLOOR * fastest
    bands = sign_bands(scene)
    assert characteristic_speeds(scene)["input_spider"].rotation < 1e-12 * fastest
    assert bands["input_spider"].rotation == pytest.approx(floor, rel=1e-12) and floor > 0
    assert all(bands[p].sliding == pytest.approx(floor, rel=1e-12) for p in PAIR_NAMES)


def test_sliding_band_with_mounting_errors():
    """With the rig's tolerances the cylindrical pairs slide: their sliding band is 1e-3 of their
    RMS sliding speed (above the floor here)."""
    scene = named_scene("rig-literal-errors")
    speeds, bands = characteristic_speeds(scene), sign_bands(scene)
    assert speeds["input_spider"].sliding > SPEED_FLOOR * speeds["frame_input"].rotation
    assert bands["input_spider"].sliding == pytest.approx(1e-3 * speeds["input_spider"].sliding, rel=1e-12)


def test_absolute_and_exact_bands():
    """``sign_band`` (m/s) is one band for every ramp, as before; ``sign_band_relative = 0`` is the
    exact sign."""
    scene = named_scene("paper-literal-10deg")
    absolute = sign_bands(replace(scene, **{"friction.sign_band": 2e-3}))
    assert all(tuple(b) == (2e-3, 2e-3, 2e-3) for b in absolute.values())  # rotation, sliding, resultant
    exact = sign_bands(replace(scene, **{"friction.sign_band_relative": 0.0}))
    assert all(tuple(b) == (0.0, 0.0, 0.0) for b in exact.values())


def test_nominal_speed_of_each_drive():
    """Speed drive: its speed; torque drive: its initial speed; angle history: the speed averaged
    over the angle turned (a uniform history at 3 rad/s gives 3 rad/s)."""
    scene = named_scene("paper-literal-10deg-60rpm")
    assert nominal_speed(scene) == pytest.approx(2 * math.pi, rel=1e-12)
    torque = replace(scene, drive={"kind": "torque", "torque": 1.0, "initial_speed": -4.0})
    assert isinstance(torque.drive, TorqueDrive) and nominal_speed(torque) == 4.0
    t = np.linspace(0.0, 5.0, 21)
    history = replace(scene, drive={"kind": "angle", "time": t.tolist(), "angle": (3.0 * t).tolist()})
    assert isinstance(history.drive, AngleDrive)
    assert nominal_speed(history) == pytest.approx(3.0, rel=1e-9)


@pytest.mark.parametrize("name", ["paper-literal-10deg-1rpm", "paper-literal-10deg-2000rpm"], ids=["1rpm",
                                                                                                   "2000rpm"])
def test_default_band_gives_the_sharp_sign_limit(name):
    """Reference engine: the default (relative) band gives the mean efficiency of the exact sign
    within 1e-4 at 1 and at 2000 rpm under the plain set, whose strong friction feedback makes it
    the most band-sensitive paper scene (measured 4.8e-5 and 3.3e-5; the difference falls in
    proportion to the relative band: 4.8e-4, 4.8e-5, 4.8e-6 at 1e-2, 1e-3, 1e-4, docs/paper.md).
    The old absolute 1e-3 m/s band missed by 0.32 at 1 rpm."""
    scene = named_scene(name)
    default = efficiency(scene)
    exact = efficiency(scene, **{"friction.sign_band_relative": 0.0})
    assert abs(default - exact) < 1e-4
    if name.endswith("1rpm"):  # the test can fail: the absolute band does at 1 rpm
        old = efficiency(scene, **{"friction.sign_band": 1e-3})
        assert old - exact > 0.3


def test_both_engines_use_the_same_bands():
    """Exudyn's friction coupling and the reference engine report the bands of
    ``reference.physics.bands.sign_bands`` for the pairs with friction."""
    from cardan_exudyn import engines

    # 60 rpm: one revolution per second, 120 steps (the bands do not depend on the step)
    scene = replace(named_scene("paper-matched-35deg-60rpm"), revolutions=1.0,
                    **{"numerics.dt": 1.0 / 120})
    expected = {p: list(b) for p, b in sign_bands(scene).items()}
    exudyn = engines.run(scene, "exudyn").summary.friction.sign_bands_m_s
    reference = engines.run(scene, "reference").summary.extras["sign_bands_m_s"]
    assert reference == expected
    assert exudyn == {p: tuple(expected[p]) for p in exudyn} and set(exudyn) == set(PAIR_NAMES)


@pytest.mark.parametrize("friction", [
    {}, {"sign_band_relative": 1e-4}, {"sign_band_relative": 0.0}, {"sign_band": 1e-3},
], ids=["default", "relative", "exact", "absolute"])
def test_scene_round_trip(friction):
    """The band fields survive the dictionary (TOML/JSON) form; fields left unset stay unset."""
    scene = replace(named_scene("paper-literal-10deg"), **{f"friction.{k}": v for k, v in friction.items()})
    data = scene_to_dict(scene)
    assert {k: data["friction"][k] for k in ("sign_band", "sign_band_relative")
            if k in data["friction"]} == friction
    assert scene_from_dict(data) == scene


def test_default_is_relative():
    """Without either field the relative default is in effect; with ``sign_band`` none is."""
    assert FrictionSettings().relative_band == DEFAULT_SIGN_BAND_RELATIVE == 1e-3
    assert FrictionSettings(sign_band_relative=0.0).relative_band == 0.0
    assert FrictionSettings(sign_band=1e-3).relative_band is None


@pytest.mark.parametrize("kwargs, match", [
    ({"sign_band": 1e-3, "sign_band_relative": 1e-3}, "either `sign_band`.*or `sign_band_relative`"),
    ({"sign_band_relative": -1e-3}, "`sign_band_relative` must be >= 0, got -0.001"),
    ({"sign_band_relative": "small"}, "`sign_band_relative` must be a number, got 'small'"),
    ({"sign_band_relative": float("inf")}, "`sign_band_relative` must be finite"),
    ({"sign_band": -1.0}, "`sign_band` must be >= 0, got -1.0"),
], ids=["both", "negative", "text", "infinite", "negative-absolute"])
def test_validation(kwargs, match):
    """Bad band settings are refused with a message naming the field and the value."""
    with pytest.raises(SceneError, match=match):
        FrictionSettings(**kwargs)


def test_scene_file_error_names_the_table():
    """Both fields in a scene's [friction] table: one line naming the table."""
    data = scene_to_dict(named_scene("paper-literal-10deg"))
    data["friction"].update(sign_band=1e-3, sign_band_relative=1e-3)
    with pytest.raises(SceneError, match=r"^\[friction\] give either"):
        scene_from_dict(data)
