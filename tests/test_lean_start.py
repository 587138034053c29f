"""A lean start: ``cardan run`` and ``cardan --help`` import only what they use (issue 19).

Each check runs in a fresh interpreter, so that what this test session has imported already
(pandas, scipy, Exudyn, ...) cannot hide an import. The timing itself is a benchmark figure
(``tests/benchmarks/startup.py``, :func:`benchmarks.startup.import_cost`), not a test.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from cardan_exudyn.scene_options import DEFAULT_SCENE
from cardan_exudyn.studies import COMMANDS
from reference.paper.data import paper_data
from reference.paper.scenes import named_scene

HEAVY = ("pandas", "matplotlib", "scipy", "dask", "distributed", "mujoco", "exudyn", "tqdm")
"""Third-party packages a run loads only when it needs them (tables, plots, the engines)."""
JOBS = ("cardan_exudyn.studies.", "cardan_exudyn.sweep", "cardan_exudyn.model", "cardan_exudyn.comparison",
        "cardan_exudyn.mujoco", "cardan_exudyn.report.plots", "rigdata")
"""Modules of this project that ``cardan run`` has no use for before its engine runs."""

PROBE = f"""
import json, sys
HEAVY, JOBS = {HEAVY!r}, {JOBS!r}

def loaded():
    heavy = sorted(m for m in sys.modules if m.split(".")[0] in HEAVY)
    jobs = sorted(m for m in sys.modules if m.startswith(JOBS))
    return {{"heavy": heavy, "jobs": jobs}}

import cardan_exudyn.cli as cli
after_import = loaded()
args = cli.parse_args(sys.argv[1:])
after_parse = loaded()
scene = cli.scene_from_args(args)
print(json.dumps({{"import": after_import, "parse": after_parse, "scene": loaded(),
                  "name": scene.name, "load": scene.load.torque,
                  "engine": sorted(m for m in sys.modules if m.startswith("reference.engine"))}}))
"""


def probe(*argv: str) -> dict:
    """Run :data:`PROBE` on the ``cardan`` arguments ``argv``; what was loaded at each stage."""
    proc = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_cardan_run_loads_nothing_heavy_before_the_engine():
    """Importing the CLI, parsing ``cardan run`` and building its default scene loads no heavy
    package, no study and no engine: the ``physical`` set's load is the stored one."""
    seen = probe("run")
    for stage in ("import", "parse", "scene"):
        assert seen[stage] == {"heavy": [], "jobs": []}, stage
    scene = named_scene(DEFAULT_SCENE)
    assert seen["name"] == scene.name
    # the load for a mean input torque of 2 N m, as stored in the paper's data file
    assert seen["load"] == scene.load.torque == paper_data()["loads"]["scenes"][seen["name"]]["torque"]
    assert seen["engine"] == []


def test_cardan_run_with_overrides_stays_lean():
    """A run with friction and angle overrides (a second paper scene) loads nothing heavy either."""
    seen = probe("run", "--angle", "35", "--coupling", "lagged", "--revolutions", "1")
    assert seen["scene"] == {"heavy": [], "jobs": []}
    assert "-35deg-" in seen["name"] and "coupling=lagged" in seen["name"]


HELP = f"""
import contextlib, io, json, sys
from cardan_exudyn.cli import main
out = io.StringIO()
with contextlib.redirect_stdout(out):
    try:
        status = main(sys.argv[1:])
    except SystemExit as exc:
        status = exc.code
print(json.dumps({{"status": status, "text": out.getvalue(),
                  "heavy": sorted(m for m in sys.modules if m.split(".")[0] in {HEAVY!r})}}))
"""


