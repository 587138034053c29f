"""Checks of user input shared by every part of a scene, the one :class:`SceneError` they raise
(naming the field, the rule and the value), and the units :data:`DEG`, :data:`RPM` (SI inside).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["RPM", "DEG", "MAX_STEPS", "MAX_STEPS_PER_REVOLUTION", "MAX_MAGNITUDE", "SceneError",
           "SceneTypeError", "require_scene", "require_instance", "is_sequence", "finite", "positive",
           "non_negative", "vector", "float_array", "check_history", "set_field", "check_steps",
           "refuse_steps_per_revolution"]

RPM = 2.0 * math.pi / 60.0
"""One revolution per minute [rad/s]."""
DEG = math.pi / 180.0
"""One degree [rad]."""

MAX_STEPS = 10_000_000
"""Most time steps (or table rows) one run may take. More is refused as bad input by every engine
before it starts: e.g. ``dt = 1e-12`` s would take days and more memory than a machine has."""


MAX_STEPS_PER_REVOLUTION = 2_000_000
"""Most time steps per input revolution an engine's automatic step may choose. A finer step is
refused (:func:`refuse_steps_per_revolution`), never capped: a capped step would miss the accuracy
it was chosen for while the run still took hours."""


MAX_MAGNITUDE = 1e12
"""Largest magnitude of any number of a scene, in its SI unit. Far beyond every Cardan joint
(the largest drive shafts carry about 1e7 N m and turn below 1e4 rad/s), and far enough below
overflow (1e308) that products of a few such numbers stay finite: a value above it is a typing
error or an absurd input, refused before any engine runs instead of ending in NaN or overflow."""


class SceneError(ValueError):
    """A scene (or one of its parts) is invalid; the message names the field and the value."""


class SceneTypeError(SceneError, TypeError):
    """A scene field (or scene argument) of the wrong type: both a :class:`SceneError` (the command
    line's one-line error, exit 2) and a ``TypeError``.
    """


def require_scene(value: Any, name: str = "scene") -> Any:
    """``value`` when it is a :class:`reference.scene.scene.Scene`, else :class:`SceneTypeError` naming
    ``name``.
    """
    if type(value).__name__ != "Scene" or not hasattr(value, "drive"):  # no import: scene.py imports this
        hint = " (a named scene: reference.named_scene(name); a file: reference.load_scene(path))" \
            if isinstance(value, (str, bytes)) else ""
        raise SceneTypeError(f"`{name}` must be a Scene, got {type(value).__name__} {value!r:.80}{hint}")
    return value


def require_instance(name: str, value: Any, cls: type | tuple[type, ...], what: str) -> Any:
    """``value`` when it is an instance of ``cls``, else :class:`SceneTypeError` naming ``name`` and
    ``what`` it must be (e.g. "a Drive").
    """
    if not isinstance(value, cls):
        raise SceneTypeError(f"`{name}` must be {what}, got {type(value).__name__} {value!r:.80}")
    return value


def is_sequence(value: Any) -> bool:
    """True for a list, tuple or numpy array (a history rather than one number)."""
    return isinstance(value, (list, tuple, np.ndarray))


def finite(name: str, value: Any) -> float:
    """``value`` as a float; :class:`SceneError` naming ``name`` unless a finite number (booleans refused)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise SceneTypeError(f"`{name}` must be a number, got {value!r:.80}")
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range
        raise SceneError(f"`{name}` must be at most {MAX_MAGNITUDE:g} in magnitude, "
                         f"got {value:.3e}") from None
    if not math.isfinite(value):
        raise SceneError(f"`{name}` must be finite, got {value!r}")
    if abs(value) > MAX_MAGNITUDE:
        raise SceneError(f"`{name}` must be at most {MAX_MAGNITUDE:g} in magnitude (SI units), got {value!r}")
    return value


def positive(name: str, value: Any) -> float:
    """:func:`finite`, and > 0."""
    value = finite(name, value)
    if value <= 0.0:
        raise SceneError(f"`{name}` must be positive, got {value!r}")
    return value


def non_negative(name: str, value: Any) -> float:
    """:func:`finite`, and >= 0."""
    value = finite(name, value)
    if value < 0.0:
        raise SceneError(f"`{name}` must be >= 0, got {value!r}")
    return value


def vector(name: str, value: Any, shape: tuple[int, ...]) -> tuple:
    """``value`` as (nested) tuples of finite floats of ``shape`` (``(3,)`` or ``(3, 3)``);
    :class:`SceneError` naming ``name`` otherwise.
    """
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"`{name}` must be numeric with shape {shape}, got {value!r}") from None
    if arr.shape != shape:
        raise SceneError(f"`{name}` must have shape {shape}, got shape {arr.shape}: {value!r}")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"`{name}` must be finite, got {value!r}")
    if np.any(np.abs(arr) > MAX_MAGNITUDE):
        raise SceneError(f"`{name}` must be at most {MAX_MAGNITUDE:g} in magnitude (SI units), got {value!r}")
    return tuple(map(tuple, arr.tolist())) if arr.ndim == 2 else tuple(arr.tolist())  # Python floats


