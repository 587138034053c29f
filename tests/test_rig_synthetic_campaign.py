"""``rigdata.synthetic.write_campaign`` and ``cardan rig synthetic --campaign``: eight labelled recordings
and a ``campaign.toml`` that lists them, every file readable with the options the list gives."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections import Counter

import pytest

import rigdata
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace as replace_field
from rigdata import synthetic
from rigdata.campaign.spec import load_campaign
from rigdata.validation import as_scene

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

#: The keys of campaign.toml that ``cardan rig campaign`` reads (rigdata.campaign.spec).
TOP_KEYS = {"scene", "engines", "coverage", "parameters", "transducers", "recording"}
RECORDING_KEYS = {"file", "shaft_angle_deg", "use"}
RECORDING_OPTIONAL = {"label", "format", "map", "unit", "sign", "transducers"}


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A default campaign of 3 s recordings and its parsed toml."""
    pytest.importorskip("asammdf")
    path = synthetic.write_campaign(tmp_path_factory.mktemp("campaign"), seconds=3.0)
    return path, tomllib.loads(path.read_text(encoding="utf-8"))


def settings_of(rec) -> dict:
    return json.loads(rec.provenance["synthetic"]["settings"])


def read_recording(path, entry, transducers=None):
    """The record of one ``[[recording]]`` read with the options the toml gives."""
    t = rigdata.Transducer(**(transducers or {}))
    return rigdata.read(path.parent / entry["file"], mapping=entry.get("map"), units=entry.get("unit"),
                        sensitivity=t.sensitivity, pulses_per_rev=t.pulses_per_rev)


def test_toml_has_the_campaign_keys(campaign):
    """campaign.toml parses; top level, parameter, transducer and recording keys as specified."""
    path, toml = campaign
    assert path.name == "campaign.toml"
    assert path.read_text().startswith("# SYNTHETIC campaign written by rigdata.synthetic.write_campaign: "
                                       "truth friction 0.12, drag 0 N m, seed 0\n")
    assert set(toml) == TOP_KEYS
    assert (toml["scene"], toml["engines"], toml["coverage"]) == ("rig", ["reference", "exudyn"], 0.95)
    f = toml["parameters"]["f"]
    assert set(toml["parameters"]) == {"f"} and set(f) == {"keys", "initial", "bounds"}
    assert f["keys"] == [f"joint.pairs.{p}.friction_coefficient" for p in PAIR_NAMES]
    assert (f["initial"], f["bounds"]) == (0.2, [0.0, 0.6])
    assert toml["transducers"] == {"full_scale": 5.0, "accuracy_class": 0.0005}
    for entry in toml["recording"]:
        assert RECORDING_KEYS <= set(entry) <= RECORDING_KEYS | RECORDING_OPTIONAL, entry


def test_campaign_loads(campaign):
    """``cardan rig campaign``'s parser takes the file: eight recordings with their use and sign, the
    campaign's transducers, the friction parameter on every pair."""
    path, toml = campaign
    spec = load_campaign(path)
    assert [r.file.name for r in spec.recordings] == [e["file"] for e in toml["recording"]]
    assert [r.use for r in spec.recordings] == [e["use"] for e in toml["recording"]]
    assert [r.signs for r in spec.recordings] == [e.get("sign", {}) for e in toml["recording"]]
    assert all(r.transducers == (synthetic.CAMPAIGN_TRANSDUCER,) * 2 for r in spec.recordings)
    assert [p.name for p in spec.parameters] == ["f"] and len(spec.parameters[0].keys) == 4


def test_own_transducer_reaches_the_toml(tmp_path):
    """A transducer of other sensitivity, pulses and drift: ``[transducers]`` states them, the parser
    reads the file with them."""
    t = rigdata.Transducer(full_scale=5.0, accuracy_class=5e-4, sensitivity=2.0, pulses_per_rev=360,
                           zero_drift=5e-4)
    point = {"shaft_angle_deg": 20.0, "speed": 6.0, "input_torque": 2.0, "use": "calibration",
             "format": "csv"}
    path = synthetic.write_campaign(tmp_path, points=[point], seconds=3.0, transducer=t)
    toml = tomllib.loads(path.read_text())
    assert toml["transducers"] == {"full_scale": 5.0, "accuracy_class": 5e-4, "sensitivity": 2.0,
                                   "pulses_per_rev": 360, "zero_drift": 5e-4}
    spec = load_campaign(path)
    assert spec.recordings[0].transducers == (t, t)
    rec = rigdata.read(spec.recordings[0].file, **spec.recordings[0].read)
    assert math.degrees(rec.sources["angle_in"].quantum) == pytest.approx(1.0)
    # volts read at 2 V/(N m) (at the default 0.1 the torque would read 20 times too large): the mean input
    # torque over whole revolutions is the 2 N m set, within the class, drift and noise (under 0.2 %)
    m = rigdata.measure(rec, 20.0, transducers=t, monte_carlo=0)
    assert m.as_dict()["mean_torque_in"] == pytest.approx(2.0, rel=2e-3)


