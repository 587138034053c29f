"""What a validation ran with, for ``validation.json``: the model scene as its resolved TOML dictionary
with a hash, its shaft angle and friction, the engines' versions; and the rerun of that model from a
``validation.json`` alone.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from cardan_exudyn.engines import run
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.report.environment import environment
from reference.scene.mapping import scene_from_dict, scene_to_dict
from reference.scene.scene import Scene
from rigdata.model import computed_efficiency
from rigdata.record import RigDataError

__all__ = ["ENGINE_PACKAGES", "scene_sha256", "scene_entry", "model_settings", "run_environment", "rerun"]

#: The package whose version is each engine's.
ENGINE_PACKAGES = {"reference": "cardan-exudyn", "exudyn": "exudyn"}


def scene_sha256(toml: Mapping[str, Any]) -> str:
    """SHA-256 of a scene dictionary's canonical JSON (sorted keys)."""
    return hashlib.sha256(json.dumps(to_jsonable(toml), sort_keys=True).encode()).hexdigest()


def scene_entry(scene: Scene) -> dict[str, Any]:
    """``name``, ``sha256`` and ``toml`` (:func:`reference.scene.mapping.scene_to_dict`, SI) of ``scene``."""
    toml = to_jsonable(scene_to_dict(scene))
    return {"name": scene.name, "sha256": scene_sha256(toml), "toml": toml}


def model_settings(scene: Scene) -> dict[str, Any]:
    """``shaft_angle_deg`` [deg] and ``friction_coefficient`` (per pair, chain order) of ``scene``."""
    return {"shaft_angle_deg": math.degrees(scene.joint.geometry.shaft_angle),
            "friction_coefficient": {name: pair.friction_coefficient
                                     for name, pair in scene.joint.pairs.items()}}


def run_environment(engines: Iterable[str]) -> dict[str, Any]:
    """:func:`cardan_exudyn.report.environment.environment` with ``engines``: each engine's package and
    version.
    """
    env = environment()
    versions = env["packages"]
    env["engines"] = {e: {"package": ENGINE_PACKAGES.get(e), "version": versions.get(ENGINE_PACKAGES.get(e))}
                      for e in engines}
    return env


def _summary(source: Mapping[str, Any] | str | os.PathLike) -> Mapping[str, Any]:
    """``source`` itself or the ``validation.json`` it names."""
    if isinstance(source, Mapping):
        return source
    return json.loads(Path(source).read_text(encoding="utf-8"))


def rerun(source: Mapping[str, Any] | str | os.PathLike, engine: str = "reference") -> dict[str, Any]:
    """The model of a validation run again from its ``validation.json`` (path or loaded) alone.

    Parameters
    ----------
    source : dict, str or path-like
        ``validation.json`` or its content.
    engine : str
        Engine to run the stored scene on.

    Returns
    -------
    dict
        :func:`rigdata.model.computed_efficiency` without ``series``.

    Raises
    ------
    RigDataError
        No ``scene`` in ``source``, or a scene whose hash is not the stored one.
    """
    summary = _summary(source)
    stored = summary.get("scene")
    if not isinstance(stored, Mapping) or "toml" not in stored:
        raise RigDataError("`source` has no `scene` with a `toml` dictionary: not a validation.json of this "
                           "version")
    if scene_sha256(stored["toml"]) != stored.get("sha256"):
        raise RigDataError(f"`source` scene {stored.get('name')!r}: its dictionary does not hash to the "
                           f"stored sha256 {stored.get('sha256')!r}")
    computed = computed_efficiency(run(scene_from_dict(stored["toml"]), engine))
    return {k: val for k, val in computed.items() if k != "series"}
