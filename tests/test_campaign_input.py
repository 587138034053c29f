"""``cardan rig campaign``: bad input gets one line naming the campaign file and the key (exit 2, no
traceback, nothing on stdout). Problems of the campaign file itself are found by
:func:`rigdata.campaign.spec.load_campaign` before any recording is read, so they are checked there (the
command adds only the one-line wrapper, checked once); problems found by reading a recording, and the
command's own options, are checked through the command."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rigdata
from rigdata.campaign.spec import CampaignError, load_campaign
from rigdata.synthetic import write

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs" / "rigdata.md"
FRICTION = "joint.pairs.input_spider.friction_coefficient"
HEAD = 'scene = "rig"\nmonte_carlo = 0\n'
PARAMETER = f'[parameters.f]\nkeys = ["{FRICTION}"]\ninitial = 0.2\nbounds = [0.0, 0.6]\n'


def recording(file: str = "cal.csv", use: str = "calibration", angle: float = 20, extra: str = "") -> str:
    """One ``[[recording]]`` table."""
    return f'[[recording]]\nfile = "{file}"\nshaft_angle_deg = {angle}\nuse = "{use}"\n{extra}'


VALIDATION = recording("val.csv", "validation", 30)


def campaign(top: str = "", parameters: str = PARAMETER, tables: str = "",
             recordings: tuple[str, ...] = (recording(), VALIDATION), engines: str = '["reference"]') -> str:
    """A campaign file's text: the valid one unless a part is replaced."""
    return HEAD + f"engines = {engines}\n" + top + parameters + tables + "".join(recordings)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """Two short synthetic recordings (2 revolutions), an unreadable text file, a binary file named
    .csv, and a folder named .csv."""
    where = tmp_path_factory.mktemp("campaign")
    write(where / "cal.csv", "csv", rigdata.RigSettings(revolutions=2.0, shaft_angle_deg=20.0, seed=1))
    write(where / "val.csv", "csv", rigdata.RigSettings(revolutions=2.0, shaft_angle_deg=30.0, seed=2))
    (where / "garbage.csv").write_text("hello rig\nthis is, only words\nno numbers\n", encoding="utf-8")
    (where / "binary.csv").write_bytes(bytes(range(256)) * 8)
    (where / "folder.csv").mkdir()
    return where


def written(folder: Path, name: str, text: str) -> Path:
    """``text`` as campaign file ``name`` in ``folder`` (next to the recordings)."""
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


