"""A scene for a test: a named scene, a TOML file or a scene, with overrides."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from reference.paper.scenes import named_scene
from reference.scene.files import load_scene
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import SceneError

__all__ = ["make_scene"]


def make_scene(source: str | Path | Scene, root: str | Path | None = None, **changes: Any) -> Scene:
    """The scene ``source`` names, with ``changes`` applied.

    Parameters
    ----------
    source : str, pathlib.Path or Scene
        A named scene (:func:`reference.paper.scenes.named_scene`), a TOML file (a ``Path``, or a
        string ending in ``.toml`` or holding a ``/``), or a scene.
    root : str or pathlib.Path, optional
        Folder of a relative file path (default: the current folder).
    **changes
        Scene fields by dotted path (:func:`reference.scene.mapping.replace`); ``__`` stands for the
        dot (``numerics__accuracy=1e-4``); unit-suffixed names work (``shaft_angle_deg``).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        The message names the source.
    """
    try:
        scene = _source(source, root)
        if changes:
            scene = replace(scene, **{k.replace("__", "."): v for k, v in changes.items()})
    except SceneError as exc:
        raise SceneError(f"scene {_label(source)}: {exc}") from None
    return scene


def _source(source: str | Path | Scene, root: str | Path | None) -> Scene:
    """The scene ``source`` names, without changes."""
    if isinstance(source, Scene):
        return source
    if isinstance(source, Path) or (isinstance(source, str) and
                                    (source.lower().endswith(".toml") or "/" in source)):
        path = Path(source)
        return load_scene(path if root is None or path.is_absolute() else Path(root) / path)
    if isinstance(source, str):
        return named_scene(source)
    raise SceneError(f"the source must be a scene name, a TOML file or a Scene, "
                     f"got {type(source).__name__}")


def _label(source: Any) -> str:
    """How an error message names ``source``."""
    return repr(source.name) if isinstance(source, Scene) else repr(str(source))
