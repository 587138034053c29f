"""Scenes as users write them: TOML files and tables that may start from a named scene
(``base = "paper-10deg"``) and override what differs. It needs the paper's data, so it sits above
:mod:`reference.scene.mapping` and :mod:`reference.paper`.
"""

from __future__ import annotations

import pathlib
from collections.abc import Mapping
from typing import Any

from reference.paper.scenes import named_scene
from reference.scene.mapping import UNIT_ALIASES, scene_from_dict, scene_to_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError, SceneTypeError

__all__ = ["read_toml", "load_scene", "scene_from_mapping"]

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib


def _merge(base: dict, over: Mapping) -> dict:
    """``base`` (a scene's dictionary form) with the tables and values of ``over`` laid on top."""
    out = dict(base)
    for alias_base, (suffix, _) in UNIT_ALIASES.items():
        if alias_base + suffix in over:
            out.pop(alias_base, None)  # the override's unit-suffixed value replaces the base's
    for key, value in over.items():
        if (key == "drive" and isinstance(value, Mapping) and isinstance(out.get(key), Mapping)
                and "kind" in value and value["kind"] != out[key].get("kind")):
            out[key] = dict(value)  # another kind of drive replaces the base's, keys and all
        elif isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = _merge(out[key], value)
        elif key == "drive" and isinstance(value, Mapping) and "kind" not in value:
            out[key] = _merge(out.get(key, {}), value)
        else:
            out[key] = value
    return out


def read_toml(path: str | pathlib.Path, what: str, noun: str,
              error: type[Exception]) -> dict[str, Any]:
    """The table of a UTF-8 TOML file at ``path``, or ``error`` in one line naming ``what`` the file is
    (and ``noun``, what it holds, when it is not text).
    """
    if not isinstance(path, (str, pathlib.PurePath)) or not str(path).strip():
        raise error(f"the {what} must be a path (str or pathlib.Path) naming a file, got {path!r:.80}")
    path = pathlib.Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise error(f"cannot read {what} {str(path)!r}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{what} {str(path)!r} is not UTF-8 text (byte {exc.start}); {noun} is a "
                    "TOML file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{what} {str(path)!r} is not valid TOML: {exc}") from None


def load_scene(path: str | pathlib.Path) -> Scene:
    """The scene of a TOML file at ``path`` (SI or unit-suffixed aliases; may start from ``base``);
    SceneError, starting with the path, when it cannot be read, is not TOML or is not a valid scene.
    """
    if not isinstance(path, (str, pathlib.PurePath)):
        raise SceneTypeError(f"`path` must be a str or pathlib.Path naming a scene file, got "
                             f"{type(path).__name__} {path!r:.80}")
    data = read_toml(path, "scene file", "a scene", SceneError)
    try:
        return scene_from_mapping(data)
    except SceneError as exc:
        raise SceneError(f"{path}: {exc}") from None


def scene_from_mapping(data: Mapping[str, Any]) -> Scene:
    """:func:`reference.scene.mapping.scene_from_dict` of ``data`` after resolving its optional ``base``
    named scene, which the other keys override.
    """
    if not isinstance(data, Mapping):
        raise SceneTypeError(f"`data` must be a mapping (a scene table), got {type(data).__name__} "
                             f"{data!r:.80}")
    data = dict(data)
    base = data.pop("base", None)
    if base is not None:
        if not isinstance(base, str):
            raise SceneTypeError(f"`base` must be the name of a scene (a string), got {base!r:.80}")
        data = _merge(scene_to_dict(named_scene(base)), data)
    return scene_from_dict(data)
