"""The stored loads of ``[loads]`` in the data file: which scenes, and the text to store. Regenerate
when ``tests/test_paper_loads.py`` says so::

    python -c "from reference.paper.load_table import loads_toml; print(loads_toml())"

and paste the output over ``[loads]`` of ``reference/paper/data/paper.toml``.
"""

from __future__ import annotations

from typing import Any

from reference.paper.cases import paper_cases
from reference.paper.loads import scene_key, solve_mean_input_load
from reference.paper.parameter_sets import PARAMETER_SETS, set_values
from reference.paper.scenes import paper_scene, rig_scene
from reference.scene.scene import Scene

__all__ = ["COMMAND", "load_entries", "loads_toml", "mean_input_sets", "stored_scenes"]

COMMAND = 'python -c "from reference.paper.load_table import loads_toml; print(loads_toml())"'
"""The command that prints ``[loads]``."""


def mean_input_sets() -> list[str]:
    """The parameter sets whose ``torque_reading`` is ``mean_input`` (their scenes need a load)."""
    return [name for name in PARAMETER_SETS if set_values(name).get("torque_reading") == "mean_input"]


def stored_scenes() -> dict[str, Scene]:
    """Named scene -> the scene its load is solved for, for every named scene with friction whose set
    reads the torque as ``mean_input`` (built with the reading ``output_load``, so building solves
    nothing; labels differ, which :func:`reference.paper.loads.scene_key` leaves out).
    """
    out: dict[str, Scene] = {}
    for name in mean_input_sets():
        values = {**set_values(name), "torque_reading": "output_load"}
        for case in paper_cases():
            deg = case["shaft_angle_deg"]
            rpm = case["speed_rpm"]
            out[f"paper-{name}-{deg:g}deg-{rpm:g}rpm"] = paper_scene(deg, rpm, parameters=values)
        for errors in (False, True):
            out[f"rig-{name}" + ("-errors" if errors else "")] = rig_scene(parameters=values,
                                                                             errors=errors)
    return out


def load_entries() -> dict[str, dict[str, Any]]:
    """Named scene -> ``key`` (:func:`reference.paper.loads.scene_key`), ``target`` (mean input torque
    [N m]) and ``torque`` (the output load [N m], solved by the reference engine).
    """
    return {name: {"key": scene_key(scene), "target": float(scene.load.torque),
                   "torque": solve_mean_input_load(scene)}
            for name, scene in stored_scenes().items()}


def loads_toml() -> str:
    """``[loads]`` of the data file, solved afresh, floats with every digit (``repr``) so the stored
    value is the solved one exactly.
    """
    from reference.engine.solve import ENGINE_VERSION  # the paper's data sit below the engine

    lines = [
        "[loads]",
        f"command = '{COMMAND}'",
        f'engine = "{ENGINE_VERSION}"',
        'method = "two reference-engine runs (default options) and a secant step '
        '(reference/paper/loads.py: solve_mean_input_load); about 1e-6 of the target"',
    ]
    for name, entry in load_entries().items():
        lines += ["", f'[loads.scenes."{name}"]', f'key = "{entry["key"]}"',
                  f"target = {entry['target']!r}", f"torque = {entry['torque']!r}"]
    return "\n".join(lines)