def cardan_help(*argv: str) -> dict:
    proc = subprocess.run([sys.executable, "-c", HELP, *argv], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_cardan_help_lists_every_command_without_heavy_imports():
    """``cardan --help`` exits 0 and lists the core, study and plugin commands, loading no heavy
    package (the studies register their parsers; their work imports on call)."""
    seen = cardan_help("--help")
    assert seen["status"] == 0
    assert seen["heavy"] == []
    listed = seen["text"].split("{", 1)[1].split("}", 1)[0].replace("\n", "").replace(" ", "").split(",")
    assert {"run", "sweep", "scene", "rig"} <= set(listed)
    assert len(listed) == 3 + len(COMMANDS) + 1  # core, one per study module, rigdata's `rig`


def test_cardan_run_help():
    """``cardan run --help`` (the core-only parser) shows the run options and exits 0."""
    seen = cardan_help("run", "--help")
    assert seen["status"] == 0 and seen["heavy"] == []
    assert "--engine" in seen["text"] and "--accuracy" in seen["text"]


def test_unknown_command_gets_the_whole_parser():
    """A command that is no core command is checked against the whole parser (exit 2, one line)."""
    proc = subprocess.run([sys.executable, "-m", "cardan_exudyn.cli", "rnu"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2
    assert "invalid choice: 'rnu'" in proc.stderr and "reproduce" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


class RippledMotion:
    """An input angle ``6 (t - t0) + ripple sin(12 (t - t0))`` [rad], as the reference engine's
    input motion offers it (``angle(t)``)."""

    def __init__(self, t0: float, ripple: float):
        self.t0, self.ripple = t0, ripple

    def angle(self, t: float) -> float:
        return 6.0 * (t - self.t0) + self.ripple * math.sin(12.0 * (t - self.t0))


def offset(t: float, motion: RippledMotion, theta: float) -> float:
    return motion.angle(t) - theta


@pytest.mark.parametrize("t0", [0.0, 1e9], ids=["t0=0", "t0=1e9"])
@pytest.mark.parametrize("ripple", [0.0, 0.03, 0.4], ids=["steady", "ripple", "speed-dips"])
def test_window_times_agree_with_brentq(t0, ripple):
    """The reference engine's time-at-angle root (Illinois regula falsi, in place of scipy's
    brentq so that building a scene needs no scipy) meets brentq's own tolerance; ripple 0.4
    lets the speed dip to 1.2 rad/s."""
    from scipy.optimize import brentq

    from reference.engine.work import time_at_angle

    motion = RippledMotion(t0, ripple)
    rtol = 4 * np.finfo(float).eps  # brentq's settings in the engine before, xtol 1e-15 s
    for lo in t0 + np.random.default_rng(7).uniform(0.0, 2.0, 40):
        hi = lo + 1e-3
        theta = motion.angle(lo) + 0.37 * (motion.angle(hi) - motion.angle(lo))
        expected = brentq(offset, lo, hi, args=(motion, theta), xtol=1e-15, rtol=rtol)
        # both stop within their tolerance of the root, so within twice it of each other
        assert abs(time_at_angle(motion, theta, lo, hi) - expected) <= 2 * (1e-15 + rtol * lo)


WHOLE_RUN = """
import sys
import cardan_exudyn.cli as cli
status = cli.main(sys.argv[1:])
print("pandas" in sys.modules, status)
"""


@pytest.mark.parametrize("engine", ["exudyn", "reference"])
def test_a_run_without_out_builds_no_table(engine, tmp_path):
    """``cardan run`` without ``--out`` never imports pandas (nobody reads its time table); with
    ``--out`` the table is built and written."""
    base = ["run", "--engine", engine, "--revolutions", "1"]
    bare = subprocess.run([sys.executable, "-c", WHOLE_RUN, *base], capture_output=True, text=True,
                          timeout=300)
    assert bare.stdout.splitlines()[-1] == "False 0", bare.stderr
    out = tmp_path / "out"
    written = subprocess.run([sys.executable, "-c", WHOLE_RUN, *base, "--out", str(out)],
                             capture_output=True, text=True, timeout=300)
    assert written.stdout.splitlines()[-1] == "True 0", written.stderr
    assert (out / "timeseries.csv").stat().st_size > 0
