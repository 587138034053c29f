"""The paper's tolerance case (sections 4.2 and 5): the rig scene (15 deg, 6 rad/s, f = 0.42,
0.2 N m) without and with ``a_i = 0.5 mm`` and twist errors of 6e-3 deg; the paper reports an
efficiency change of about 0.15 %. Computed per engine, parameter set, friction law and coupling
(``converged``, or ``uncoupled``: eqs. (3), (5) on the frictionless reactions).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from cardan_exudyn.engines import run
from reference.paper import PARAMETER_SETS, paper_errors, rig_scene, value
from reference.results.summary import Status, Summary
from reference.scene import FRICTION_LAWS, replace
from reference.scene.joint import PAIR_NAMES

__all__ = ["CYLINDRICAL", "COUPLINGS", "LAWS", "MATCH_FACTOR", "case_numbers", "paper_row",
           "paper_case", "law_verdicts", "sign_envelope", "paper_study"]

CYLINDRICAL = PAIR_NAMES[1:]
"""The cylindrical pairs, the ones that slide with mounting errors."""
COUPLINGS = ("converged", "uncoupled")
"""Friction fed back into the dynamics, or eqs. (3), (5) evaluated on the frictionless reactions."""
LAWS = FRICTION_LAWS
MATCH_FACTOR = 2.0
"""A change matches the paper's "about 0.15 %" within this factor of its magnitude: one rounded
number for a sign combination the paper does not state (the signs alone move it more)."""


def _value(x: float | None) -> float:
    return float("nan") if x is None else float(x)


def case_numbers(summary: Summary) -> dict[str, float]:
    """Mean efficiency and per-pair loss and sliding-loss shares of the input work [-] (NaN where missing)."""
    w_in = _value(summary.input_work)
    out = {"mean_efficiency": _value(summary.mean_efficiency)}
    for pair in PAIR_NAMES:
        out[f"loss_{pair}"] = _value(summary.pair_loss_work.get(pair)) / w_in
        out[f"sliding_{pair}"] = _value(summary.pair_sliding_loss_work.get(pair, 0.0)) / w_in
    return out


def paper_row(parameters: str, coupling: str, engine: str, law: str = "paper") -> dict[str, Any]:
    """The rig case of set ``parameters``, ``law`` and ``coupling`` run by ``engine`` without and with
    the stated errors: statuses, efficiencies, their change, per-pair loss changes [-].
    """
    ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling, "friction.law": law})
    with_errors = replace(ideal, **paper_errors())
    r0 = run(ideal, engine).summary
    r1 = run(with_errors, engine).summary
    row: dict[str, Any] = {"parameters": parameters, "law": law, "coupling": coupling, "engine": engine,
                           "status_ideal": r0.status.value, "status_errors": r1.status.value,
                           "reason": r1.reason if not r1.success else ""}
    a = case_numbers(r0)
    b = case_numbers(r1)
    row["eta_ideal"] = a["mean_efficiency"]
    row["eta_errors"] = b["mean_efficiency"]
    row["change"] = b["mean_efficiency"] - a["mean_efficiency"]
    row["relative_change"] = row["change"] / a["mean_efficiency"]
    row["sliding_share"] = sum(b[f"sliding_{p}"] for p in CYLINDRICAL)
    for pair in PAIR_NAMES:
        row[f"d_loss_{pair}"] = b[f"loss_{pair}"] - a[f"loss_{pair}"]
    return row


def paper_case(engines: Sequence[str] = ("reference", "exudyn"),
               parameter_sets: Sequence[str] = PARAMETER_SETS,
               couplings: Sequence[str] = COUPLINGS,
               progress: Callable[[dict[str, Any]], None] | None = None,
               laws: Sequence[str] = LAWS):
    """The rig case with and without the stated errors, per engine, parameter set, law and coupling.

    Parameters
    ----------
    engines, parameter_sets, couplings, laws : sequence of str
        Keys of :data:`cardan_exudyn.engines.ENGINES`, sets of :func:`reference.paper.scenes.rig_scene`,
        ``friction.coupling`` and ``friction.law`` values.
    progress : callable, optional
        Called with each row as it is computed.

    Returns
    -------
    pandas.DataFrame
        One row per (parameters, law, coupling, engine), all [-]: statuses, ``eta_ideal``,
        ``eta_errors``, ``change``, ``relative_change``, ``sliding_share`` and per pair
        ``d_loss_<pair>`` (that pair's loss change over the input work).
    """
    import pandas as pd  # import cost: pandas for this study only

    rows = []
    for parameters, law, coupling, engine in itertools.product(parameter_sets, laws, couplings, engines):
        rows.append(paper_row(parameters, coupling, engine, law))
        if progress:
            progress(rows[-1])
    return pd.DataFrame(rows)


def law_verdicts(rows, paper: float) -> list[dict[str, Any]]:
    """Per parameter set and engine of :func:`paper_case` ``rows``: ``cells`` (``"<law>/<coupling>"``
    -> relative change [-] or failed status), ``closest`` to ``paper`` in magnitude ratio (None when
    nothing ran ok), ``matches`` (within :data:`MATCH_FACTOR`).
    """
    out = []
    for (parameters, engine), group in rows.groupby(["parameters", "engine"], sort=False):
        cells = {}
        for r in group.itertuples():  # a failed run: its status
            bad = r.status_errors if r.status_ideal == Status.OK else r.status_ideal
            cells[f"{r.law}/{r.coupling}"] = float(r.relative_change) if bad == Status.OK else str(bad)
        ratio = {k: abs(v) / paper for k, v in cells.items() if isinstance(v, float) and v != 0.0}
        best = min(ratio, key=lambda k: abs(math.log(ratio[k])), default=None)  # None: nothing ran ok
        out.append({"parameters": parameters, "engine": engine, "cells": cells, "closest": best,
                    "matches": None if best is None else 1.0 / MATCH_FACTOR <= ratio[best] <= MATCH_FACTOR})
    return out


def sign_envelope(parameters: str = "matched", coupling: str = "converged",
                  engine: str = "reference") -> dict[str, Any]:
    """Range of the efficiency change [-] over the 64 sign combinations of the stated errors (the paper
    gives magnitudes): the arguments, ``combinations``, ``ok``, ``eta_ideal``, ``change_min``,
    ``change_max`` (NaN when none ran ok).
    """
    ideal = replace(rig_scene(parameters=parameters), **{"friction.coupling": coupling})
    eta0 = _value(run(ideal, engine).mean_efficiency)
    base = paper_errors()
    changes = []
    for signs in itertools.product((1.0, -1.0), repeat=len(base)):
        errors = {k: s * v for (k, v), s in zip(base.items(), signs, strict=True)}
        changes.append(_value(run(replace(ideal, **errors), engine).mean_efficiency) - eta0)
    changes = np.array(changes)
    ok = np.isfinite(changes)
    return {"parameters": parameters, "coupling": coupling, "engine": engine,
            "combinations": len(changes), "ok": int(ok.sum()), "eta_ideal": eta0,
            "change_min": float(changes[ok].min()) if ok.any() else float("nan"),
            "change_max": float(changes[ok].max()) if ok.any() else float("nan")}


def paper_study(engines: Sequence[str] = ("reference", "exudyn"),
                progress: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """``cardan tolerance paper``'s numbers with ``engines``: ``paper_change`` [-], ``rows``
    (:func:`paper_case` over everything), ``sign_envelope`` and ``verdicts`` (:func:`law_verdicts`).
    """
    rows = paper_case(engines, progress=progress)
    envelope = [sign_envelope(p, c) for p in PARAMETER_SETS for c in COUPLINGS]
    paper = value("case.rig.tolerance_effect")
    return {"paper_change": paper, "rows": rows, "sign_envelope": envelope,
            "verdicts": law_verdicts(rows, paper)}
