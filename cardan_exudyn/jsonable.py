"""Plain JSON data from the project's values: numpy scalars and arrays, enums, summaries; NaN and
infinities as null (JSON has neither), so that every file and ``--json`` output is strict JSON."""

from __future__ import annotations

import math
from enum import Enum
from typing import Any

import numpy as np

from reference.results.summary import Summary

__all__ = ["to_jsonable", "dumps"]


def to_jsonable(value: Any) -> Any:
    """``value`` as plain JSON data: Summary as ``to_dict()``, enums as values, string keys, sequences and
    arrays as lists, numpy scalars as Python numbers, non-finite floats as None."""
    if isinstance(value, Summary):
        return to_jsonable(value.to_dict())
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, (np.bool_,)):
        return bool(value)
    return value


def dumps(data: Any) -> str:
    """``data`` as indented strict JSON text (:func:`to_jsonable` first)."""
    import json  # import cost: a plain `cardan run` writes no JSON

    return json.dumps(to_jsonable(data), indent=2, allow_nan=False)
