"""A measured load: the output torque as a history, in the scene and in both engines."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cardan_exudyn import run
from reference.paper import named_scene
from reference.scene import AngleDrive, Load, scene_from_dict, scene_to_dict
from reference.scene_files import load_scene
from reference.validation import SceneError

SPEED = 6.0
SPAN = 2 * np.pi * 2.2 / SPEED


def driven(load: Load, revolutions: float = 2.0):
    """The rig case driven by a fluctuating input angle (a motor's 2x ripple), ``load`` on it."""
    t = np.linspace(0.0, SPAN, 400)
    angle = SPEED * t + 0.03 * np.sin(2 * SPEED * t)
    return replace(named_scene("rig-calibrated"), drive=AngleDrive(tuple(t), tuple(angle)), load=load,
                   revolutions=revolutions)


def varying() -> Load:
    t = np.linspace(0.0, SPAN, 300)
    return Load(tuple(0.2 + 0.03 * np.sin(3.0 * t)), tuple(t))


@pytest.mark.parametrize("kwargs, match", [
    ({"torque": (1.0, 2.0)}, "needs `time`"),
    ({"torque": (1.0, 2.0), "time": (0.0,)}, "at least 2"),
    ({"torque": (1.0,), "time": (0.0, 1.0)}, "one value per time sample"),
    ({"torque": (1.0, float("nan")), "time": (0.0, 1.0)}, "finite"),
    ({"torque": (1.0, 2.0, 3.0), "time": (0.0, 2.0, 1.0)}, "strictly increasing"),
    ({"torque": 1.0, "time": (0.0, 1.0)}, "one value per time sample"),
], ids=["no-time", "short", "length", "nan", "order", "scalar-with-time"])
def test_load_history_validation(kwargs, match):
    """A malformed torque history is refused with a message naming what is wrong."""
    with pytest.raises(SceneError, match=match):
        Load(**kwargs)


def test_load_history_interpolates_and_holds():
    """Linear in between, held at the end values outside, mean by the trapezoid rule."""
    load = Load((1.0, 3.0, 2.0), (0.0, 1.0, 2.0))
    np.testing.assert_allclose(load.at([-1.0, 0.5, 1.5, 5.0]), [1.0, 2.0, 2.5, 2.0], rtol=0, atol=0)
    assert load.mean() == pytest.approx((2.0 + 2.5) / 2.0, abs=1e-15)
    assert Load(0.7).at(np.zeros((2, 3))).shape == (2, 3)


def test_load_history_round_trips_through_toml(tmp_path):
    """A scene with a load history is written and read back unchanged."""
    import tomli_w

    scene = driven(varying())
    path = tmp_path / "s.toml"
    path.write_bytes(tomli_w.dumps(scene_to_dict(scene)).encode())
    assert load_scene(path).load == scene.load
    assert scene_from_dict(scene_to_dict(scene)) == scene


def test_flat_history_equals_constant_load():
    """A flat two-sample history gives the constant load's result to rounding (reference)."""
    flat = run(driven(Load((0.2, 0.2), (0.0, SPAN))), "reference")
    constant = run(driven(Load(0.2)), "reference")
    assert flat.summary.mean_efficiency == pytest.approx(constant.summary.mean_efficiency,
                                                            rel=0, abs=1e-12)


def test_load_history_energy_balance_and_torque_out_column():
    """The reference's table carries the history; input work = output + loss + energy change."""
    scene = driven(varying())
    result = run(scene, "reference")
    assert result.summary.status == "ok"
    table = result.table
    np.testing.assert_allclose(table["torque_out"], scene.load.at(table["t"]), rtol=0, atol=1e-15)
    assert abs(result.summary.extras["energy_balance_residual"]) < 1e-9 * result.summary.input_work


def test_load_history_exudyn_matches_reference():
    """Exudyn (load user function) and the reference agree on a varying load.

    Exudyn at its automatic step for 1e-5 speed-ratio accuracy: its mean-efficiency error on the
    rig scenes was 2e-6..1e-5 (README); 3e-5 allows the friction's under-resolved sign ramps."""
    scene = driven(varying())
    ref, exu = run(scene, "reference"), run(scene)
    assert exu.summary.status == "ok"
    assert exu.summary.mean_efficiency == pytest.approx(ref.summary.mean_efficiency, abs=3e-5)
    t = exu.table["t"].to_numpy()
    np.testing.assert_allclose(exu.table["torque_out"], scene.load.at(t), rtol=0, atol=1e-15)
    # the load matters: doubling its ripple would be visible in the input torque
    ref_in = np.interp(t, ref.table["t"], ref.table["torque_in"])
    assert np.max(np.abs(exu.table["torque_in"] - ref_in)) < 5e-3 * np.max(np.abs(ref_in))


def test_mujoco_refuses_load_history():
    """MuJoCo takes constant loads only and says so, through the dispatch."""
    pytest.importorskip("mujoco")
    from cardan_exudyn.engines import EngineUnavailable

    scene = replace(named_scene("rig-frictionless"), load=Load((0.2, 0.2), (0.0, 10.0)))
    with pytest.raises(EngineUnavailable, match="load history"):
        run(scene, "mujoco")
