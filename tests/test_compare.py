"""Exudyn against the reference engine on the paper's scenes, and the `compare` machinery.

The reference engine has no time-stepping error (prescribed motion is solved sample by sample,
the work integrals by adaptive quadrature), so the differences are Exudyn's discretisation
error. Exudyn's integrator (generalized-alpha, index 3) is second order, so the difference must
be at most ``(omega h)^2`` (the dimensionless
step squared) for the mean efficiency, halving the step must divide the differences by about
four, and Richardson extrapolation of two Exudyn runs must land on the reference. These claims
hold where the friction sign ramps are resolved by the step: the default ramp (1e-3 of each
pair's characteristic speed, ``reference.physics.bands``) spans about 1.5e-3 rad of input angle and makes
the mean-efficiency error first order at any affordable step (``docs/accuracy.md``), so the
friction scenes here use a ramp of ``RAMP_RELATIVE`` (0.1 rad wide, four steps at 200 steps per
revolution): both engines solve the same regularised model. The
first quarter revolution is left out of the per-row statistics: it holds the integrator's
start-up transient, which decays geometrically in steps (see the README).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cardan_exudyn import ExudynOptions
from cardan_exudyn.cli import main
from cardan_exudyn.comparison import Comparison, compare, join_on_input_angle
from cardan_exudyn.engines import run
from cardan_exudyn.jsonable import dumps
from reference.engine.options import ReferenceOptions
from reference.paper.scenes import named_scene
from reference.results.summary import OptionsError, Status
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace

SKIP = 0.25  # revolutions left out of the steady statistics
RAMP_RELATIVE = 0.1  # sign ramp resolved by the step (see the module docstring)
SCENES = ["paper-literal-30deg-frictionless", "paper-literal-10deg", "paper-matched-30deg"]


def kind_scales(table) -> dict[str, float]:
    """Largest magnitude of each kind of quantity in a table (the scale errors are measured in)."""
    forces = [f"{p}_f{c}" for p in PAIR_NAMES for c in "xy"]
    moments = [f"{p}_m{c}" for p in PAIR_NAMES for c in "xy"] + ["torque_in"]
    return {"force": float(table[forces].abs().to_numpy().max()),
            "moment": float(table[moments].abs().to_numpy().max()),
            "speed": float(table["omega_in"].abs().max()),
            "power": float(table["power_in"].abs().max()),
            "angle": 1.0}


def kind_of(column: str) -> str:
    if column.startswith("power"):
        return "power"
    if column.startswith("theta"):
        return "angle"
    if column.startswith("omega"):
        return "speed"
    if column.endswith(("_fx", "_fy")):
        return "force"
    return "moment"


CHECKED = (["theta_out", "omega_out", "torque_in"]
           + [f"{p}_{c}" for p in PAIR_NAMES for c in ("fx", "fy", "mx", "my", "friction_torque")]
           + [f"power_loss_{p}" for p in PAIR_NAMES])


def run_pair(name: str, steps_per_revolution: int) -> tuple[Comparison, float]:
    base = named_scene(name)
    h = 2 * math.pi / abs(base.drive.speed) / steps_per_revolution
    scene = replace(base, revolutions=1, **{"numerics.dt": h})
    if scene.has_friction:  # the converged coupling: its per-step fixed point is second order
        # with a resolved ramp; the extrapolated one is at 400 steps/rev (2.7e-4 here, ratio 4.5
        # to 800; tests/test_coupling_lean.py holds it to its own measurements)
        scene = replace(scene, **{"friction.sign_band_relative": RAMP_RELATIVE,
                                  "friction.coupling": "converged"})
    wh2 = (2 * math.pi / steps_per_revolution) ** 2
    return compare(scene, ["exudyn", "reference"], skip_revolutions=SKIP), wh2


@pytest.fixture(scope="module")
def ladder():
    return {(name, spr): run_pair(name, spr) for name in SCENES for spr in (200, 400)}


@pytest.mark.parametrize("name", ["paper-literal-30deg-frictionless"])
def test_richardson_extrapolated_exudyn_predicts_the_reference(ladder, name):
    """Every checked column (kinematics, each pair's reactions and friction, input torque,
    per-pair loss): Exudyn's error is its leading second-order term. Extrapolating Exudyn's own
    runs at h and h/2, (4 E(h/2) - E(h)) / 3, lands on the reference engine far closer than
    either run: within a quarter of the finer run's difference, on every steady row.

    Frictionless only: with friction, some columns are not yet in the asymptotic regime at these
    steps (the spider friction sign ramp, 0.3 deg wide, is narrower than a step of 0.9-1.8 deg,
    and the frame bearing moments converge faster than second order near 180 deg; measured
    RMS ratios E(h) / E(h/2) of 3-7); those scenes are held to the weaker claims below."""
    coarse, _ = ladder[(name, 200)]
    fine, _ = ladder[(name, 400)]
    e_h, ref = coarse.results["exudyn"].table, coarse.results["reference"].table
    e_h2 = fine.results["exudyn"].table.iloc[::2].reset_index(drop=True)  # the rows at t = k h
    assert np.allclose(e_h2["t"], e_h["t"], rtol=0, atol=1e-12)
    theta = e_h["theta_in"].to_numpy()
    steady = np.abs(theta - theta[0]) >= 2 * math.pi * SKIP
    failures = {}
    for column in CHECKED:
        r = ref[column].to_numpy()[steady]
        fine_error = np.max(np.abs(e_h2[column].to_numpy()[steady] - r))
        extrapolated = (4 * e_h2[column].to_numpy() - e_h[column].to_numpy()) / 3
        residual = np.max(np.abs(extrapolated[steady] - r))
        # Exudyn's Newton stops at a relative tolerance of 1e-10 (ExudynOptions); differences
        # of columns that are ~0 sit at ~1e-9 of their kind's scale (measured): solver noise
        floor = 1e-8 * kind_scales(e_h)[kind_of(column)]
        if residual > 0.25 * fine_error + floor:
            failures[column] = residual / fine_error
    assert not failures, f"extrapolated / fine difference: {failures}"


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.parametrize("spr", [200, 400])
def test_mean_efficiency_within_the_second_order_bound(ladder, name, spr):
    comparison, wh2 = ladder[(name, spr)]
    results = comparison.results
    assert results["exudyn"].status == results["reference"].status == Status.OK
    assert abs(comparison.differences["reference"].means["mean_efficiency"]) <= wh2


@pytest.mark.parametrize("name", SCENES)
def test_differences_shrink_with_the_step(ladder, name):
    """Halving Exudyn's step divides the RMS steady difference of every checked column by about
    4 (second order) without friction; with friction by at least 2.5 (the sign ramps narrower
    than a step keep some columns away from their asymptotic rate at these steps, on either
    side), and the drive torque and output speed still by about 4."""
    coarse = ladder[(name, 200)][0].differences["reference"].steady
    fine = ladder[(name, 400)][0].differences["reference"].steady
    scales = kind_scales(ladder[(name, 200)][0].results["exudyn"].table)
    frictionless = name.endswith("frictionless")
    for column in CHECKED:
        if coarse.loc[column, "rms"] <= 1e-8 * scales[kind_of(column)]:
            continue  # zero in both engines up to solver noise (e.g. friction without friction)
        ratio = coarse.loc[column, "rms"] / fine.loc[column, "rms"]
        if frictionless or column in ("torque_in", "omega_out"):
            assert 3.0 < ratio < 5.0, (column, ratio)
        else:
            assert ratio > 2.5, (column, ratio)  # measured up to 8.5 (frame_input_my)


def test_join_interpolates_when_rows_differ():
    """Different sampling: the spline join reproduces a smooth column far below the differences
    the comparison measures (reference sampled at two resolutions against itself)."""
    scene = replace(named_scene("paper-literal-20deg-frictionless"), revolutions=1)
    a = run(scene, "reference", ReferenceOptions(samples_per_revolution=720)).table
    b = run(scene, "reference", ReferenceOptions(samples_per_revolution=360)).table
    joined, how = join_on_input_angle(a, b)
    assert how.startswith("cubic spline")
    # cubic interpolation error ~ h^4 f'''' / 384 with h = 1 deg: ~1e-9 of the scale
    for column in ("torque_in", "omega_out", "frame_input_fx"):
        scale = np.max(np.abs(a[column]))
        assert np.nanmax(np.abs(joined[column] - a[column])) < 1e-6 * scale


def test_cli_compare_json_and_report(tmp_path, capsys):
    out = tmp_path / "cmp"
    code = main(["compare", "--name", "paper-literal-10deg-frictionless", "--revolutions", "1",
                 "--engines", "exudyn,reference", "--skip-revolutions", "0.25", "--json",
                 "--out", str(out)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data["engines"]) == {"exudyn", "reference"}
    d = data["differences"]["reference"]
    assert d["against"] == "exudyn" and "torque_in" in d["steady"] and "mean_efficiency" in d["means"]
    names = {p.name for p in out.iterdir()}
    assert {"comparison.json", "report.md", "exudyn.csv", "reference.csv",
            "overlay_kinematics.png", "overlay_losses.png", "overlay_reactions.png"} <= names


@pytest.mark.parametrize("engines, message", [
    ("exudyn", "at least two engines"),
    ("exudyn,exudyn", "twice"),
    ("exudyn,nosuch", "must be one of"),
    ("reference,mujoco", "cannot run"),  # the scene has friction: MuJoCo cannot express eq. (3)
])
def test_cli_compare_bad_engines(tmp_path, capsys, engines, message):
    out = tmp_path / "cmp"
    code = main(["compare", "--name", "paper-literal-10deg", "--revolutions", "1", "--engines", engines,
                 "--out", str(out)])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()  # nothing half-written


def test_comparison_api(ladder):
    """The typed comparison: statistics per column as a DataFrame, the JSON shape of the report,
    and the differing columns as a text table."""
    comparison, _ = ladder[("paper-literal-30deg-frictionless", 200)]
    assert comparison.base == "exudyn" and comparison.success
    d = comparison.differences["reference"]
    assert d.against == "exudyn" and d.join == "same rows"
    assert list(d.steady.columns) == ["max_abs", "rms", "scale", "max_rel", "rows"]
    assert d.steady.index.name == "column" and "torque_in" in d.steady.index
    row = d.steady.loc["torque_in"]
    assert row["max_rel"] == pytest.approx(row["max_abs"] / row["scale"])
    assert 0 < row["rms"] <= row["max_abs"]
    data = json.loads(dumps(comparison.to_dict()))
    assert set(data) == {"scene", "skip_revolutions", "engines", "differences"}
    assert data["engines"]["reference"]["status"] == "ok"
    assert set(data["differences"]["reference"]["all"]["torque_in"]) == {"max_abs", "rms", "scale", "rows"}
    assert data["differences"]["reference"]["steady"]["torque_in"]["rms"] == pytest.approx(row["rms"])
    # nothing differs by its own scale; at 1e-12 of the scale the torque does
    assert comparison.differing(rtol=1.0).empty
    differing = comparison.differing(rtol=1e-12)
    assert "torque_in" in set(differing["column"]) and set(differing["engine"]) == {"reference"}
    text = comparison.differences_table(rtol=1e-12)
    assert text.startswith("| engine | column | max_abs | rms | scale | max_rel |")
    assert "| reference | torque_in |" in text and "nan" not in text


def test_compare_passes_each_engine_its_options():
    scene = replace(named_scene("paper-literal-10deg-frictionless"), revolutions=1)
    options = {"reference": ReferenceOptions(gauss_nodes=6)}
    comparison = compare(scene, ("exudyn", "reference"), options=options)
    assert comparison.results["reference"].summary.options["gauss_nodes"] == 6
    assert comparison.results["exudyn"].success and comparison.results["reference"].success


@pytest.mark.parametrize("options, message", [
    ({"mujoco": ReferenceOptions()}, "not among"),
    ({"reference": ExudynOptions()}, "not the options of engine 'reference'"),
])
def test_compare_refuses_wrong_options_before_running(options, message):
    scene = named_scene("paper-literal-10deg-frictionless")
    with pytest.raises(OptionsError, match=message):
        compare(scene, ("exudyn", "reference"), options=options)


def test_the_package_function_survives_the_module_import():
    """`cardan_exudyn.compare` is the function, also after its module has been imported (a
    submodule named `compare` would have replaced it)."""
    import cardan_exudyn
    import cardan_exudyn.comparison

    assert cardan_exudyn.compare is compare and cardan_exudyn.Comparison is Comparison
