"""Richardson extrapolation of two Exudyn runs (``numerics.richardson``,
cardan_exudyn.model.richardson): exact for an error ``c h^2``, closer to the reference engine than
either run, round-tripped by scene files, and selectable (and refused) from ``cardan run``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cardan_exudyn import ExudynOptions, run
from cardan_exudyn.cli import main
from cardan_exudyn.model import richardson
from reference.engine.motion import input_motion
from reference.engine.options import ReferenceOptions
from reference.engine.table import columns_at
from reference.paper.scenes import named_scene
from reference.physics.kinematics import speed_ratio
from reference.scene.files import load_scene
from reference.scene.mapping import replace
from reference.scene.validation import SceneError

SCENE = "paper-literal-35deg-frictionless"


def _columns(t: np.ndarray, h: float) -> dict[str, np.ndarray]:
    """A hand-made table whose extrapolated columns are exact histories plus ``c h^2`` (c a
    function of time), and whose filtered (force-level) columns are linear in time."""
    exact = {"omega_in": 200.0 + 0.0 * t, "omega_out": 200.0 + 30.0 * np.sin(400.0 * t),
             "torque_in": 2.0 + 5.0 * t, "energy_kinetic": 1.0 + t ** 2}
    error = {"omega_in": 0.0 * t, "omega_out": 7.0 * np.cos(400.0 * t), "torque_in": 3.0 + 4.0 * t,
             "energy_kinetic": -2.0 * t}
    cols = {k: exact[k] + error[k] * h ** 2 for k in exact}
    cols.update(t=t, theta_in=200.0 * t, theta_out=200.0 * t + h, torque_out=np.full_like(t, 1.5),
                energy_potential=np.zeros_like(t), power_loss=np.zeros_like(t))
    return cols


def test_combination_is_exact_for_an_error_c_h2():
    """On a hand-made pair of tables with error exactly ``c(t) h^2`` (h and h/2), the combination
    returns the exact histories to rounding; positions come from the fine run; the powers are
    recomputed from the combined torques and speeds."""
    h = 1e-3
    t_c, t_f = np.arange(11) * h, np.arange(21) * h / 2
    combined = richardson.combine(_columns(t_c, h), _columns(t_f, h / 2))
    assert np.max(np.abs(combined["torque_in"] - (2.0 + 5.0 * t_c))) < 1e-12
    assert np.max(np.abs(combined["omega_out"] - (200.0 + 30.0 * np.sin(400.0 * t_c)))) < 1e-11
    assert np.max(np.abs(combined["energy_kinetic"] - (1.0 + t_c ** 2))) < 1e-12
    assert np.array_equal(combined["theta_out"], 200.0 * t_c + h / 2)  # the fine run's
    assert np.array_equal(combined["power_in"], combined["torque_in"] * combined["omega_in"])
    assert np.array_equal(combined["t"], t_f[::2])


def test_combination_refuses_grids_that_are_not_halved():
    h = 1e-3
    with pytest.raises(ValueError, match="halved"):
        richardson.combine(_columns(np.arange(11) * h, h), _columns(np.arange(21) * h / 3, h / 3))


def test_smoothing_removes_an_alternating_component():
    """The start-up oscillation of generalized-alpha alternates from row to row: the filter
    removes it from the inner rows and keeps a linear history."""
    t = np.linspace(0.0, 1.0, 9)
    smoothed = richardson.smooth(3.0 * t + (-1.0) ** np.arange(9))
    assert np.allclose(smoothed[1:-1], 3.0 * t[1:-1], atol=1e-14)


def _steady_torque_error(scene, result) -> float:
    table = result.table
    t = table["t"].to_numpy()
    ref = columns_at(scene, input_motion(scene, ReferenceOptions()), t)["torque_in"]
    theta = table["theta_in"].to_numpy()
    steady = np.abs(theta - theta[0]) >= 2.0 * math.pi - 1e-9
    return float(np.max(np.abs(table["torque_in"].to_numpy()[steady] - ref[steady])) / np.max(np.abs(ref)))


def test_extrapolated_drive_torque_is_closer_to_the_reference_than_either_run():
    """35 deg, 2 revolutions at 25 and 50 steps per revolution (with the projection). Measured
    steady drive-torque errors: 4.1e-2 and 8.5e-3 for the runs, 1.7e-3 for the combination; the
    test asks for half the better run's (margin 2.5x). The speed ratio stays exact."""
    base = named_scene(SCENE)
    dt = 2.0 * math.pi / base.drive.max_speed() / 25
    options = ExudynOptions(modified_newton=True, jacobian_every_step=True, newton_relative_tolerance=1e-8,
                            velocity_projection=True)
    coarse = run(replace(base, **{"numerics.dt": dt}), options=options)
    fine = run(replace(base, **{"numerics.dt": dt / 2}), options=options)
    combined = run(replace(base, **{"numerics.dt": dt, "numerics.richardson": True}), options=options)
    assert coarse.success and fine.success and combined.success
    errors = [_steady_torque_error(base, r) for r in (coarse, fine, combined)]
    assert errors[2] < 0.5 * min(errors[:2]), errors
    # the projected speeds are exact for the computed positions: Hooke's ratio to rounding
    table = combined.table
    hooke = speed_ratio(table["theta_in"].to_numpy(), base.joint.geometry.shaft_angle)
    assert np.max(np.abs(table["omega_out"] / table["omega_in"] - hooke)) < 1e-12
    assert len(combined.table) == len(coarse.table)
    assert combined.summary.steps == coarse.summary.steps + fine.summary.steps
    info = combined.summary.extras["richardson"]
    assert info["fine_dt"] == pytest.approx(0.5 * info["coarse_dt"], rel=1e-12)


def test_richardson_with_friction_is_refused():
    scene = replace(named_scene("paper-literal-35deg"), **{"numerics.richardson": True})
    with pytest.raises(SceneError, match="frictionless scenes only"):
        run(scene)


def test_scene_file_round_trips_richardson(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(f'base = "{SCENE}"\n[numerics]\nrichardson = true\n', encoding="utf-8")
    scene = load_scene(path)
    assert scene.numerics.richardson is True
    assert named_scene(SCENE).numerics.richardson is False
    path.write_text(f'base = "{SCENE}"\n[numerics]\nrichardson = 1\n', encoding="utf-8")
    with pytest.raises(SceneError, match="richardson"):
        load_scene(path)


def test_cli_flags(tmp_path, capsys):
    """``--richardson --projection`` run (exit 0, the summary says what was combined); each is
    refused, one line and exit 2, where it does not apply."""
    import json

    assert main(["run", "--name", SCENE, "--revolutions", "2", "--dt", "0.0006", "--richardson",
                 "--projection", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["options"]["velocity_projection"] is True
    assert summary["scene"]["numerics"]["richardson"] is True
    assert "torque_in" in summary["richardson"]["extrapolated"]  # extras are top-level keys
    for argv, message in ((["--engine", "reference", "--projection"], "--projection"),
                          (["--name", "paper-literal-35deg", "--richardson"], "frictionless scenes only")):
        argv = ["run", *(["--name", SCENE] if "--name" not in argv else []), *argv]
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1