def test_parameter_keys_set_every_pair(campaign):
    """The parameter's keys are scene fields: ``mapping.replace`` sets each pair's friction with them."""
    keys = campaign[1]["parameters"]["f"]["keys"]
    scene = replace_field(as_scene("rig"), **{k: 0.3 for k in keys})
    assert [pair.friction_coefficient for _, pair in scene.joint.pairs.items()] == [0.3] * 4


def test_eight_recordings_two_per_format(campaign):
    """Eight files, two per format (csv, lvm, mdf, mat), half calibration, half validation; the csv
    files with decimal commas."""
    path, toml = campaign
    entries = toml["recording"]
    assert len(entries) == 8 and all((path.parent / e["file"]).is_file() for e in entries)
    suffixes = Counter((path.parent / e["file"]).suffix for e in entries)
    assert suffixes == {".csv": 2, ".lvm": 2, ".mf4": 2, ".mat": 2}
    assert Counter(e["use"] for e in entries) == {"calibration": 4, "validation": 4}
    for e in entries:
        if e["file"].endswith(".csv"):
            assert ";" in (path.parent / e["file"]).read_text().splitlines()[-1]


def test_every_file_reads_with_the_toml_options(campaign):
    """Each file read and measured with its toml options: labelled synthetic, the toml's shaft angle and
    the truth friction in its settings, an efficiency in (0, 1]."""
    path, toml = campaign
    t = rigdata.Transducer(**toml["transducers"])
    for entry in toml["recording"]:
        rec = read_recording(path, entry, toml["transducers"])
        stored = settings_of(rec)
        assert (stored["shaft_angle_deg"], stored["friction"]) == (entry["shaft_angle_deg"], 0.12)
        m = rigdata.measure(rec, entry["shaft_angle_deg"], transducers=t, monte_carlo=0,
                            signs=entry.get("sign"))
        assert 0.0 < m.efficiency <= 1.0 + 2 * m.u, entry["file"]


def test_conventions_vary(campaign):
    """One recording with its speeds in rpm, one with the output torque negative (the toml says
    ``sign = { torque_out = -1 }``); the others with neither."""
    path, toml = campaign
    stored = {e["file"]: settings_of(read_recording(path, e)) for e in toml["recording"]}
    rpm = [f for f, s in stored.items() if s["speed_channel"] == "rpm"]
    negative = [f for f, s in stored.items() if s["torque_out_sign"] == -1]
    assert len(rpm) == 1 and len(negative) == 1
    signs = {e["file"]: e.get("sign") for e in toml["recording"]}
    assert signs == {f: ({"torque_out": -1} if f in negative else None) for f in stored}


def test_validation_loads_outside_the_calibration_loads(campaign):
    """Validation points include input torques below and above every calibration point's, at shaft angles
    and speeds that differ between the recordings."""
    path, toml = campaign
    loads = {"calibration": [], "validation": []}
    points = set()
    for entry in toml["recording"]:
        s = settings_of(read_recording(path, entry))
        loads[entry["use"]].append(s["input_torque"])
        points.add((s["shaft_angle_deg"], s["speed"], s["input_torque"]))
    assert min(loads["validation"]) < min(loads["calibration"])
    assert max(loads["validation"]) > max(loads["calibration"])
    assert len(points) == 8


def test_own_points_and_drag(tmp_path):
    """``points``: the caller's operating points, one file each; ``drag_torque`` reaches every file and
    lowers each measured efficiency by drag / input torque (same seeds, same noise)."""
    points = [{"shaft_angle_deg": 30.0, "speed": 6.0, "input_torque": 1.0, "use": "validation",
               "format": "csv"},
              {"shaft_angle_deg": 20.0, "speed": 8.0, "input_torque": 2.0, "use": "calibration",
               "format": "lvm", "speed_channel": "rpm"}]
    measured = {}
    for drag in (0.0, 0.04):
        path = synthetic.write_campaign(tmp_path / str(drag), points=points, drag_torque=drag, seconds=3.0)
        toml = tomllib.loads(path.read_text())
        assert [e["file"] for e in toml["recording"]] == ["r1_b30_w6.csv", "r2_b20_w8.lvm"]
        t = rigdata.Transducer(**toml["transducers"])
        measured[drag] = [rigdata.measure(read_recording(path, e), e["shaft_angle_deg"], transducers=t,
                                          monte_carlo=0) for e in toml["recording"]]
        assert all(settings_of(m.record)["drag_torque"] == drag for m in measured[drag])
    for point, plain, dragged in zip(points, measured[0.0], measured[0.04], strict=True):
        expected = 0.04 / point["input_torque"]
        # the drop is off by the input work's relative error (within u) and the rounding of the mean
        # output torque (less than one acquisition step)
        tol = 2 * dragged.u * expected + t.adc_step / point["input_torque"]
        assert abs(plain.efficiency - dragged.efficiency - expected) <= tol


