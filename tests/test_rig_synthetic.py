"""``cardan rig synthetic`` and ``rigdata.synthetic`` as a test-matrix generator: each option written,
read back and measured, its effect found within the measurement's own uncertainty; bad values refused
in one line naming the option."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import rigdata
from rigdata import files, synthetic
from rigdata.conditioning import condition

#: Exact transducers (no offsets or drift) at 20 N m: the uncertainty is the noise's and the class's.
BASE = {"input_torque": 20.0, "revolutions": 3.0, "offsets": (0.0, 0.0), "drifts": (0.0, 0.0)}
#: A 5 N m transducer of class 0.05 % giving 2 V/(N m) (an acquisition step of 1.5e-4 N m): torques of
#: 1-4 N m resolved to about 1e-3 of their value.
FINE = rigdata.Transducer(full_scale=5.0, accuracy_class=5e-4, sensitivity=2.0)


def cardan(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", "rig", *args],
                          capture_output=True, text=True, timeout=300)


def written(tmp_path, name="run.csv", transducer=None, **changes):
    """Write a synthetic file with ``BASE`` + ``changes``; its record read back and ``used``."""
    settings = synthetic.RigSettings(**{**BASE, **changes})
    path = tmp_path / name
    used = synthetic.write(path, path.suffix[1:], settings, transducer)
    t = transducer or rigdata.Transducer()
    return rigdata.read(path, sensitivity=t.sensitivity, pulses_per_rev=t.pulses_per_rev), used


def fitted_angle(rec) -> tuple[float, float]:
    """The recording's own shaft angle and its standard uncertainty [deg] (Hooke's ratio fit)."""
    beta = math.radians(15.0)
    for _ in range(2):
        fit = condition(rec, beta).phase_fit
        beta = fit["shaft_angle_fit"]
    return math.degrees(beta), math.degrees(fit["shaft_angle_fit_u"])


def test_angle_30_gives_a_30_degree_recording(tmp_path):
    """``shaft_angle_deg=30``: the file's fitted shaft angle is 30 deg within 2u; the metadata says 30."""
    rec, used = written(tmp_path, shaft_angle_deg=30.0)
    angle, u = fitted_angle(rec)
    assert abs(angle - 30.0) <= 2 * u
    assert json.loads(rec.provenance["synthetic"]["settings"])["shaft_angle_deg"] == 30.0


def test_friction_zero_gives_efficiency_one(tmp_path):
    """``friction=0``: true efficiency 1, measured 1 within 2u (the default 0.42 is 0.97, far outside)."""
    rec, used = written(tmp_path, friction=0.0)
    m = rigdata.measure(rec, 15.0, monte_carlo=0)
    assert used["true_efficiency"] == pytest.approx(1.0, abs=1e-12)
    assert abs(m.efficiency - 1.0) <= 2 * m.u
    default = rigdata.measure(written(tmp_path, "default.csv")[0], 15.0, monte_carlo=0)
    assert 1.0 - default.efficiency > 5 * default.u


def test_named_scene_sets_the_joint(tmp_path):
    """``scene="rig-frictionless"`` is the frictionless rig: efficiency 1 within 2u."""
    rec, used = written(tmp_path, scene="rig-frictionless")
    m = rigdata.measure(rec, 15.0, monte_carlo=0)
    assert abs(m.efficiency - 1.0) <= 2 * m.u


def test_scene_file_sets_the_joint(tmp_path):
    """A scene TOML file (``base = "rig"``, 25 deg) is the joint: its angle is the recording's."""
    scene = tmp_path / "joint.toml"
    scene.write_text('base = "rig"\n[joint.geometry]\nshaft_angle_deg = 25.0\n')
    rec, used = written(tmp_path, scene=str(scene))
    angle, u = fitted_angle(rec)
    assert abs(angle - 25.0) <= 2 * u and used["scene"] == str(scene)


def test_load_sets_the_brake_torque(tmp_path):
    """``load_torque=5``: the measured mean output torque is 5 N m and the input torque 5/eta, within
    their uncertainties; at 20 N m input they are four times larger."""
    rec, used = written(tmp_path, load_torque=5.0)
    m = rigdata.measure(rec, 15.0, monte_carlo=0).as_dict()
    assert used["brake_torque"] == 5.0 and used["input_torque"] is None
    t_out = m["mean_torque_out"]
    assert abs(t_out - 5.0) <= 2 * m["relative_u_torque_out"] * t_out
    t_in = m["mean_torque_in"]
    assert abs(t_in - 5.0 / used["true_efficiency"]) <= 2 * m["relative_u_torque_in"] * t_in + 0.01
    heavy = rigdata.measure(written(tmp_path, "heavy.csv")[0], 15.0, monte_carlo=0).as_dict()
    assert heavy["mean_torque_out"] > 3.5 * t_out


