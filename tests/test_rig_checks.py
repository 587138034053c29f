"""``cardan rig``: never a wrong number with exit 0. Each case a synthetic file with one column
changed as a bench gets it wrong (sign convention, speed gain, torque scale, shaft angle), run through
the CLI: its exit status and the one line the user sees."""

from __future__ import annotations

import json
import math
import re

import pytest

from rigdata import files, synthetic
from tests.test_rig_cli import cardan

# 20 N m (not the paper's 0.2 N m): the accuracy class then leaves u(eta) ~ 0.005, so a wrong number
# is far outside it; rpm speed channels carry the gain a pulse count cannot have
SETTINGS = synthetic.RigSettings(input_torque=20.0, revolutions=3.0, speed_channel="rpm",
                                 offsets=(0.0, 0.0), drifts=(0.0, 0.0))


@pytest.fixture(scope="module")
def truth():
    return synthetic.true_signals(SETTINGS)


def rig_file(tmp_path, truth, name, edit=None, settings=SETTINGS):
    """A synthetic CSV with ``edit(table)`` applied to its raw columns first."""
    table, units, used = synthetic.measure(truth, settings)
    if edit is not None:
        edit(table)
    path = tmp_path / name
    files.write_csv(path, table, units, synthetic.metadata(used))
    return path, used


def scaled(column, factor):
    def edit(table):
        table[column] = table[column] * factor
    return edit


def test_unchanged_file_passes_every_check(tmp_path, truth):
    """The control: the same file unchanged measures the truth within 2u, exit 0, status ok."""
    path, used = rig_file(tmp_path, truth, "ok.csv")
    proc = cardan("measure", str(path), "--mc", "0", "--json")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = json.loads(proc.stdout)
    assert out["status"] == "ok"
    assert abs(out["measured_efficiency"] - used["true_efficiency"]) <= 2 * out["measured_efficiency_u"]


def test_reversed_output_torque_is_refused_with_the_option(tmp_path, truth):
    """An output torque recorded with the opposite sign: exit 2, one line naming --sign torque_out=-1;
    with that option the truth comes back."""
    path, used = rig_file(tmp_path, truth, "sign.csv", scaled("Torque Out", -1.0))
    proc = cardan("measure", str(path), "--mc", "0")
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert proc.stdout == ""
    line, = proc.stderr.strip().splitlines()
    assert "output power is negative" in line and "--sign torque_out=-1" in line
    fixed = cardan("measure", str(path), "--mc", "0", "--sign", "torque_out=-1", "--json")
    assert fixed.returncode == 0, fixed.stderr
    out = json.loads(fixed.stdout)
    assert abs(out["measured_efficiency"] - used["true_efficiency"]) <= 2 * out["measured_efficiency_u"]


def test_speed_gain_error_is_inconsistent(tmp_path, truth):
    """A 0.6 % gain on the output speed: the output turns 0.6 % more revolutions than the input, beyond
    the 0.16 % two speed channels of class 0.1 % allow (k=2): exit 3, both counts named."""
    path, _ = rig_file(tmp_path, truth, "gain.csv", scaled("Speed Out", 1.006))
    proc = cardan("measure", str(path), "--mc", "0")
    assert proc.returncode == 3, proc.stdout + proc.stderr
    line, = proc.stdout.strip().splitlines()
    assert "status inconsistent" in line
    assert "output shaft turns 2.01" in line and "input turns 2.00" in line and "+0.60 %" in line
    assert "speed_out" in line


def test_speed_gain_enters_the_budget(tmp_path, truth):
    """Speed channels put a gain row per shaft in the budget: u = 0.1 % / sqrt 3 of eta each."""
    path, _ = rig_file(tmp_path, truth, "budget.csv")
    out = json.loads(cardan("measure", str(path), "--mc", "0", "--json").stdout)
    rows = {b["quantity"]: b for b in out["uncertainty_budget"]}
    for shaft in ("input", "output"):
        assert rows[f"speed gain, {shaft} speed"]["contribution"] == pytest.approx(
            out["measured_efficiency"] * 1e-3 / math.sqrt(3), rel=1e-12)


def test_efficiency_above_one_is_not_a_result(tmp_path, truth):
    """An output torque read 1.45 times too large (a sensitivity typed wrong): efficiency 1.41, far
    beyond 2u above 1: exit 3, status unphysical with the reason, no plain result line."""
    path, _ = rig_file(tmp_path, truth, "scale.csv", scaled("Torque Out", 1.45))
    proc = cardan("measure", str(path), "--mc", "0")
    assert proc.returncode == 3, proc.stdout + proc.stderr
    line, = proc.stdout.strip().splitlines()
    assert "status unphysical" in line and "above 1 by more than 2u" in line
    assert "efficiency 1.4" in line


def test_efficiency_above_one_within_its_uncertainty_is_unresolved(tmp_path, truth):
    """At the paper's 0.2 N m the class alone gives u ~ 0.5: the drawn offsets read 1.44, above 1 but
    within 2u: status unresolved, exit 3 (the number is not an efficiency)."""
    settings = synthetic.RigSettings(revolutions=3.0)
    path, _ = rig_file(tmp_path, synthetic.true_signals(settings), "low.csv", settings=settings)
    proc = cardan("measure", str(path), "--mc", "0")
    assert proc.returncode == 3, proc.stdout + proc.stderr
    line, = proc.stdout.strip().splitlines()
    assert "status unresolved" in line and "within 2u" in line


@pytest.fixture(scope="module")
def thirty(tmp_path_factory):
    settings = synthetic.RigSettings(input_torque=20.0, revolutions=3.0, shaft_angle_deg=30.0,
                                     offsets=(0.0, 0.0), drifts=(0.0, 0.0))
    return rig_file(tmp_path_factory.mktemp("angle"), synthetic.true_signals(settings), "thirty.csv",
                    settings=settings)


def test_validate_warns_of_a_shaft_angle_mismatch(thirty, tmp_path):
    """A 30 deg recording against the scene's 15 deg: a warning line before the run naming the
    recording's angle, a line in the report and the printed checks."""
    path, _ = thirty
    out = tmp_path / "report"
    proc = cardan("validate", str(path), "--engines", "reference", "--mc", "0", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    warned = [line for line in proc.stderr.splitlines() if "warning" in line]
    assert len(warned) == 1
    found, u = map(float, re.search(r"own shaft angle is ([\d.]+) \+- ([\d.]+) deg", warned[0]).groups())
    assert abs(found - 30.0) <= 2 * u  # the recording's true angle, within the fit's own 2u
    assert "the model runs at 15.000 deg" in warned[0] and "--angle auto" in warned[0]
    assert proc.stderr.index("warning") < proc.stderr.index("model driven by the measurement")
    assert "check shaft_angle: mismatch" in proc.stdout
    assert "Check shaft_angle: mismatch." in (out / "report.md").read_text()
    assert json.loads((out / "validation.json").read_text())["status"] == "mismatch"


def test_validate_angle_auto_uses_the_recordings(thirty, tmp_path):
    """--angle auto runs the model at the recording's angle: no warning, the truth computed."""
    path, used = thirty
    out = tmp_path / "report"
    proc = cardan("validate", str(path), "--angle", "auto", "--engines", "reference", "--mc", "0",
                  "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr
    s = json.loads((out / "validation.json").read_text())
    assert s["status"] == "ok"
    # the model at the fitted angle (within its u of 30 deg) gives the true efficiency to the same 2e-3
    # as test_rig_cli's validate at the true angle
    assert s["computed"]["reference"]["mean_efficiency"] == pytest.approx(used["true_efficiency"], abs=2e-3)
