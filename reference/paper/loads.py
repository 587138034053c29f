"""The output load of the ``mean_input`` torque reading (the case's torque is the mean input torque):
stored in ``[loads]`` of the data file for the named scenes, keyed by :func:`scene_key`, else
solved by the reference engine on first use and cached for the process.
"""

from __future__ import annotations

import functools
import hashlib
import json

from reference.paper.data import paper_data
from reference.scene.drives import SpeedDrive
from reference.scene.mapping import replace, scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

__all__ = ["UNKEYED_FIELDS", "mean_input_load", "scene_key", "solve_mean_input_load", "stored_loads"]

UNKEYED_FIELDS = ("name", "description", "parameter_set")
"""Scene fields left out of :func:`scene_key`: labels that do not change the load."""


def scene_key(scene: Scene) -> str:
    """Fingerprint of what the load depends on in ``scene``: the first 16 hex digits of the SHA-256 of
    its dictionary form (sorted JSON, :data:`UNKEYED_FIELDS` left out, floats exact).
    """
    data = {k: v for k, v in scene_to_dict(scene).items() if k not in UNKEYED_FIELDS}
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def stored_loads() -> dict[str, float]:
    """Scene key -> stored load [N m], from ``[loads.scenes]`` of the data file (empty if none)."""
    scenes = paper_data().get("loads", {}).get("scenes", {})
    return {entry["key"]: float(entry["torque"]) for entry in scenes.values()}


def mean_input_load(scene: Scene) -> float:
    """The constant output load [N m] under which ``scene``'s mean input torque equals its load torque:
    stored (:func:`stored_loads`), else :func:`solve_mean_input_load` (and its SceneError).
    """
    stored = stored_loads().get(scene_key(scene))
    return solve_mean_input_load(scene) if stored is None else stored


@functools.lru_cache(maxsize=256)
def solve_mean_input_load(scene: Scene) -> float:
    """:func:`mean_input_load` by the reference engine: the load is ``target * eta(load)``; two runs and a
    secant step give it to about 1e-6 of the target (the target without friction). SceneError unless a
    constant-speed drive, or when the run fails.
    """
    target = scene.load.torque
    if not isinstance(scene.drive, SpeedDrive) or not scene.load.constant:
        raise SceneError("`torque_reading` 'mean_input' needs a constant-speed drive and a constant load")
    if not scene.has_friction or target == 0.0:
        return target
    from reference.engine.solve import run  # the paper's data sit below the engine; imported on use

    loads = [target]
    torques = []
    for _ in range(2):
        trial = replace(scene, **{"load.torque": loads[-1], "record.timeseries": False})
        result = run(trial)
        if not result.success or not result.summary.mean_efficiency:
            raise SceneError(f"cannot find the load for a mean input torque of {target:g} N m: the "
                             f"reference run ended {result.status}: {result.message}")
        torques.append(loads[-1] / float(result.summary.mean_efficiency))
        if len(loads) == 1:
            loads.append(target * float(result.summary.mean_efficiency))
    return _secant(target, loads, torques)


def _secant(target: float, loads: list[float], torques: list[float]) -> float:
    """The load [N m] where the line through ``(loads[k], torques[k])`` reaches ``target`` [N m]; the second
    load if the line is flat.
    """
    l0, l1 = loads
    t0, t1 = torques
    return l1 + (target - t1) * (l1 - l0) / (t1 - t0) if t1 != t0 else l1