def test_speed_and_rate(tmp_path):
    """``speed`` and ``rate``: the measured mean input speed and the file's sample rate."""
    rec, used = written(tmp_path, speed=20.0, rate=3000.0, revolutions=4.0)
    assert rec.sample_rate == pytest.approx(3000.0)
    m = rigdata.measure(rec, 15.0, monte_carlo=0).as_dict()
    assert m["mean_speed_in"] == pytest.approx(20.0, rel=1e-3)  # ripple 1 %, whole revolutions


def test_noise_is_the_measured_noise(tmp_path):
    """``noise=0.05``: the measurement's torque noise estimate is 0.05 N m within 20 %."""
    m = rigdata.measure(written(tmp_path, noise=0.05)[0], 15.0, monte_carlo=0).as_dict()
    assert m["noise_torque_in"] == pytest.approx(0.05, rel=0.2)


def test_transducer_settings_reach_file_and_metadata(tmp_path):
    """360 pulses per revolution and a 50 N m, 0.05 % transducer: the angle resolution of the file is 1 deg
    and the settings are in its metadata."""
    t = rigdata.Transducer(pulses_per_rev=360, full_scale=50.0, accuracy_class=5e-4)
    rec, used = written(tmp_path, transducer=t)
    assert math.degrees(rec.sources["angle_in"].quantum) == pytest.approx(1.0)
    stored = json.loads(rec.provenance["synthetic"]["settings"])["transducer"]
    assert stored == t.as_dict()


def test_negative_output_torque_convention(tmp_path):
    """``torque_out_sign=-1``: the output torque column is negative, refused as it stands, and read with
    ``signs`` gives the true efficiency within 2u."""
    rec, used = written(tmp_path, torque_out_sign=-1)
    assert rec.channels["torque_out"].mean() < 0
    with pytest.raises(rigdata.RigDataError, match="torque_out=-1"):
        rigdata.measure(rec, 15.0, monte_carlo=0)
    flipped = rigdata.measure(rec, 15.0, monte_carlo=0, signs={"torque_out": -1})
    assert abs(flipped.efficiency - used["true_efficiency"]) <= 2 * flipped.u


@pytest.mark.parametrize("fmt", ["mat", "parquet"])
def test_binary_formats_measure_like_csv(tmp_path, fmt):
    """``mat`` (scipy.io v5) and ``parquet``: labelled synthetic, the CSV's efficiency."""
    if fmt == "parquet":
        pytest.importorskip("pyarrow")
    rec, used = written(tmp_path, f"run.{fmt}")
    assert rec.provenance["format"] == fmt
    assert json.loads(rec.provenance["synthetic"]["settings"])["seed"] == used["seed"]
    csv = rigdata.measure(written(tmp_path)[0], 15.0, monte_carlo=0)
    assert rigdata.measure(rec, 15.0, monte_carlo=0).efficiency == pytest.approx(csv.efficiency, rel=1e-12)


@pytest.mark.parametrize("fmt, decimal", [("csv", ","), ("lvm", ".")], ids=["csv-comma", "lvm-point"])
def test_decimal_mark_reads_back(tmp_path, fmt, decimal):
    """``decimal``: csv with a decimal comma (fields apart by ';'), lvm with a decimal point; the reader
    finds the layout and reads the numbers of the plain CSV to the last digit."""
    settings = synthetic.RigSettings(**BASE)
    truth = synthetic.true_signals(settings)
    synthetic.write(tmp_path / f"mark.{fmt}", fmt, settings, truth=truth, decimal=decimal)
    synthetic.write(tmp_path / "plain.csv", "csv", settings, truth=truth)
    last = (tmp_path / f"mark.{fmt}").read_text().splitlines()[-1]
    other = "." if decimal == "," else ","
    assert decimal in last and other not in last and (";" in last) == (fmt == "csv")
    marked = rigdata.read(tmp_path / f"mark.{fmt}")
    plain = rigdata.read(tmp_path / "plain.csv")
    for name, values in plain.channels.items():
        np.testing.assert_array_equal(marked.channels[name], values, err_msg=name)
    np.testing.assert_array_equal(marked.time, plain.time)
    assert marked.provenance["synthetic"]["settings"] == plain.provenance["synthetic"]["settings"]


@pytest.mark.parametrize("fmt", ["tdms", "mat", "mdf"])
def test_decimal_mark_refused_for_binary_formats(tmp_path, fmt):
    with pytest.raises(ValueError, match=f"`decimal` must be .* got ',' for {fmt}"):
        synthetic.write(tmp_path / "x", fmt, decimal=",")


