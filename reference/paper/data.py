"""The paper's data file (``data/paper.toml``): every entry with value, unit and source or assumption
(Cavacece, Stefanelli, Valentini, Vita, "A multibody dynamic model of a Cardan joint with
experimental validation").
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

__all__ = ["assumption_register", "paper_data", "stated_values", "value"]


@functools.lru_cache(maxsize=1)
def paper_data() -> dict[str, Any]:
    """The raw data file, every entry with value, unit and source or assumption."""
    # beside this module (package data), not importlib.resources: ~5 ms less import per command
    text = (Path(__file__).parent / "data" / "paper.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def value(path: str) -> Any:
    """Value of a dotted entry of the data file, e.g. ``value("bearings.frame.length")``, in its own
    ``unit`` (mostly SI; angles [deg], multibody speeds [rpm]).
    """
    node: Any = paper_data()
    for key in path.split("."):
        node = node[key]
    return node["value"]


def assumption_register() -> list[dict[str, Any]]:
    """Every value the paper does not state: name, value, unit, assumption, reason."""
    return [{"name": k, **v} for k, v in paper_data()["assumption"].items()]


def stated_values() -> list[dict[str, Any]]:
    """Every value taken from the paper, with unit and source."""
    out = []

    def walk(prefix: str, node: dict) -> None:
        for key, item in node.items():
            if isinstance(item, dict) and "source" in item:
                out.append({"name": f"{prefix}{key}", **item})
            elif isinstance(item, dict):
                walk(f"{prefix}{key}.", item)

    for section in ("table1", "bearings", "case"):
        walk(f"{section}.", paper_data()[section])
    return out
