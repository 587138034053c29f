"""The report of ``cardan rig validate`` is reproducible: validation.json and report.md state the scene
(its whole dictionary and hash), shaft angle, friction, versions, command and the file's hash, and the
model runs again from validation.json alone; Figure 10 names what it shows and compares like with like;
the prose says what the numbers are.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import subprocess
import sys
from importlib import metadata

import numpy as np
import pytest

import rigdata
from cardan_exudyn.engines import run
from reference.paper.scenes import named_scene
from reference.scene.mapping import scene_from_dict
from rigdata import synthetic
from rigdata.model import computed_efficiency
from rigdata.record import RigDataError
from rigdata.report import FIGURE_CAPTION, figure, markdown, write_report
from rigdata.validation import validate


@pytest.fixture(scope="module")
def csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("rig") / "bench.csv"
    synthetic.write(path, "csv", synthetic.RigSettings(revolutions=3))
    return path


@pytest.fixture(scope="module")
def validation(csv):
    return validate(csv, named_scene("rig"), engines=("reference",), monte_carlo=0)


@pytest.fixture(scope="module")
def written(validation, tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "rep"
    write_report(validation, out)
    return out, json.loads((out / "validation.json").read_text())


def test_validation_json_alone_reruns_the_same_model(written, validation):
    """The scene stored in validation.json (drive and load included) is the scene that ran: rebuilt
    from the dictionary it equals it, hashes as stored, and runs to the same efficiency; rigdata.rerun
    does the same and refuses a dictionary that does not match its hash."""
    out, s = written
    scene = scene_from_dict(s["scene"]["toml"])
    assert scene == validation.scene
    assert s["scene"]["name"] == validation.scene.name == "rig-physical-measured"
    again = computed_efficiency(run(scene, "reference"))
    assert again["mean_efficiency"] == s["computed"]["reference"]["mean_efficiency"]
    assert rigdata.rerun(out / "validation.json")["mean_efficiency"] == s["computed"]["reference"][
        "mean_efficiency"]
    tampered = copy.deepcopy(s)
    tampered["scene"]["toml"]["joint"]["geometry"]["shaft_angle"] = 0.5
    with pytest.raises(RigDataError, match="does not hash to the stored sha256"):
        rigdata.rerun(tampered)


def test_cli_report_states_scene_angle_friction_versions_command_and_file_hash(csv, tmp_path):
    """validation.json and report.md carry the model's shaft angle and friction, the scene's name and
    hash, the engines' and packages' versions, the command line and the input file's SHA-256."""
    out = tmp_path / "rep"
    argv = ["rig", "validate", str(csv), "--angle", "15", "--friction", "0.3", "--engines", "reference",
            "--mc", "0", "--out", str(out)]
    proc = subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", *argv], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    s = json.loads((out / "validation.json").read_text())
    text = (out / "report.md").read_text()
    file_hash = hashlib.sha256(csv.read_bytes()).hexdigest()
    assert s["file_sha256"] == file_hash and file_hash in text
    assert s["model"]["shaft_angle_deg"] == pytest.approx(15.0, abs=1e-12)
    assert set(s["model"]["friction_coefficient"].values()) == {0.3}
    assert "shaft angle **15.000 deg**, friction coefficient 0.3 in every pair" in text
    assert s["scene"]["sha256"] in text and s["scene"]["name"] in text
    assert s["command"] == "cardan " + " ".join(argv) and s["command"] in text
    env = s["environment"]
    version = metadata.version("cardan-exudyn")
    assert env["engines"]["reference"] == {"package": "cardan-exudyn", "version": version}
    assert env["packages"]["numpy"] == np.__version__ and f"numpy {np.__version__}" in text
    assert "reference (cardan-exudyn " in text


def test_api_report_says_there_was_no_command(written):
    """From the Python API there is no command line: stored as null, said so in the report."""
    out, s = written
    assert s["command"] is None
    assert "Command: none (the Python API, rigdata.validate)." in (out / "report.md").read_text()


def test_figure_names_file_angle_friction_and_synthetic(validation):
    """Figure 10's heading names the file, the shaft angle and friction the model ran with, and says
    SYNTHETIC for a synthetic record only."""
    import matplotlib.pyplot as plt

    fig = figure(validation)
    heading = fig.get_suptitle()
    plt.close(fig)
    assert heading.startswith("SYNTHETIC DATA")
    assert "bench.csv" in heading and "shaft angle 15.000 deg" in heading
    assert "friction coefficient 0.42 in every pair" in heading
    provenance = {k: val for k, val in validation.record.provenance.items() if k != "synthetic"}
    record = dataclasses.replace(validation.record, provenance=provenance)
    real = dataclasses.replace(validation, record=record)
    fig = figure(real)
    heading = fig.get_suptitle()
    plt.close(fig)
    assert "SYNTHETIC" not in heading and "bench.csv" in heading


def test_lower_panel_compares_power_ratio_with_power_ratio(validation, written):
    """The lower panel is measured P_out / P_in minus the model's own P_out / P_in (not its
    1 - P_loss / P_in, which differs within a revolution by the inertia power); the caption says so."""
    import matplotlib.pyplot as plt

    fig = figure(validation)
    line = fig.axes[2].lines[0]
    plt.close(fig)
    inside = validation.conditioned.in_window()
    inst = validation.measured.instantaneous
    t = inst["t"][inside]
    series = validation.computed["reference"]["series"]
    like = inst["efficiency"][inside] - np.interp(t, series["t"], series["power_ratio"])
    unlike = inst["efficiency"][inside] - np.interp(t, series["t"], series["efficiency"])
    assert np.max(np.abs(like - unlike)) > 1e-6  # the two definitions differ here
    np.testing.assert_allclose(line.get_ydata(), like, rtol=0, atol=1e-15)
    assert "P_out / P_in" in line.get_label()
    out, _ = written
    assert FIGURE_CAPTION in (out / "report.md").read_text()
    assert "against the model's own P_out / P_in" in FIGURE_CAPTION


def test_accuracy_class_uncertainty_is_printed_with_its_digits(written):
    """A 0.19 % relative torque uncertainty is printed as 0.19 %, not rounded to 0 %."""
    _, s = written
    text = markdown({**s, "relative_u_torque_in": 0.0019})
    assert "alone gives each torque a 0.19 % standard uncertainty" in text
    assert "a 0 % standard" not in text


@pytest.mark.parametrize("interval, asymmetric", [((0.90, 1.10), False), ((0.95, 1.20), True)])
def test_asymmetric_only_when_the_interval_is(written, interval, asymmetric):
    """The Monte Carlo interval is called asymmetric only when its sides about the estimate differ."""
    _, s = written
    mc = {"samples": 2000, "std": 0.05, "interval_95": list(interval)}
    text = markdown({**s, "measured_efficiency": 1.0, "monte_carlo": mc})
    assert ("asymmetric" in text) is asymmetric
    if asymmetric:
        assert "asymmetric (0.2000 above the estimate, 0.0500 below)" in text
