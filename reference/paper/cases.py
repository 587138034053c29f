"""The paper's eleven mean efficiencies as cases, and the envelope the model reaches for each."""

from __future__ import annotations

from typing import Any

from reference.paper.data import paper_data, value

__all__ = ["case_key", "envelope", "in_fit", "paper_cases"]


def case_key(case: dict[str, Any]) -> str:
    """``study:angle:rpm``, the key of one of :func:`paper_cases` (``table2:10:2000``)."""
    return f"{case['study']}:{case['shaft_angle_deg']:g}:{case['speed_rpm']:g}"


def in_fit(case: dict[str, Any], fit: list[str] | tuple[str, ...]) -> bool:
    """Whether ``case`` (one of :func:`paper_cases`) is one of the ``fit`` case keys or the same scene
    (angle and speed) as one.
    """
    scene = (float(case["shaft_angle_deg"]), float(case["speed_rpm"]))
    return any((float(k.split(":")[1]), float(k.split(":")[2])) == scene for k in fit)


def envelope() -> list[dict[str, Any]]:
    """Per case of :func:`paper_cases`, the stored (``cardan calibrate --envelope``) lowest and highest mean
    efficiency over :func:`plausible_box`: ``case``, ``paper``, ``lowest``, ``highest`` [-],
    ``reachable``, ``closest``, ``lowest_at``/``highest_at``; empty when nothing is stored.
    """
    stored = paper_data().get("envelope", {}).get("cases", {})
    out = []
    for case in paper_cases():
        entry = stored.get(case_key(case))
        if entry is None:
            continue
        lo = entry["lowest"]
        hi = entry["highest"]
        paper = case["paper_mean_efficiency"]
        out.append({"case": case_key(case), "paper": paper, "lowest": lo, "highest": hi,
                    "reachable": lo <= paper <= hi, "closest": min(max(paper, lo), hi),
                    "lowest_at": dict(entry.get("lowest_at", {})),
                    "highest_at": dict(entry.get("highest_at", {}))})
    return out


def paper_cases() -> list[dict[str, Any]]:
    """The paper's eleven numbers: Table 2 (8 angles) and the speed study (3 speeds)."""
    cases = []
    t2 = paper_data()["case"]["table2"]
    for deg, eta in zip(t2["shaft_angle"]["value"], t2["mean_efficiency"]["value"], strict=True):
        cases.append({"study": "table2", "shaft_angle_deg": deg,
                      "speed_rpm": value("case.multibody.speed"), "paper_mean_efficiency": eta})
    sp = paper_data()["case"]["speed_study"]
    for rpm, eta in zip(sp["speed"]["value"], sp["mean_efficiency"]["value"], strict=True):
        cases.append({"study": "speed", "shaft_angle_deg": sp["shaft_angle"]["value"],
                      "speed_rpm": rpm, "paper_mean_efficiency": eta})
    return cases