def float_array(name: str, value: Any) -> np.ndarray | None:
    """A sequence ``value`` as a float array, None when not a sequence; :class:`SceneTypeError` naming
    ``name`` when a sample is not a number.
    """
    if not is_sequence(value):
        return None
    try:
        arr = np.asarray(value)
        if arr.dtype.kind not in "iuf" and arr.size:  # text, booleans, ragged or nested objects
            raise TypeError
        return np.asarray(arr, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise SceneTypeError(f"{name} must be numbers, got {value!r:.80}") from None


def check_history(t: np.ndarray | None, values: np.ndarray | None, raw_time: Any, raw_values: Any,
                  values_name: str, minimum: int, prefix: str = "") -> None:
    """Refuse a history unless its times ``t`` [s] increase strictly, number ``minimum`` or more and
    ``values`` has one finite value per time; ``raw_*``, ``values_name`` and ``prefix`` word the messages.
    """
    if t is None or t.ndim != 1 or t.size < minimum:
        raise SceneError(f"{prefix}`time` must be a sequence of at least {minimum} numbers, "
                         f"got {raw_time!r}")
    if values is None or values.shape != t.shape:
        raise SceneError(f"{prefix}`{values_name}` must have one value per time sample ({t.size}), "
                         f"got {np.shape(raw_values) if values is not None else raw_values!r}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(values))):
        raise SceneError(f"{prefix}`time` and `{values_name}` must be finite")
    if np.any(np.abs(t) > MAX_MAGNITUDE) or np.any(np.abs(values) > MAX_MAGNITUDE):
        raise SceneError(f"{prefix}`time` and `{values_name}` must be at most {MAX_MAGNITUDE:g} in "
                         "magnitude (SI units)")
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise SceneError(f"{prefix}`time` must be strictly increasing, got {float(t[i])!r} "
                         f"then {float(t[i + 1])!r}")


def set_field(obj: Any, name: str, value: Any) -> None:
    """Store a validated ``value`` as field ``name`` of the frozen dataclass ``obj`` (from its
    ``__post_init__``).
    """
    object.__setattr__(obj, name, value)


def check_steps(steps: float, what: str) -> None:
    """Refuse ``steps`` beyond :data:`MAX_STEPS` (inf and NaN too); ``what`` needs them, for the message."""
    if not steps <= MAX_STEPS:
        raise SceneError(f"{what} needs {steps:.3g} steps; at most {MAX_STEPS:.0e} are allowed: give a "
                         "larger `numerics.dt` (or `numerics.accuracy`) or fewer `revolutions`")


def refuse_steps_per_revolution(steps: float, revolutions: float, seconds_per_step: float,
                                why: str) -> None:
    """Refuse ``steps`` per input revolution beyond :data:`MAX_STEPS_PER_REVOLUTION`; the message
    predicts the total over ``revolutions`` and the run time at ``seconds_per_step`` [s], and says ``why``.
    """
    if steps <= MAX_STEPS_PER_REVOLUTION:
        return
    total = steps * revolutions
    raise SceneError(f"{why} needs {steps:.3g} steps per input revolution (at most "
                     f"{MAX_STEPS_PER_REVOLUTION:.0e}): {total:.3g} steps, about "
                     f"{total * seconds_per_step:.3g} s; ask for a larger `accuracy`")
