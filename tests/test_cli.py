"""The ``cardan`` command line: outputs, exit status, and bad input (exit 2, one line)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from cardan_exudyn.cli import main


def cardan(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", *args],
                          capture_output=True, text=True, timeout=300)


def test_run_json_prints_only_the_summary():
    """--json prints one JSON document on stdout with the schema's summary keys."""
    proc = cardan("run", "--angle", "15", "--revolutions", "1", "--json")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    for key in ("status", "engine", "engine_version", "scene", "mean_efficiency",
                "mean_instantaneous_efficiency", "revolutions", "wall_time_s", "steps",
                "newton_iterations", "max_constraint_violation_m", "dt", "dt_choice"):
        assert key in summary
    assert summary["status"] == "ok"
    pairs = summary["scene"]["joint"]["pairs"]
    assert set(pairs["frame_input"]) == {"friction_coefficient", "journal_diameter", "moment_lever"}


def test_run_out_writes_files(tmp_path):
    """--out writes timeseries.csv with every schema column and summary.json."""
    import pandas as pd

    from reference.results.columns import table_columns

    assert main(["run", "--angle", "5", "--rpm", "500", "--revolutions", "1",
                 "--out", str(tmp_path / "r")]) == 0
    table = pd.read_csv(tmp_path / "r" / "timeseries.csv")
    assert list(table.columns) == table_columns()
    assert json.loads((tmp_path / "r" / "summary.json").read_text())["status"] == "ok"


BAD_CLI = [
    (["run", "--angle", "abc"], "expected a number"),
    (["run", "--angle", "95"], "`shaft_angle` must be in [0, 90) deg"),
    (["run", "--rpm", "0"], "must be non-zero"),
    (["run", "--dt", "-1"], "must be positive"),
    (["run", "--friction-spider", "-0.1"], "must be >= 0"),
    (["run", "--scene", "/nonexistent.toml"], "cannot read scene file"),
    (["run", "--name", "nope"], "unknown scene name 'nope'"),
    (["run", "--engine", "warp"], "`--engine` must be one of"),
    (["run", "--revolutions", "0.3"], "`revolutions` must be at least"),
    (["run", "--angle", "nan"], "expected a finite number"),
    (["run", "--coupling", "halfway"], "invalid choice"),
    (["run", "--sign-band", "-1"], "must be >= 0"),
]


@pytest.mark.parametrize("args, message", BAD_CLI, ids=[" ".join(a) for a, _ in BAD_CLI])
def test_bad_cli_input(args, message):
    """Bad input exits 2 with one line naming the problem and no traceback."""
    proc = cardan(*args)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""


def test_scene_command_prints_toml(tmp_path):
    """`cardan scene` prints the resolved scene, which loads back."""
    from cardan_exudyn.cli import build_parser
    from cardan_exudyn.scene_options import scene_from_args
    from reference import load_scene

    argv = ["scene", "--name", "paper-literal-frictionless", "--angle", "12"]
    proc = cardan(*argv)
    assert proc.returncode == 0
    assert "shaft_angle = 0.2094" in proc.stdout
    path = tmp_path / "printed.toml"
    path.write_text(proc.stdout)
    assert load_scene(path) == scene_from_args(build_parser().parse_args(argv))


def test_reproduce_quick(tmp_path):
    """`cardan reproduce --quick` writes the report folder with its table and plots."""
    out = tmp_path / "rep"
    assert main(["reproduce", "--quick", "--out", str(out)]) == 0
    for name in ("report.md", "results.csv", "assumptions.csv", "table2.png",
                 "fig4_efficiency_10deg_physical.png", "fig5_pair_losses_physical.png",
                 "summaries.json"):
        assert (out / name).is_file(), name
    report = (out / "report.md").read_text()
    assert "Assumption register" in report
    assert "mean_instantaneous_efficiency" in report


def test_self_locking_exits_3():
    """A self-locking run prints its status and reason, not a number, and exits 3."""
    proc = cardan("run", "--name", "paper-literal-50deg", "--revolutions", "1")
    assert proc.returncode == 3
    assert "self_locking" in proc.stderr and "loop gain" in proc.stderr
    assert "mean efficiency" not in proc.stdout


def test_reader_that_goes_away_ends_quietly():
    """`cardan run --json | head -1`: no BrokenPipeError traceback, exit 141 (128 + SIGPIPE)."""
    proc = subprocess.Popen([sys.executable, "-m", "cardan_exudyn.cli", "run", "--name",
                             "paper-literal-10deg-frictionless", "--revolutions", "1", "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader is gone before the command writes
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 141
    assert err == ""


@pytest.mark.parametrize("command", ["run", "scene", "sweep", "reproduce", "bench", "stress", "compare",
                                     "calibrate", "tolerance"])
def test_every_command_has_help(command, capsys):
    """Core and study commands are all registered: `--help` prints their usage, exit 0."""
    with pytest.raises(SystemExit) as stop:
        main([command, "--help"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: cardan {command}")
