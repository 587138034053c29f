"""The fit of ``cardan calibrate``: a parameter set's open values identified from its ``fit_cases``,
the other paper cases held out. ``physical``: bounded least squares (trust-region reflective) in
the plausible box, once per discrete combination, smallest RMS kept; ``matched``: levers and
eccentricity within :data:`~cardan_exudyn.studies.calibrate.fitting.MATCHED_BOUNDS` (log scale).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from cardan_exudyn.studies.calibrate.fitting import CaseModel, Space, cases_named, set_space
from reference.paper import case_key, paper_cases, parameter_set
from reference.paper.cases import in_fit

__all__ = ["FIT_SETS", "XTOL", "residuals", "fit", "choices_label", "case_rows", "fit_statistics",
           "calibrate"]

FIT_SETS = ("physical", "matched")
"""The parameter sets with values to fit."""
XTOL = 1e-8
"""``least_squares`` step tolerance in the unit box: 1e-8 of a parameter's range."""


def residuals(model: CaseModel, cases: Sequence[Mapping[str, Any]], values: Mapping[str, Any]) -> np.ndarray:
    """Model minus paper mean efficiency [-] per case of ``cases`` under ``values``; a failed
    (self-locking) case counts as efficiency 0.
    """
    etas = [model.efficiency(c, values) for c in cases]
    return np.asarray([(e if math.isfinite(e) else 0.0) - c["paper_mean_efficiency"]
                       for e, c in zip(etas, cases, strict=True)])


def fit(model: CaseModel, space: Space, combinations: Sequence[Mapping[str, Any]],
        start: Sequence[float], cases: Sequence[Mapping[str, Any]],
        progress: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Bounded least-squares fit of ``space``'s numbers to ``cases``, once per discrete combination.

    Parameters
    ----------
    model : CaseModel
    space : Space
    combinations : sequence of mapping
        The discrete choices, one fit each.
    start : sequence of float
        The start in the unit box.
    cases : sequence of mapping
        The paper cases fitted to.
    progress : callable, optional
        Called with a line of text per combination.

    Returns
    -------
    list of dict
        Best first: ``choices``, ``values``, ``rms`` [-], ``evaluations``, ``status``.
    """
    from scipy.optimize import least_squares  # import cost: scipy for the fit only

    out = []
    for choices in combinations:
        count = 0

        def fun(u: np.ndarray, choices: Mapping[str, Any] = choices) -> np.ndarray:
            """The residuals at ``u`` (unit box) under the combination's ``choices``, counted."""
            nonlocal count
            count += 1
            return residuals(model, cases, {**choices, **space.values(u)})

        # diff_step: 1e-6 of a range; the reference's quadrature (1e-9 of the input work) keeps
        # the difference quotient's error near 1e-3 of the derivative
        solution = least_squares(fun, np.asarray(start, dtype=float), bounds=(0.0, 1.0), method="trf",
                                 diff_step=1e-6, xtol=XTOL, ftol=1e-12, gtol=1e-12, max_nfev=200)
        values = {**choices, **space.values(solution.x)}
        rms = float(np.sqrt(np.mean(np.square(solution.fun))))
        out.append({"choices": dict(choices), "values": values, "rms": rms, "evaluations": count,
                    "status": solution.message})
        if progress:
            progress(f"{choices_label(choices)}: fit RMS {rms:.5f} after {count} evaluations")
    return sorted(out, key=lambda r: r["rms"])


def choices_label(choices: Mapping[str, Any]) -> str:
    """A combination of discrete choices as ``name = option, ...`` (``held choices`` for none)."""
    return ", ".join(f"{k} = {v}" for k, v in choices.items()) or "held choices"


def case_rows(model: CaseModel, values: Mapping[str, Any], fit_keys: Sequence[str]) -> list[dict[str, Any]]:
    """Every paper case under ``values``.

    Parameters
    ----------
    model : CaseModel
    values : mapping
        Parameter values (numbers and choices).
    fit_keys : sequence of str
        The cases fitted to (:func:`reference.paper.cases.case_key`).

    Returns
    -------
    list of dict
        ``case``, ``used_in_fit``, ``paper`` and ``model`` mean efficiency [-], ``difference`` [-],
        ``status``, ``reason``.
    """
    rows = []
    for case in paper_cases():
        eta, status, reason = model.run_case(case, values)
        rows.append({"case": case_key(case), "used_in_fit": in_fit(case, fit_keys),
                     "paper": case["paper_mean_efficiency"], "model": eta,
                     "difference": eta - case["paper_mean_efficiency"], "status": status,
                     "reason": reason})
    return rows


def fit_statistics(rows: Sequence[Mapping[str, Any]]) -> dict[str, float]:
    """RMS and largest magnitude of the difference [-], fit cases and held-out cases apart."""
    out = {}
    for group, used in (("fit", True), ("held_out", False)):
        d = np.asarray([r["difference"] for r in rows if r["used_in_fit"] == used], dtype=float)
        out[f"{group}_rms"] = float(np.sqrt(np.nanmean(np.square(d)))) if d.size else float("nan")
        out[f"{group}_max_abs"] = float(np.nanmax(np.abs(d))) if d.size else float("nan")
    return out


def calibrate(name: str = "physical", engine: str = "reference",
              progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Refit set ``name``'s fitted values on its fit cases with ``engine``; returns ``set``, ``engine``,
    ``fit_cases``, ``parameters`` [m], ``values``, ``combinations`` (:func:`fit`), ``rows``
    (:func:`case_rows`), :func:`fit_statistics`, ``runs``, ``method``, ``wall_time_s`` [s].
    """
    if not isinstance(name, str) or name not in FIT_SETS:
        raise ValueError(f"`name` must be one of {list(FIT_SETS)}, got {name!r:.80}")
    start_time = time.perf_counter()
    model = CaseModel(engine, progress)
    space, combinations, start = set_space(name)
    start_text = [round(float(x), 6) for x in start]
    fit_keys = parameter_set(name)["fit_cases"]
    combos = fit(model, space, combinations, start, cases_named(fit_keys), progress)
    best = combos[0]["values"]
    rows = case_rows(model, best, fit_keys)
    return {"set": name, "engine": engine, "fit_cases": list(fit_keys),
            "parameters": {k: best[k] for k in space.names}, "values": best,
            "combinations": combos, "rows": rows, **fit_statistics(rows), "runs": model.runs,
            "method": ("scipy.optimize.least_squares (trf, bounded), unit-box variables "
                       f"({'log' if any(space.log) else 'linear'} scale), start {start_text}, "
                       f"xtol {XTOL:g}; every combination of discrete choices"),
            "wall_time_s": time.perf_counter() - start_time}

