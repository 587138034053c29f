"""The checks of a campaign file's values: each problem a :class:`CampaignError` in one line naming
where it is (the campaign file's name is added by :func:`rigdata.campaign.spec.campaign_from_mapping`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = ["CampaignError", "known", "table_of", "text", "required", "number", "count"]


class CampaignError(ValueError):
    """A campaign file or table that cannot run; the one-line message names the file and the key."""


def known(table: Mapping[str, Any], known: set[str], where: str) -> None:
    """CampaignError for a key of ``table`` that is not in ``known``."""
    unknown = sorted(set(table) - known)
    if unknown:
        raise CampaignError(f"{where}: unknown key {unknown[0]!r} (known: {', '.join(sorted(known))})")


def table_of(data: Mapping[str, Any], key: str, where: str = "the campaign") -> Mapping[str, Any]:
    """``data[key]`` as a table (empty if absent)."""
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise CampaignError(f"{where}: `{key}` must be a table, got {value!r:.80}")
    return value


def text(data: Mapping[str, Any], key: str, where: str, default: str) -> str:
    """``data[key]`` as a non-empty string."""
    value = data.get(key, default)
    if not isinstance(value, str) or (key != "title" and not value.strip()):
        raise CampaignError(f"{where}: `{key}` must be a string, got {value!r:.80}")
    return value


def required(table: Mapping[str, Any], key: str, where: str) -> Any:
    """``table[key]``; CampaignError naming ``where`` when it is missing."""
    if key not in table:
        raise CampaignError(f"{where}: `{key}` is missing")
    return table[key]


def number(value: Any, where: str) -> float:
    """``value`` as a finite float; CampaignError naming ``where`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CampaignError(f"{where} must be a finite number, got {value!r:.80}")
    return float(value)


def count(data: Mapping[str, Any], key: str, default: int) -> int:
    """``data[key]`` as an integer >= 0."""
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise CampaignError(f"`{key}` must be an integer >= 0, got {value!r:.80}")
    return value