SPEC_CASES = [
    pytest.param(campaign(top="colour = 1\n"), r"the campaign: unknown key 'colour'", id="unknown-top-key"),
    pytest.param(campaign(recordings=(recording(), recording("nope.csv", "validation"))),
                 r"\[\[recording\]\] 2 \(nope.csv\): `file` '.*nope.csv' does not exist", id="file-missing"),
    pytest.param(campaign(recordings=(recording(), recording("folder.csv", "validation"))),
                 r"\[\[recording\]\] 2 \(folder.csv\): `file` .* is not a file", id="file-is-a-folder"),
    pytest.param(campaign(parameters=PARAMETER.replace("input_spider", "nope")),
                 r"\[parameters.f\]: key 'joint.pairs.nope.friction_coefficient' is not a number of the",
                 id="parameter-key-not-in-scene"),
    pytest.param(campaign(parameters=PARAMETER.replace(FRICTION, "load.torque")),
                 r"\[parameters.f\]: key 'load.torque' is replaced by each recording's measured drive and",
                 id="parameter-key-the-recordings-replace"),
    pytest.param(campaign(parameters=PARAMETER.replace(FRICTION, "joint.geometry.shaft_angle")),
                 r"\[parameters.f\]: key 'joint.geometry.shaft_angle' is each recording's `shaft_angle_deg`",
                 id="parameter-shaft-angle"),
    pytest.param(campaign(tables='[inputs."drive.speed"]\nstd = 0.1\n'),
                 r"\[inputs.\"drive.speed\"\]: key 'drive.speed' is replaced by each recording's measured",
                 id="input-key-the-recordings-replace"),
    pytest.param(campaign(top="monte_carlo = 1000000000\n").replace("monte_carlo = 0\n", ""),
                 r"`monte_carlo` must be an integer in \[0, 100000\], got 1000000000", id="monte-carlo-huge"),
    pytest.param(campaign(parameters=PARAMETER.replace("initial = 0.2", "initial = 0.9")),
                 r"\[parameters.f\]: `initial` 0.9 is outside `bounds` \[0, 0.6\]",
                 id="bounds-exclude-initial"),
    pytest.param(campaign(parameters=PARAMETER.replace("[0.0, 0.6]", "[0.6, 0.6]")),
                 r"\[parameters.f\]: `bounds` must have low < high", id="bounds-low-not-below-high"),
    pytest.param(campaign(parameters=PARAMETER.replace("[0.0, 0.6]", "[-1.0, 0.6]")),
                 rf"\[parameters.f\]: key '{FRICTION}' does not take `bounds` low -1 .*must be >= 0",
                 id="bound-the-scene-refuses"),
    pytest.param(campaign(parameters=PARAMETER.replace("[0.0, 0.6]", "[nan, 0.6]")),
                 r"\[parameters.f\] `bounds` low must be a finite number, got nan", id="bound-nan"),
    pytest.param(campaign(parameters=PARAMETER.replace("initial = 0.2", 'initial = "0.2"')),
                 r"\[parameters.f\] `initial` must be a finite number, got '0.2'", id="initial-string"),
    pytest.param(campaign(parameters=PARAMETER.replace(f'["{FRICTION}"]', "[]")),
                 r"\[parameters.f\]: `keys` must be a non-empty list", id="keys-empty"),
    pytest.param(campaign(recordings=(recording(use="validation"), VALIDATION)),
                 r"\[parameters\] asks for a calibration but no \[\[recording\]\] has use = \"calibration\"",
                 id="parameters-without-calibration-recordings"),
    pytest.param(campaign(recordings=(recording(), recording("cal.csv", "validation"))),
                 r"\[\[recording\]\] 2 \(cal.csv\): `file` is '.*cal.csv', the file of \[\[recording\]\] 1",
                 id="same-file-twice"),
    pytest.param(campaign(recordings=(recording(), recording("./cal.csv", "validation"))),
                 r"\[\[recording\]\] 2 \(\./cal.csv\): `file` is '.*cal.csv', the file of \[\[recording\]\]",
                 id="same-file-spelled-twice"),
    pytest.param(campaign(recordings=(recording(), recording("folder.csv/../cal.csv", "validation"))),
                 r"\[\[recording\]\] 2 \(folder.csv/\.\./cal.csv\): .*the file of \[\[recording\]\] 1",
                 id="same-file-through-a-parent"),
    pytest.param(campaign(recordings=(recording(), recording("val.csv", "test"))),
                 r"\[\[recording\]\] 2 \(val.csv\): `use` must be \"calibration\" or \"validation\", got 't",
                 id="use-test"),
    pytest.param(campaign(recordings=(recording(), recording("val.csv", "validation", 95))),
                 r"\[\[recording\]\] 2 \(val.csv\): `shaft_angle_deg` must be in \[0, 90\) deg, got 95",
                 id="shaft-angle-95"),
    pytest.param(campaign(recordings=(recording().replace("shaft_angle_deg = 20\n", ""), VALIDATION)),
                 r"\[\[recording\]\] 1 \(cal.csv\): `shaft_angle_deg` is missing", id="shaft-angle-missing"),
    pytest.param(campaign(engines='["reference", "abaqus"]'),
                 r"`engines`: 'abaqus' cannot be driven by a measurement", id="unknown-engine"),
    pytest.param(campaign(engines='["mujoco"]'),
                 r"`engines`: 'mujoco' cannot be driven by a measurement", id="engine-mujoco"),
    pytest.param(campaign(top="coverage = 1.5\n"), r"`coverage` must be a probability in \[0.5, 1\), got 1.5",
                 id="coverage-1.5"),
    pytest.param(campaign(tables='[inputs."joint.geometry.nope"]\nstd = 0.001\n'),
                 r"\[inputs.\"joint.geometry.nope\"\]: key 'joint.geometry.nope' is not a number of the",
                 id="input-key-not-in-scene"),
    pytest.param(campaign(tables=f'[inputs."{FRICTION}"]\nstd = 0.01\n'),
                 rf"\[inputs.\"{FRICTION}\"\]: '{FRICTION}' is calibrated \(\[parameters\]\)",
                 id="input-also-calibrated"),
    pytest.param(campaign(recordings=(recording(extra="colour = 1\n"), VALIDATION)),
                 r"\[\[recording\]\] 1 \(cal.csv\): unknown key 'colour'", id="recording-unknown-key"),
    pytest.param(campaign(recordings=(recording(), "[[recording]]\n")),
                 r"\[\[recording\]\] 2: `file` is missing", id="recording-empty"),
    pytest.param(campaign(recordings=(recording(extra='map = "x"\n'), VALIDATION)),
                 r"\[\[recording\]\] 1 \(cal.csv\): `map` must be a table, got 'x'", id="map-not-a-table"),
    pytest.param(campaign(recordings=(recording(extra='format = "xls9"\n'), VALIDATION)),
                 r"\[\[recording\]\] 1 \(cal.csv\): `format` must be \"auto\" or one of .*got 'xls9'",
                 id="format-unknown"),
]