@pytest.mark.parametrize("points, match", [
    ([], "`points` must be a non-empty list"),
    ([{"shaft_angle_deg": 20.0, "speed": 6.0, "input_torque": 1.0, "use": "calibration"}],
     r"`points\[0\]` needs the keys .* missing \['format'\]"),
    ([{"shaft_angle_deg": 20.0, "speed": 6.0, "input_torque": 1.0, "use": "test", "format": "csv"}],
     r"`points\[0\]\['use'\]` must be one of"),
    ([{"shaft_angle_deg": 95.0, "speed": 6.0, "input_torque": 1.0, "use": "validation", "format": "csv"}],
     r"`points\[0\]`: `shaft_angle_deg` must be in"),
], ids=["empty", "no-format", "bad-use", "bad-angle"])
def test_bad_points_are_refused_before_writing(tmp_path, points, match):
    with pytest.raises(ValueError, match=match):
        synthetic.write_campaign(tmp_path / "c", points=points, seconds=3.0)
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("changes, match", [({"seconds": 1.0}, "`seconds` 1 at 6 rad/s"),
                                            ({"seed": -1}, "`seed` must be"),
                                            ({"formats": ("csv", "xlsx")}, "`formats` must be"),
                                            ({"drag_torque": -0.1}, "`drag_torque` must be >= 0")],
                         ids=["short", "seed", "format", "drag"])
def test_bad_settings_are_refused_before_writing(tmp_path, changes, match):
    with pytest.raises(ValueError, match=match):
        synthetic.write_campaign(tmp_path / "c", **changes)
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("argv, expected", [
    ([], {"drag_torque": 0.0, "rate": 1000.0, "scene": "rig"}),
    (["--friction", "0.2", "--drag-torque", "0.01", "--seed", "3", "--seconds", "5", "--rate", "500"],
     {"friction": 0.2, "drag_torque": 0.01, "seed": 3, "seconds": 5.0, "rate": 500.0, "scene": "rig"}),
], ids=["defaults", "options"])
def test_cli_campaign_options(tmp_path, monkeypatch, capsys, argv, expected):
    """``--campaign DIR``: the options reach write_campaign (the library's defaults where none is given),
    the toml's path is printed."""
    from cardan_exudyn.cli import main

    calls = []

    def fake(folder, **kwargs):
        calls.append((folder, kwargs))
        return tmp_path / "c" / "campaign.toml"

    monkeypatch.setattr(synthetic, "write_campaign", fake)
    assert main(["rig", "synthetic", "--campaign", str(tmp_path / "c"), *argv]) == 0
    assert calls == [(str(tmp_path / "c"), expected)]
    assert capsys.readouterr().out.strip() == str(tmp_path / "c" / "campaign.toml")


def test_cli_campaign_needs_a_folder(tmp_path, capsys):
    """``--campaign`` naming a file, or with ``--out``: one line, exit 2."""
    from cardan_exudyn.cli import main

    (tmp_path / "f").write_text("")
    assert main(["rig", "synthetic", "--campaign", str(tmp_path / "f")]) == 2
    assert "is a file" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["rig", "synthetic", "--campaign", str(tmp_path), "--out", str(tmp_path / "x.csv")])
    assert "not allowed with argument" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_campaign(tmp_path):
    """``cardan rig synthetic --campaign DIR`` end to end: prints the toml's path; friction, drag and seed
    reach the files and the toml's first line."""
    pytest.importorskip("asammdf")
    proc = subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", "rig", "synthetic", "--campaign",
                           str(tmp_path / "c"), "--friction", "0.2", "--drag-torque", "0.01", "--seed", "3",
                           "--seconds", "3"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    path = tmp_path / "c" / "campaign.toml"
    assert proc.stdout.strip() == str(path)
    assert "truth friction 0.2, drag 0.01 N m, seed 3" in path.read_text().splitlines()[0]
    entry = tomllib.loads(path.read_text())["recording"][0]
    stored = settings_of(read_recording(path, entry))
    assert (stored["friction"], stored["drag_torque"]) == (0.2, 0.01)
    assert stored["revolutions"] == pytest.approx(3.0 * 6.0 / (2 * math.pi) - 0.25)


@pytest.mark.slow
def test_default_campaign_is_resolved_at_full_length(tmp_path):
    """The default campaign (12 s at 1 kHz): every recording's measured efficiency has status ok and its
    loss is at least one standard uncertainty."""
    pytest.importorskip("asammdf")
    path = synthetic.write_campaign(tmp_path)
    toml = tomllib.loads(path.read_text())
    t = rigdata.Transducer(**toml["transducers"])
    for entry in toml["recording"]:
        m = rigdata.measure(read_recording(path, entry), entry["shaft_angle_deg"], transducers=t,
                            monte_carlo=0, signs=entry.get("sign"))
        assert m.status == "ok" and 1.0 - m.efficiency >= m.u, (entry["file"], m.efficiency, m.u)