def test_mdf4_round_trip(tmp_path):
    """``fmt="mdf"``: an ASAM MDF 4 file (asammdf) read back labelled synthetic with its settings, every
    column's unit as written, and the plain CSV's numbers to the last digit (MDF stores doubles)."""
    pytest.importorskip("asammdf")
    settings = synthetic.RigSettings(**BASE)
    truth = synthetic.true_signals(settings)
    used = synthetic.write(tmp_path / "run.mf4", "mdf", settings, truth=truth)
    synthetic.write(tmp_path / "run.csv", "csv", settings, truth=truth)
    assert (tmp_path / "run.mf4").read_bytes().startswith(b"MDF     4.10")
    rec = rigdata.read(tmp_path / "run.mf4")
    plain = rigdata.read(tmp_path / "run.csv")
    assert rec.provenance["format"] == "mdf"
    assert json.loads(rec.provenance["synthetic"]["settings"]) == json.loads(json.dumps(used))
    assert rec.provenance["synthetic"]["generator"] == synthetic.GENERATOR
    assert {k: s.unit for k, s in rec.sources.items()} == {"torque_in": "V", "torque_out": "V",
                                                           "angle_in": "counts", "angle_out": "counts"}
    for name, values in plain.channels.items():
        np.testing.assert_array_equal(rec.channels[name], values, err_msg=name)
    np.testing.assert_array_equal(rec.time, plain.time)


def test_mdf_without_asammdf_is_one_line(tmp_path, monkeypatch):
    """Without asammdf the MDF writer says what to install, and leaves no file."""
    monkeypatch.setitem(sys.modules, "asammdf", None)  # import asammdf raises ImportError
    with pytest.raises(rigdata.RigDataError, match=r"needs the optional package asammdf: pip install"):
        files.write_mdf(tmp_path / "x.mf4", {"Time": [0.0, 1.0]}, {"Time": "s"}, {})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("input_torque", [1.0, 4.0], ids=["1Nm", "4Nm"])
def test_drag_lowers_the_measured_efficiency(tmp_path, input_torque):
    """``drag_torque=0.05`` N m between joint and output transducer: the measured efficiency falls by
    drag omega_out / P_in, four times more at 1 N m than at 4 N m."""
    measured = {}
    for drag in (0.0, 0.05):
        rec, used = written(tmp_path, transducer=FINE, input_torque=input_torque, drag_torque=drag)
        measured[drag] = rigdata.measure(rec, 15.0, monte_carlo=0, transducers=FINE)
    s = synthetic.RigSettings(**{**BASE, "input_torque": input_torque, "drag_torque": 0.05})
    # over whole revolutions the mean output speed is the mean input speed
    expected = s.drag_torque * s.speed / (s.input_torque * s.speed)
    # same seed, same noise: the drop is off by the measured input work's relative error (within u) and
    # by the output torque's rounding (its mean moves by less than one acquisition step)
    tol = 2 * measured[0.05].u * expected + FINE.adc_step / input_torque
    assert abs(measured[0.0].efficiency - measured[0.05].efficiency - expected) <= tol
    assert used["drag_torque"] == 0.05
    # the brake is set for the mean input torque to ~1e-10 (two correction steps), so the truth is exact
    assert used["true_brake_efficiency"] == pytest.approx(used["true_efficiency"] - expected, rel=1e-6)


def test_drag_loads_the_joint_not_the_output_transducer(tmp_path):
    """``load_torque=2``, ``drag_torque=0.05``: the output transducer reads the brake's torque as without
    drag; the input torque rises by the joint's extra load over its efficiency."""
    means = {}
    for drag in (0.0, 0.05):
        rec, used = written(tmp_path, transducer=FINE, load_torque=2.0, drag_torque=drag)
        means[drag] = rigdata.measure(rec, 15.0, monte_carlo=0, transducers=FINE).as_dict(), used
    (plain, used0), (dragged, used1) = means[0.0], means[0.05]
    assert used1["brake_torque"] == 2.0
    # each mean is rounded by less than half an acquisition step
    assert dragged["mean_torque_out"] == pytest.approx(plain["mean_torque_out"], abs=FINE.adc_step)
    rise = 2.05 / used1["true_efficiency"] - 2.0 / used0["true_efficiency"]
    assert dragged["mean_torque_in"] - plain["mean_torque_in"] == pytest.approx(rise, abs=FINE.adc_step)


def test_drag_beyond_the_load_is_refused():
    """A drag larger than the load the input torque sets leaves no brake torque: ValueError."""
    with pytest.raises(ValueError, match="`drag_torque` 1.0 N m leaves no brake torque"):
        synthetic.true_signals(synthetic.RigSettings(input_torque=0.2, drag_torque=1.0, revolutions=2.0))