@pytest.mark.parametrize(("text", "match"), SPEC_CASES)
def test_campaign_file_problem_names_file_and_key(folder, request, text, match):
    """load_campaign: CampaignError, one line, starting with the campaign file, naming the key."""
    path = written(folder, request.node.callspec.id, text)
    with pytest.raises(CampaignError, match=match) as info:
        load_campaign(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    assert "\n" not in message


def cardan_campaign(*args: str) -> subprocess.CompletedProcess:
    """``cardan rig campaign ARGS`` in a fresh interpreter running this checkout."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", "rig", "campaign", *args],
                          capture_output=True, text=True, timeout=300, env=env)


def one_line(proc: subprocess.CompletedProcess) -> str:
    """The one error line of a bad input (exit 2, nothing on stdout, no traceback)."""
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("cardan rig campaign: error: ")
    return lines[0]


READ_CASES = [
    pytest.param("garbage.csv", "", r"no data rows", id="text-garbage"),
    pytest.param("binary.csv", "", r"not a text file", id="binary-named-csv"),
    pytest.param("val.csv", 'map = { torque_in = "Nope [V]" }\n',
                 r"channel 'torque_in': mapped to column 'Nope \[V\]', which the file does not have",
                 id="map-column-missing"),
]


@pytest.mark.parametrize(("file", "extra", "match"), READ_CASES)
def test_unreadable_recording_is_one_line(folder, tmp_path, request, file, extra, match):
    """A recording that cannot be read or mapped: exit 2 naming the campaign file and
    ``[[recording]] N (file)``."""
    text = campaign(recordings=(recording(), recording(file, "validation", 30, extra)))
    path = written(folder, request.node.callspec.id, text)
    line = one_line(cardan_campaign(str(path), "--out", str(tmp_path / "out"), "--workers", "1"))
    assert f"{path}: [[recording]] 2 ({file}): " in line
    assert re.search(match, line), line


def test_unreadable_recording_in_the_worker_pool(folder, tmp_path):
    """Measured in worker processes (the default), an unreadable recording is the same one line."""
    text = campaign(recordings=(recording(), recording("binary.csv", "validation")))
    path = written(folder, "pool", text)
    line = one_line(cardan_campaign(str(path), "--out", str(tmp_path / "out"), "--workers", "2"))
    assert f"{path}: [[recording]] 2 (binary.csv): " in line


def test_campaign_file_problem_through_the_command(folder, tmp_path):
    """A problem of the campaign file is one line naming file and key; --out is not created."""
    path = written(folder, "top-key", campaign(top="colour = 1\n"))
    line = one_line(cardan_campaign(str(path), "--out", str(tmp_path / "out")))
    assert f"{path}: the campaign: unknown key 'colour'" in line
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("make", "match"), [
    pytest.param(lambda folder: folder / "nofile.toml", r"cannot read campaign file '.*nofile.toml'",
                 id="missing"),
    pytest.param(lambda folder: folder / "folder.csv", r"cannot read campaign file '.*folder.csv'",
                 id="a-folder"),
    pytest.param(lambda folder: written(folder, "broken", "[[recording]\n"),
                 r"campaign file '.*broken.toml' is not valid TOML", id="not-toml"),
    pytest.param(lambda folder: _latin1(folder), r"campaign file '.*latin1.toml' is not UTF-8 text",
                 id="not-utf8"),
])
def test_unreadable_campaign_file_is_one_line(folder, tmp_path, make, match):
    """A campaign file that is missing, a folder, not TOML or not UTF-8: one line naming it."""
    line = one_line(cardan_campaign(str(make(folder)), "--out", str(tmp_path / "out")))
    assert re.search(match, line), line


def _latin1(folder: Path) -> Path:
    """A campaign file written in Latin-1."""
    path = folder / "latin1.toml"
    path.write_bytes('title = "Prüfstand"\n'.encode("latin-1"))
    return path


def test_workers_zero_is_one_line(folder, tmp_path):
    """--workers 0: one line naming the option."""
    path = written(folder, "workers", campaign())
    line = one_line(cardan_campaign(str(path), "--out", str(tmp_path / "out"), "--workers", "0"))
    assert "argument --workers: must be >= 1 (--workers), got '0'" in line


def test_out_is_a_file_is_one_line(folder, tmp_path):
    """--out naming an existing regular file: one line naming the option; the file is left as it was."""
    path = written(folder, "out-file", campaign())
    target = tmp_path / "results.txt"
    target.write_text("previous\n", encoding="utf-8")
    line = one_line(cardan_campaign(str(path), "--out", str(target)))
    assert f"--out: '{target}' exists and is not a folder" in line
    assert target.read_text(encoding="utf-8") == "previous\n"


def known_keys(folder: Path, text: str) -> set[str]:
    """The keys a table of the campaign file takes, as the unknown-key message lists them."""
    with pytest.raises(CampaignError, match=r"unknown key 'colour' \(known: ") as info:
        load_campaign(written(folder, "known", text))
    return set(re.search(r"\(known: (.*)\)$", str(info.value))[1].split(", "))


def test_the_docs_example_campaign_shows_every_key_and_loads(folder, tmp_path):
    """The campaign file of docs/rigdata.md uses every key the file takes, and loads."""
    text = re.search(r"```toml\n(# campaign.toml\n.*?)```", DOCS.read_text(encoding="utf-8"), re.DOTALL)[1]
    data = tomllib.loads(text)
    assert set(data) == known_keys(folder, campaign(top="colour = 1\n"))
    shown = {key for table in data["recording"] for key in table}
    assert shown == known_keys(folder, campaign(recordings=(recording(extra="colour = 1\n"), VALIDATION)))
    for table in data["recording"]:
        (tmp_path / table["file"]).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / table["file"]).write_bytes(b"")  # read only when the campaign runs
    (tmp_path / "campaign.toml").write_text(text, encoding="utf-8")
    spec = load_campaign(tmp_path / "campaign.toml")
    assert [r.use for r in spec.recordings] == ["calibration", "validation"]
    assert spec.parameters[0].keys == tuple(data["parameters"]["friction"]["keys"])
