"""The optional MuJoCo engine against Hooke's closed form, the reference engine and the schema.

Tolerances come from docs/mujoco.md. With the recommended settings (RK4, constraint time
constant 20 steps, impedance 0.9999) at dt = 1e-4 s (300 steps per revolution at 2000 rpm):

- the speed-ratio error is bounded by the documented error model
  (:func:`cardan_exudyn.mujoco.timestep.speed_ratio_error_model`), which over-estimates the
  measured values (3.9e-9 at 10 deg, 2.4e-8 at 30 deg) by 2-40x;
- every constraint force, the drive torque included, misses a fraction of about ``1 - d = 1e-4``
  (MuJoCo caps the impedance d at 0.9999): the measured torque and spider-moment errors are
  5e-5 to 9e-5 of their peak at every step size, so the tolerance is ``2 * (1 - d)`` of the peak.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from benchmarks.mujoco_settings.study import MUJOCO_DEFAULTS, accuracy  # noqa: E402

from cardan_exudyn import engines
from cardan_exudyn.mujoco import MujocoOptions, choose_timestep, speed_ratio_error_model  # noqa: E402
from cardan_exudyn.mujoco import engine as mujoco_engine  # noqa: E402 (after the optional-import skip)
from reference.engine.dynamics import inverse_dynamics  # noqa: E402
from reference.paper.scenes import named_scene  # noqa: E402
from reference.results.columns import table_columns  # noqa: E402
from reference.results.result import Result  # noqa: E402
from reference.results.summary import OptionsError, Status  # noqa: E402
from reference.scene.drives import TorqueDrive  # noqa: E402
from reference.scene.mapping import replace  # noqa: E402
from reference.scene.scene import Scene  # noqa: E402
from reference.scene.settings import Numerics  # noqa: E402
from reference.scene.validation import SceneError  # noqa: E402

DT = 1e-4
STEPS_PER_REVOLUTION = 300  # 2000 rpm at DT
IMPEDANCE_LEAK = 1.0 - 0.9999
ANGLES = (10, 30)


def run(scene: Scene, options: MujocoOptions | None = None) -> Result:
    """The MuJoCo engine through the one dispatch, as every caller runs it."""
    return engines.run(scene, "mujoco", options)


def paper_scene(deg: int, **changes) -> Scene:
    return replace(named_scene(f"paper-{deg}deg-frictionless"), **{"numerics.dt": DT, **changes})


@pytest.fixture(scope="module")
def runs() -> dict:
    """The frictionless paper scenes at 10 and 30 deg, 2000 rpm, recommended settings."""
    out = {}
    for deg in ANGLES:
        scene = paper_scene(deg)
        out[deg] = (scene, run(scene))
    return out


def reference_columns(scene: Scene, t: np.ndarray) -> dict[str, np.ndarray]:
    w = scene.drive.speed
    return inverse_dynamics(scene, w * t, np.full_like(t, w), np.zeros_like(t))


@pytest.mark.parametrize("deg", ANGLES, ids=lambda d: f"{d}deg")
def test_speed_ratio_matches_hooke(runs, deg):
    """omega_out / omega_in follows Hooke's formula within the documented error model."""
    scene, result = runs[deg]
    assert result.success, result.message
    bound = speed_ratio_error_model(scene, MujocoOptions(), STEPS_PER_REVOLUTION)
    assert accuracy(scene, result)["speed_ratio_error"] <= bound


@pytest.mark.parametrize("deg", ANGLES, ids=lambda d: f"{d}deg")
def test_loop_closure_holds(runs, deg):
    """The output axis stays in its bearing: 1e-7 rad and 1e-8 m (measured 2.9e-8, 2.7e-9)."""
    summary = runs[deg][1].summary
    assert summary.max_constraint_violation_rad < 1e-7
    assert summary.max_constraint_violation_m < 1e-8


@pytest.mark.parametrize("deg", ANGLES, ids=lambda d: f"{d}deg")
def test_torque_in_matches_reference(runs, deg):
    """The drive torque equals the reference engine's within twice the impedance leak."""
    scene, result = runs[deg]
    t = result.table["t"].to_numpy()
    desired = reference_columns(scene, t)["torque_in"]
    np.testing.assert_allclose(result.table["torque_in"], desired, rtol=0.0,
                               atol=2.0 * IMPEDANCE_LEAK * np.max(np.abs(desired)))


@pytest.mark.parametrize("deg", ANGLES, ids=lambda d: f"{d}deg")
def test_mean_torque_is_the_load(runs, deg):
    """Over whole revolutions the mean drive torque of a frictionless joint is the load torque.

    Measured 6e-8 (10 deg) and 4e-7 N m (30 deg) at this step; 5x that is the tolerance.
    """
    scene, result = runs[deg]
    np.testing.assert_allclose(result.summary.mean_torque_in, scene.load.torque,
                               rtol=0.0, atol=2e-6)
    np.testing.assert_allclose(result.summary.work_ratio, 1.0, rtol=0.0, atol=1e-6)


@pytest.mark.parametrize("deg", ANGLES, ids=lambda d: f"{d}deg")
def test_spider_moments_match_reference(runs, deg):
    """The spider-pair moments, sign and frame included, equal the reference's (leak tolerance)."""
    scene, result = runs[deg]
    desired = reference_columns(scene, result.table["t"].to_numpy())
    for pair in ("input_spider", "spider_output"):
        peak = max(np.max(np.abs(desired[f"{pair}_{c}"])) for c in ("mx", "my"))
        for component in ("mx", "my", "mz"):
            np.testing.assert_allclose(result.table[f"{pair}_{component}"],
                                       desired[f"{pair}_{component}"], rtol=0.0,
                                       atol=2.0 * IMPEDANCE_LEAK * peak, err_msg=pair + component)