@pytest.mark.parametrize("field, value", [("load_torque", 0.0), ("load_torque", "5"), ("friction", -0.1),
                                          ("friction", math.nan), ("torque_out_sign", 0),
                                          ("torque_out_sign", True), ("drag_torque", -0.1),
                                          ("drag_torque", math.inf)])
def test_bad_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=f"`{field}` must be"):
        synthetic.RigSettings(**{field: value})


def test_cli_options_reach_the_file(tmp_path):
    """Every option of the command in the file's metadata; measured at its own angle the file gives its
    true efficiency within 2u."""
    path = tmp_path / "matrix.tdms"
    proc = cardan("synthetic", "--out", str(path), "--format", "tdms", "--angle", "30", "--rpm", "300",
                  "--load", "10", "--friction", "0.2", "--rate", "2000", "--seconds", "3", "--noise", "0.01",
                  "--torque-out-sign", "-1", "--full-scale", "50", "--accuracy-class", "0.05",
                  "--pulses-per-rev", "360", "--perfect", "--json")
    assert proc.returncode == 0, proc.stderr
    used = json.loads(proc.stdout)
    rec = rigdata.read(path, pulses_per_rev=360)
    stored = json.loads(rec.provenance["synthetic"]["settings"])
    assert stored == used
    assert (stored["shaft_angle_deg"], stored["friction"], stored["load_torque"], stored["rate"],
            stored["noise"], stored["torque_out_sign"]) == (30.0, 0.2, 10.0, 2000.0, 0.01, -1)
    assert stored["speed"] == pytest.approx(10 * math.pi)
    assert stored["transducer"]["full_scale"] == 50.0 and stored["transducer"]["pulses_per_rev"] == 360
    assert rec.duration == pytest.approx(3.0, abs=2e-3)
    t = rigdata.Transducer(full_scale=50.0, accuracy_class=5e-4, pulses_per_rev=360)
    m = rigdata.measure(rec, 30.0, monte_carlo=0, signs={"torque_out": -1}, transducers=(t, t))
    assert abs(m.efficiency - used["true_efficiency"]) <= 2 * m.u


@pytest.mark.parametrize("args, option", [(["--angle", "95"], "--angle"), (["--rpm", "-3"], "--rpm"),
                                          (["--friction", "-1"], "--friction"), (["--load", "0"], "--load"),
                                          (["--rate", "0"], "--rate"), (["--seconds", "0.1"], "--seconds"),
                                          (["--noise", "-1"], "--noise"),
                                          (["--torque-out-sign", "2"], "--torque-out-sign"),
                                          (["--format", "xyz"], "--format"),
                                          (["--drag-torque", "-1"], "--drag-torque"),
                                          (["--decimal", ",", "--format", "tdms"], "--decimal"),
                                          (["--speed", "6", "--rpm", "60"], "--rpm")])
def test_cli_bad_values_are_one_line_naming_the_option(tmp_path, args, option):
    out = tmp_path / "bad.csv"
    proc = cardan("synthetic", "--out", str(out), *args)
    assert proc.returncode == 2
    line, = proc.stderr.strip().splitlines()
    assert option in line and "unrecognized" not in line and not out.exists()


def test_cli_formats_are_the_writers():
    from rigdata.synthetic.command import SYNTHETIC_FORMATS

    assert SYNTHETIC_FORMATS == synthetic.FORMATS


def test_cli_decimal_and_drag(tmp_path):
    """``--decimal , --drag-torque 0.05``: a ';'-separated decimal-comma CSV whose metadata holds the drag,
    measuring the brake-over-input efficiency (the joint's less drag / input torque) within 2u."""
    path = tmp_path / "drag.csv"
    proc = cardan("synthetic", "--out", str(path), "--decimal", ",", "--drag-torque", "0.05",
                  "--input-torque", "2", "--seconds", "4", "--full-scale", "5", "--accuracy-class", "0.05",
                  "--perfect", "--json")
    assert proc.returncode == 0, proc.stderr
    used = json.loads(proc.stdout)
    assert used["drag_torque"] == 0.05
    assert ";" in path.read_text().splitlines()[-1]
    t = rigdata.Transducer(full_scale=5.0, accuracy_class=5e-4)
    m = rigdata.measure(path, 15.0, monte_carlo=0, transducers=t)
    assert abs(m.efficiency - used["true_brake_efficiency"]) <= 2 * m.u
    assert used["true_brake_efficiency"] == pytest.approx(used["true_efficiency"] - 0.05 / 2.0, rel=1e-6)
