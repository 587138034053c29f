"""A scene as a plain dictionary (and so TOML / JSON), and back; changes by dotted path. Unknown keys
are rejected; unit-suffixed aliases (:data:`UNIT_ALIASES`: ``shaft_angle_deg``, ``speed_rpm``,
``a1_mm``) are accepted at the boundary.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from reference.scene.drives import DRIVES, Drive
from reference.scene.joint import PAIR_NAMES, Body, Geometry, Joint, MountingErrors, Pair, Pairs
from reference.scene.load import Load
from reference.scene.scene import Scene
from reference.scene.settings import FrictionSettings, Numerics, Record
from reference.scene.validation import DEG, RPM, SceneError, finite, is_sequence, require_scene

__all__ = ["UNIT_ALIASES", "replace", "scene_from_dict", "scene_to_dict"]

UNIT_ALIASES = {
    "shaft_angle": ("_deg", DEG),
    "speed": ("_rpm", RPM),
    "initial_speed": ("_rpm", RPM),
    **{f"a{k}": ("_mm", 1e-3) for k in range(1, 5)},
    **{f"alpha{k}": ("_deg", DEG) for k in range(1, 5)},
    "s1": ("_mm", 1e-3),
}
"""Fields that accept a unit-suffixed alias at the boundary: name -> (suffix, factor to SI)."""


_SECTIONS: dict[type, dict[str, Any]] = {
    Scene: {"joint": Joint, "load": Load, "numerics": Numerics, "friction": FrictionSettings,
            "record": Record},
    Joint: {"input": Body, "spider": Body, "output": Body, "geometry": Geometry, "pairs": Pairs,
            "errors": MountingErrors},
    Pairs: {name: Pair for name in PAIR_NAMES},
}


def _to_si(data: dict[str, Any], names: set[str], where: str) -> None:
    """Replace the unit-suffixed keys of ``data`` (those of :data:`UNIT_ALIASES` that ``names``
    has) by their SI fields, in place."""
    for key in list(data):
        for base, (suffix, factor) in UNIT_ALIASES.items():
            if key == base + suffix and base in names:
                if base in data:
                    raise SceneError(f"[{where}] give either `{base}` or `{key}`, not both")
                value = data.pop(key)
                data[base] = finite(key, value) * factor if not is_sequence(value) else value


def _build(cls: type, data: Mapping[str, Any], path: str) -> Any:
    """An instance of the scene part ``cls`` from its table at dotted ``path`` ("" for the scene)."""
    where = path or "scene"
    if not isinstance(data, Mapping):
        raise SceneError(f"[{where}] must be a table, got {data!r}")
    data = dict(data)
    names = {f.name for f in dataclasses.fields(cls) if f.init}
    _to_si(data, names, where)
    unknown = sorted(set(data) - names - {"kind"})
    if unknown:
        raise SceneError(f"[{where}] unknown key(s) {unknown}; allowed: {_allowed_keys(cls, names)}")
    kwargs = {}
    for key, value in data.items():
        if key == "kind":
            continue
        sub = _SECTIONS.get(cls, {}).get(key)
        if key == "drive" and cls is Scene:
            kwargs[key] = _build_drive(value, f"{path}.drive".lstrip("."))
        elif sub is not None:
            kwargs[key] = _build(sub, value, f"{path}.{key}".lstrip("."))
        else:
            kwargs[key] = value
    missing = sorted(f.name for f in dataclasses.fields(cls) if f.init and f.name not in kwargs
                     and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
    if missing:
        raise SceneError(f"[{where}] missing required key(s) {missing}"
                         + (" (or start from a named scene with `base = \"paper\"`)" if cls is Scene else ""))
    try:
        return cls(**kwargs)
    except (SceneError, TypeError) as exc:  # TypeError: a value of the wrong kind for a field
        raise SceneError(f"[{where}] {exc}") from None


def _allowed_keys(cls: type, names: set[str]) -> list[str]:
    """The keys a table of ``cls`` takes, for messages: its fields, their unit-suffixed aliases
    and, for a drive, ``kind``."""
    aliases = {base + suffix for base, (suffix, _) in UNIT_ALIASES.items() if base in names}
    return sorted(names | aliases | ({"kind"} if cls in DRIVES.values() else set()))


def _build_drive(data: Mapping[str, Any], path: str) -> Drive:
    """The drive of the kind its table names (``kind = "speed" | "angle" | "torque"``)."""
    if not isinstance(data, Mapping):
        raise SceneError(f"[{path}] must be a table, got {data!r}")
    kind = data.get("kind")
    if kind not in DRIVES:
        raise SceneError(f"[{path}] `kind` must be one of {sorted(DRIVES)}, got {kind!r}")
    return _build(DRIVES[kind], data, path)


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """Build and validate a scene from a TOML-shaped dictionary ``data`` (SI units or
    :data:`UNIT_ALIASES`; a named ``base`` is :func:`reference.scene.files.scene_from_mapping`'s);
    SceneError naming the table and value of an unknown, missing or invalid key.
    """
    return _build(Scene, data, "")


def scene_to_dict(obj: Any) -> Any:
    """The fully resolved scene (or part) as JSON/TOML-ready data, SI units: dataclasses as dicts (None
    fields left out), tuples as lists; :func:`scene_from_dict` reads it back to an equal scene.
    """
    if dataclasses.is_dataclass(obj):
        out = {}
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if value is None:
                continue
            out[f.name] = scene_to_dict(value)
        return out
    if isinstance(obj, tuple):
        return [scene_to_dict(v) for v in obj]
    return obj


def replace(scene: Scene, **changes: Any) -> Scene:
    """Copy of ``scene`` with dotted-path ``changes`` (SI, or a unit-suffixed leaf such as
    ``"joint.geometry.shaft_angle_deg"``), validated again; SceneError for an unknown path or an
    invalid value. Example: ``replace(scene, **{"load.torque": 1.0})``.
    """
    data = scene_to_dict(require_scene(scene))
    for dotted, value in changes.items():
        node = data
        *parents, leaf = dotted.split(".")
        if not all(parents) or not leaf:
            raise SceneError(f"unknown scene field {dotted!r}")
        for key in parents:
            if not isinstance(node.get(key), dict):
                raise SceneError(f"unknown scene field {dotted!r}")
            node = node[key]
        for base, (suffix, _) in UNIT_ALIASES.items():
            if leaf == base + suffix:
                node.pop(base, None)
        node[leaf] = value
    return scene_from_dict(data)