def test_columns_and_summary_follow_the_schema(runs):
    """Same columns as the schema; unfillable reactions are NaN; summary keys of every engine."""
    scene, result = runs[30]
    assert list(result.table.columns) == table_columns()
    unfilled = [f"{p}_{c}" for p in ("frame_input", "output_frame") for c in ("fx", "fy", "fz",
                                                                                "mx", "my", "mz")]
    unfilled += [f"{p}_{c}" for p in ("input_spider", "spider_output") for c in ("fx", "fy", "fz")]
    assert result.table[unfilled].isna().all().all()
    filled = [c for c in table_columns() if c not in unfilled]
    assert result.table[filled].notna().all().all()
    summary = result.summary
    assert summary.status == Status.OK and summary.reason == ""
    for value in (summary.engine_version, summary.scene, summary.dt, summary.steps,
                  summary.wall_time_s, summary.mean_efficiency, summary.mean_torque_in,
                  summary.work_ratio):
        assert value is not None and value == value  # set and not NaN
    assert summary.engine == "mujoco"
    assert summary.dt == DT
    reference = engines.run(scene, "reference").summary
    # the keys of every engine (the reference's), but each engine's own extras
    assert set(summary.to_dict()) - set(summary.extras) == set(reference.to_dict()) - set(reference.extras)
    assert set(summary.to_dict()) >= {"status", "reason", "max_drive_error_rad", "mean_efficiency"}


def test_friction_scene_is_refused():
    """MuJoCo cannot model friction proportional to reactions: the engine raises
    NotImplementedError, which the dispatch reports as the engine being unavailable."""
    with pytest.raises(NotImplementedError, match="friction"):
        mujoco_engine.run(named_scene("paper-literal-10deg"))
    with pytest.raises(engines.EngineUnavailable, match="friction"):
        run(named_scene("paper-literal-10deg"))


def test_unreachable_accuracy_is_refused_before_running():
    """An automatic step needing more steps per revolution than allowed is refused with the
    predicted steps and time (SceneError: ``cardan run`` exits 2), never capped at the limit."""
    scene = replace(named_scene("paper-literal-10deg-frictionless"),
                    **{"joint.geometry.shaft_angle": math.radians(89.9)})
    unreachable = r"speed-ratio error of 0.001 at 89.9 deg needs .* steps per input revolution .* about .* s"
    with pytest.raises(SceneError, match=unreachable):
        choose_timestep(scene, MujocoOptions())
    with pytest.raises(SceneError, match=unreachable):
        run(scene)


def test_mujoco_defaults_are_flagged():
    """MuJoCo's own defaults (Euler, 2 ms, solref 0.02) open the loop: the run is flagged."""
    result = run(named_scene("paper-literal-30deg-frictionless"), MUJOCO_DEFAULTS)
    assert result.status == Status.CONSTRAINT_VIOLATED
    assert result.summary.max_constraint_violation_rad > 0.1


def test_automatic_step_meets_the_accuracy():
    """Without a step, the engine picks one that meets ``numerics.accuracy`` on the speed ratio."""
    scene = replace(named_scene("paper-literal-30deg-frictionless"), **{"numerics.accuracy": 1e-7})
    result = run(scene)
    assert result.summary.dt_choice.startswith("auto")
    assert accuracy(scene, result)["speed_ratio_error"] <= 1e-7


def test_torque_drive_balances_energy():
    """Torque drive: input work = output work + change of mechanical energy (measured 1e-6)."""
    base = named_scene("paper-literal-30deg-frictionless")
    scene = Scene(joint=base.joint, drive=TorqueDrive(torque=3.0, initial_speed=100.0),
                  load=base.load, gravity=base.gravity, revolutions=2.0, numerics=Numerics(dt=DT))
    result = run(scene)
    assert result.success, result.message
    table = result.table
    assert table["theta_in"].iloc[-1] >= 2.0 * 2.0 * math.pi
    t = table["t"].to_numpy()

    def work(power: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])

    net = work((table["power_in"] - table["power_out"]).to_numpy())
    energy = (table["energy_kinetic"] + table["energy_potential"]).to_numpy()
    input_work = work(table["power_in"].to_numpy())[-1]
    np.testing.assert_allclose(net, energy - energy[0], rtol=0.0, atol=1e-5 * input_work)


@pytest.mark.parametrize("kwargs, match", [
    ({"integrator": "Verlet"}, "integrator"),
    ({"solimp": (0.9, 1.0, 0.001, 0.5, 2)}, "solimp"),
    ({"solref": (-1.0, 2.0)}, "solref"),
    ({"o_solref": "soft"}, "o_solref"),
    ({"timeconst_steps": 0}, "timeconst_steps"),
    ({"iterations": 0}, "iterations"),
], ids=["integrator", "solimp", "solref", "o_solref", "timeconst", "iterations"])
def test_invalid_settings_are_rejected(kwargs, match):
    """Bad settings raise OptionsError (a ValueError) naming the argument."""
    with pytest.raises(OptionsError, match=match):
        MujocoOptions(**kwargs)
