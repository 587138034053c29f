"""``python tests/benchmarks``: every benchmark registered, run as a script from any folder, bad
input as one line with exit 2, and the targets' quick run end to end."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from benchmarks import BENCHMARKS
from benchmarks.cli import main

HERE = Path(__file__).resolve().parent


def test_the_script_lists_every_benchmark(tmp_path):
    """``python tests/benchmarks --help`` from another folder: exit 0, every name listed, and no
    module of the benchmarks imported by the product (the script puts ``tests/`` on the path)."""
    proc = subprocess.run([sys.executable, str(HERE), "--help"], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    listed = proc.stdout.split("{", 1)[1].split("}", 1)[0].split(",")
    assert listed == list(BENCHMARKS)


@pytest.mark.parametrize("argv, message", [
    (["targets", "--paper-steps", "0"], "--paper-steps"),
    (["targets", "--paper-coupling", "implicit", "--no-audit"], "--paper-coupling"),
    (["targets", "--scenes", "friction-90deg"], "--scenes"),
    (["batch", "--sizes", "0,10"], "--sizes"),
    (["accuracy", "--seed", "-1"], "--seed"),
    (["coupling", "--quick", "--out", "{file}/sub"], "not a folder"),
    (["nothing"], "invalid choice"),
], ids=["paper-steps", "paper-coupling", "scenes", "sizes", "seed", "out", "unknown"])
def test_bad_input_is_exit_2_with_one_line(argv, message, tmp_path, capsys):
    """A bad option: exit 2, one line on stderr naming it, no traceback."""
    (tmp_path / "file").write_text("keep")
    argv = [a.replace("{file}", str(tmp_path / "file")) for a in argv]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and message in err[-1] and not any("Traceback" in line for line in err)
    assert (tmp_path / "file").read_text() == "keep"


def test_quick_targets_write_their_folder(tmp_path, capsys):
    """The targets of a quick run on one friction scene (with its twin): the bench's rows, the
    friction-cost targets and ladders, the report opening with the command that ran it."""
    out = tmp_path / "targets"
    code = main(["targets", "--quick", "--scenes", "friction-10deg", "--engines", "exudyn,reference",
                 "--no-audit", "--no-paper", "--no-startup", "--out", str(out), "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["settings"]["scenes"] == ["frictionless-10deg", "friction-10deg"]
    assert {t["target"] for t in summary["targets"]} == {"kinematics", "friction_cost"}
    assert sorted(p.name for p in out.iterdir()) == ["bench.csv", "ladders.csv", "report.md",
                                                     "targets.csv", "targets.json", "work_precision.png"]
    ladders = pd.read_csv(out / "ladders.csv")
    assert set(ladders["scene"]) == {"friction-10deg"} and (ladders["cost_ratio"] > 0).all()
    report = (out / "report.md").read_text()
    assert "`python tests/benchmarks targets --quick --repeats 1 --scenes frictionless-10deg," in report
    assert "## Friction ladders" in report
