"""``cardan calibrate --envelope``: the lowest and highest mean efficiency the model gives for each
paper case over the plausible box. Method: every corner under every discrete combination, then a
bounded L-BFGS-B from the best corner per case and direction; a local search, so a stored
``lowest`` may be too high and ``highest`` too low.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from cardan_exudyn.studies.calibrate.fitting import CaseModel, Space, box_space
from reference.paper.cases import case_key, paper_cases

METHOD = ("every combination of the discrete options; the continuous box by its 2^n corners, then "
          "a bounded local optimisation (scipy.optimize.minimize, L-BFGS-B, forward-difference "
          "gradient, step 1e-6 of each range) from the best corner per case and direction; a local "
          "search that can miss an extreme inside the box")
BOUND_TOL = 1e-6
"""A parameter within this share of its range from a bound is at the bound."""

__all__ = ["METHOD", "BOUND_TOL", "corner_scan", "refine", "at_bounds", "envelope_study", "case_envelope"]


def corner_scan(model: CaseModel, space: Space, combinations: list[dict[str, str]],
                cases: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every corner of ``space`` under every discrete combination, for ``cases``: per point ``u``,
    ``choices`` and ``eta`` (each case's mean efficiency [-], NaN where the run failed).
    """
    points = []
    for choices in combinations:
        for u in space.corners():
            values = {**choices, **space.values(u)}
            points.append({"u": u, "choices": choices,
                           "eta": np.asarray([model.efficiency(c, values) for c in cases])})
    return points


def refine(model: CaseModel, space: Space, case: Mapping[str, Any], point: Mapping[str, Any],
           sign: float) -> tuple[float, np.ndarray]:
    """``(eta, u)``: bounded local optimisation of ``sign * eta`` of ``case`` from corner ``point``
    (``sign`` 1: lowest, -1: highest).
    """
    from scipy.optimize import minimize  # import cost: this module is behind a CLI command

    choices = point["choices"]

    def objective(u: np.ndarray) -> float:
        """``sign * eta`` at ``u``; a locked run is worse than any efficiency."""
        eta = model.efficiency(case, {**choices, **space.values(u)})
        return sign * eta if np.isfinite(eta) else 10.0  # a locked run: worse than any efficiency

    solution = minimize(objective, np.asarray(point["u"], dtype=float), method="L-BFGS-B",
                        bounds=[(0.0, 1.0)] * len(space.names),
                        options={"eps": 1e-6, "maxiter": 30, "ftol": 1e-12, "gtol": 1e-9})
    best_corner = sign * objective(np.asarray(point["u"], dtype=float))
    eta = sign * float(solution.fun)
    if sign * eta > sign * best_corner:  # never worse than the corner it started from
        return best_corner, np.asarray(point["u"], dtype=float)
    return eta, np.clip(solution.x, 0.0, 1.0)


def at_bounds(model: CaseModel, space: Space, case: Mapping[str, Any], u: np.ndarray,
              choices: Mapping[str, str]) -> list[dict[str, Any]]:
    """The parameters at a bound of the box at ``u`` (with ``choices``): ``name``, ``bound``,
    ``value`` [m] and ``slope_outwards`` [1/m] of ``case``'s efficiency (from a step 1e-3 of the
    range inwards).
    """
    base = model.efficiency(case, {**choices, **space.values(u)})
    out = []
    for i, name in enumerate(space.names):
        for bound, edge, inward in (("lower", 0.0, 1.0), ("upper", 1.0, -1.0)):
            if abs(u[i] - edge) > BOUND_TOL:
                continue
            v = u.copy()
            v[i] = edge + inward * 1e-3
            step = (space.upper[i] - space.lower[i]) * 1e-3
            slope = (base - model.efficiency(case, {**choices, **space.values(v)})) / step
            out.append({"name": name, "bound": bound, "value": space.values(u)[name],
                        "slope_outwards": float(slope)})
    return out


def envelope_study(engine: str = "reference", progress: Callable[[str], None] | None = None,
                   space: Space | None = None, combinations: list[dict[str, str]] | None = None,
                   cases: list[dict[str, Any]] | None = None) -> dict[str, Any]:
    """The lowest and highest mean efficiency of each paper case over the plausible box with ``engine``.

    ``space``, ``combinations``, ``cases``: a smaller study (tests). Returns ``method``, ``engine``,
    ``cases`` (per case :func:`case_envelope`), ``corners``, ``runs``, ``failed_runs``,
    ``wall_time_s`` [s].
    """
    start = time.perf_counter()
    model = CaseModel(engine, progress)
    if space is None or combinations is None:
        default_space, default_combinations = box_space()
        space = default_space if space is None else space
        combinations = default_combinations if combinations is None else combinations
    cases = paper_cases() if cases is None else cases
    points = corner_scan(model, space, combinations, cases)
    if progress:
        progress(f"{len(points)} corners x {len(cases)} cases: {model.runs} runs, "
                 f"{time.perf_counter() - start:.0f} s; refining")
    rows = [case_envelope(model, space, points, k, case) for k, case in enumerate(cases)]
    failed = sorted({k for k, (eta, _, _) in model.cache.items() if not np.isfinite(eta)}, key=str)
    return {"method": METHOD, "engine": engine, "cases": rows, "corners": len(points),
            "box": {n: [lo, hi] for n, lo, hi in zip(space.names, space.lower, space.upper, strict=True)},
            "choices": combinations, "runs": model.runs, "failed_runs": [str(f) for f in failed],
            "wall_time_s": time.perf_counter() - start}


def case_envelope(model: CaseModel, space: Space, points: list[dict[str, Any]], k: int,
                  case: Mapping[str, Any]) -> dict[str, Any]:
    """Case ``k``'s envelope from the corner scan ``points``, refined: ``case``, ``paper``, ``lowest``
    and ``highest`` [-] with ``lowest_at``, ``highest_at``, ``reachable``, ``closest`` and, outside
    the envelope, ``limiting`` (:func:`at_bounds`).
    """
    row: dict[str, Any] = {"case": case_key(case), "paper": case["paper_mean_efficiency"]}
    where = {}
    for key, sign in (("lowest", 1.0), ("highest", -1.0)):
        finite = [p for p in points if np.isfinite(p["eta"][k])]
        corner = min(finite, key=lambda p: sign * p["eta"][k])
        eta, u = refine(model, space, case, corner, sign)
        row[key] = eta
        row[f"{key}_at"] = {**corner["choices"], **space.values(u)}
        where[key] = (u, corner["choices"])
    paper = row["paper"]
    row["reachable"] = row["lowest"] <= paper <= row["highest"]
    row["closest"] = min(max(paper, row["lowest"]), row["highest"])
    if not row["reachable"]:
        u, choices = where["lowest" if paper < row["lowest"] else "highest"]
        row["limiting"] = at_bounds(model, space, case, u, choices)
    return row
