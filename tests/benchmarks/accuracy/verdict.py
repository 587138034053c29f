"""What the accuracy grid's rows say: the honesty verdict (:func:`honesty`) and the envelope
constants of the a-priori error model that the cells measure (:func:`fit_constants`: the values
``EFFICIENCY_FIRST_ORDER``, ``EFFICIENCY_FIRST_ORDER_ERRORS`` and ``EFFICIENCY_SECOND_ORDER`` of
:mod:`cardan_exudyn.model.stepsize` need)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["honesty", "fit_constants"]


def honesty(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The grid's verdict: shares of cells within the target, with the estimate within a factor 3
    of the true error (either way, or as a bound: true <= 3 x estimate), and the estimate's cost."""
    done = [r for r in rows if "true_error" in r]
    friction = [r for r in done if r["true_error"] > 0 or (r["estimate"] or 0) > 0]
    ratios = np.array([r["ratio"] for r in friction], float)
    cost = np.array([r["cost_ratio"] for r in done if r["friction"] > 0], float)

    def share(mask: Any) -> float:
        return float(np.mean(mask)) if np.size(mask) else math.nan

    return {"cells": len(rows), "compared": len(done),
            "not_compared": [f"{r['angle_deg']:g}deg/{r['rpm']:g}rpm/f{r['friction']:g}/"
                             f"{'errors/' if r['errors'] else ''}{r['drive']}: {r.get('status')}"
                             for r in rows if "true_error" not in r],
            "within_target": share([r["within_target"] for r in done]),
            "within_target_of_all": share([r.get("within_target", False) for r in rows]),
            "met_when_within": share([r["met"] == r["within_target"] for r in done]),
            "estimate_within_3x": share((ratios <= 3.0) & (ratios >= 1.0 / 3.0)),
            "true_within_3x_estimate": share(ratios <= 3.0),
            "ratio_median": float(np.median(ratios)) if ratios.size else math.nan,
            "ratio_max": float(np.max(ratios)) if ratios.size else math.nan,
            "cost_ratio_median": float(np.median(cost)) if cost.size else math.nan,
            "cost_ratio_max": float(np.max(cost)) if cost.size else math.nan}


def fit_constants(rows: Sequence[dict[str, Any]]) -> dict[str, float]:
    """Envelopes of ``true_error / (r h)`` over the first-order cells (``lagged``; ``r`` the loss
    fraction) and ``true_error / ((1 - eta) h^2)`` over the
    second-order ones: the values ``EFFICIENCY_FIRST_ORDER`` and ``EFFICIENCY_SECOND_ORDER`` need
    (the first ignores the second-order part, the second includes ``K``: both bound from above)."""
    out = {"first_order": 0.0, "first_order_errors": 0.0, "second_order": 0.0}
    for r in rows:
        if "true_error" not in r or not r.get("loss_fraction") or not r.get("steps_per_revolution"):
            continue
        h = 2.0 * math.pi / r["steps_per_revolution"]
        if r["order"] == 1:
            key = "first_order_errors" if r["errors"] else "first_order"
            out[key] = max(out[key], r["true_error"] / (r["loss_fraction"] * h))
        else:
            out["second_order"] = max(out["second_order"], r["true_error"] / (r["loss_fraction"] * h * h))
    return out
