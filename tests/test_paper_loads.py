"""The stored loads of the ``mean_input`` torque reading (``[loads]`` of the paper's data file)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from reference.paper.data import paper_data
from reference.paper.load_table import stored_scenes
from reference.paper.loads import mean_input_load, scene_key, solve_mean_input_load, stored_loads
from reference.paper.scenes import named_scene
from reference.scene.mapping import replace

STORED = paper_data()["loads"]["scenes"]

# 1e-12 of the load: far below the secant's 1e-6 of the target, above what another BLAS's
# rounding could move the reference engine's mean efficiency by.
RTOL = 1e-12


def test_every_scene_that_needs_a_load_has_its_current_key_stored():
    """The stored names are the scenes that need a load, each under the key of the scene as it is
    built now (a change to the data file or the scenes shows here, without running the engine)."""
    scenes = stored_scenes()
    assert set(STORED) == set(scenes)
    for name, scene in scenes.items():
        assert STORED[name]["key"] == scene_key(scene), name
        assert STORED[name]["target"] == scene.load.torque, name


@pytest.mark.parametrize("name", ["paper-physical-10deg-2000rpm"])
def test_stored_load_is_the_engine_solution(name):
    """The stored load of the default scene is what the reference engine solves for it."""
    scene = stored_scenes()[name]
    assert solve_mean_input_load(scene) == pytest.approx(STORED[name]["torque"], rel=RTOL, abs=0.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(STORED))
def test_every_stored_load_is_the_engine_solution(name):
    """Every stored load is what the reference engine solves for its scene (about 0.1 s each)."""
    scene = stored_scenes()[name]
    assert solve_mean_input_load(scene) == pytest.approx(STORED[name]["torque"], rel=RTOL, abs=0.0)


@pytest.mark.parametrize("name", sorted(STORED))
def test_named_scene_takes_the_stored_load(name):
    """Each named scene with a stored load carries it exactly."""
    assert named_scene(name).load.torque == STORED[name]["torque"]


def test_a_scene_not_stored_is_solved():
    """A scene outside the store (another angle) is solved, to the same rule as the stored ones."""
    scene = stored_scenes()["paper-physical-10deg-2000rpm"]
    other = replace(scene, **{"joint.geometry.shaft_angle_deg": 27.0})
    assert scene_key(other) not in stored_loads()
    assert mean_input_load(other) == solve_mean_input_load(other) < 2.0
    assert named_scene("paper-27deg").load.torque == solve_mean_input_load(other)


@pytest.mark.parametrize("name", ["paper-10deg", "paper-10deg-frictionless"])
def test_building_a_named_scene_runs_no_engine(name):
    """A stored or frictionless named scene built in a fresh interpreter imports no engine module."""
    code = (f"import json, sys, reference; s = reference.named_scene({name!r}); "
            "print(json.dumps([s.load.torque, sorted(m for m in sys.modules "
            "if m.startswith('reference.engine'))]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    torque, engine = json.loads(proc.stdout)
    assert engine == []
    if name == "paper-10deg":
        assert torque == STORED["paper-physical-10deg-2000rpm"]["torque"]
    else:
        assert torque == 2.0  # frictionless: the mean input torque is the load
