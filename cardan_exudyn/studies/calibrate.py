"""``cardan calibrate``: identify the paper's open parameters from a subset of its own results.

The paper leaves several values open (see the assumption register). This module fits the
fewest physically interpretable ones to a subset of the paper's eleven mean efficiencies
(default: 0, 10, 20, 30 deg at 2000 rpm and 10 deg at 1000 rpm) by least squares
(``scipy.optimize.least_squares``, parameters on a log scale within physical bounds), then
reports the error on the cases not used in the fit. The values it prints are what
``reference/data/paper.toml`` stores under ``[calibrated]``; ``tests/test_calibration.py``
(slow) re-runs the fit and checks that they still agree.

The parameters (each applied by :func:`reference.paper.apply_parameters`):

- ``spider_lever`` [m]: moment lever of eq. (1) in the two spider pairs. Literal reading: the
  trunnion bearing length L = 6 mm. A lumped pair stands for two trunnion bearings on opposite
  arms, which carry a bending moment as a couple with the lever *between the bearings*,
  2 x arm radius.
- ``frame_lever`` [m]: the same for the two shaft-frame pairs. Literal: L = 10 mm. Physical: the
  spacing of the two support bearings of a shaft.
- ``input_eccentricity`` [m]: distance of the input shaft's centre of mass from its axis.
  Table 1 under the register's reading: 8.6 mm (a 352 N rotating load at 2000 rpm). The paper
  mentions the eccentricity; its size is what makes the 0 deg loss.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any

import numpy as np

from cardan_exudyn.model.solve import run
from reference.paper import CALIBRATION_PARAMETERS, paper_cases, paper_scene
from reference.scene import replace

DEFAULT_FIT = ("table2:0:2000", "table2:10:2000", "table2:20:2000", "table2:30:2000",
               "speed:10:1000")
DEFAULT_PARAMETERS = ("spider_lever", "frame_lever", "input_eccentricity")


def _key(case: dict) -> str:
    return f"{case['study']}:{case['shaft_angle_deg']:g}:{case['speed_rpm']:g}"


def in_fit(case: dict, fit: tuple[str, ...] | list[str]) -> bool:
    """Whether ``case`` is one of the fit cases or the same scene (angle and speed) as one:
    the speed study's 10 deg, 2000 rpm case is Table 2's 10 deg case."""
    scene = (case["shaft_angle_deg"], case["speed_rpm"])
    return any((float(k.split(":")[1]), float(k.split(":")[2])) == scene for k in fit)


def efficiency(case: dict, values: dict[str, float], accuracy: float, revolutions: float) -> float:
    """Mean efficiency of ``case`` with the parameter ``values``; NaN when the run failed."""
    return run_case(case, values, accuracy, revolutions)[0]


def run_case(case: dict, values: dict[str, float], accuracy: float,
             revolutions: float) -> tuple[float, str, str]:
    """Mean efficiency (NaN when the run failed), status and reason of ``case``."""
    scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"], parameters=values)
    scene = replace(scene, **{"numerics.accuracy": accuracy, "revolutions": revolutions,
                              "record.timeseries": False})
    result = run(scene)
    s = result.summary
    if not result.ok:
        return float("nan"), str(s.get("status")), str(s.get("reason", ""))
    return float(s["mean_efficiency"]), "ok", ""


def calibrate(names: tuple[str, ...] = DEFAULT_PARAMETERS, fit: tuple[str, ...] = DEFAULT_FIT,
              accuracy: float = 1e-4, revolutions: float = 1.0,
              progress=None) -> dict[str, Any]:
    """Least-squares fit of ``names`` to the ``fit`` cases; the held-out errors of the others."""
    from scipy.optimize import least_squares

    unknown = [n for n in names if n not in CALIBRATION_PARAMETERS]
    if unknown:
        raise ValueError(f"unknown parameter(s) {unknown}; choose from {list(CALIBRATION_PARAMETERS)}")
    cases = paper_cases()
    by_key = {_key(c): c for c in cases}
    missing = [k for k in fit if k not in by_key]
    if missing:
        raise ValueError(f"unknown fit case(s) {missing}; cases are {list(by_key)}")
    spec = [CALIBRATION_PARAMETERS[n] for n in names]
    lo = np.log([s["bounds"][0] for s in spec])
    hi = np.log([s["bounds"][1] for s in spec])
    x0 = np.log([s["start"] for s in spec])
    evaluations = {"n": 0}
    start = time.perf_counter()

    def values_of(x: np.ndarray) -> dict[str, float]:
        return {n: float(math.exp(v)) for n, v in zip(names, x, strict=True)}

    def residuals(x: np.ndarray) -> np.ndarray:
        values = values_of(x)
        out = []
        for k in fit:
            eta = efficiency(by_key[k], values, accuracy, revolutions)
            # a failed (self-locking) case counts as efficiency 0: a large, finite residual
            out.append((eta if math.isfinite(eta) else 0.0) - by_key[k]["paper_mean_efficiency"])
        evaluations["n"] += 1
        if progress:
            progress(f"evaluation {evaluations['n']}: "
                     + ", ".join(f"{n} = {v:.5g}" for n, v in values.items())
                     + f"; RMS residual {np.sqrt(np.mean(np.square(out))):.5f}")
        return np.asarray(out)

    solution = least_squares(residuals, np.clip(x0, lo, hi), bounds=(lo, hi), diff_step=1e-3,
                             xtol=1e-6, ftol=1e-8)
    values = values_of(solution.x)
    rows = []
    for case in cases:
        eta, status, reason = run_case(case, values, accuracy, revolutions)
        rows.append({"case": _key(case), "used_in_fit": in_fit(case, fit),
                     "paper": case["paper_mean_efficiency"], "model": eta,
                     "difference": eta - case["paper_mean_efficiency"], "status": status,
                     "reason": reason})
    held = [r["difference"] for r in rows if not r["used_in_fit"]]
    fitted = [r["difference"] for r in rows if r["used_in_fit"]]
    return {
        "parameters": values,
        "fit_cases": list(fit),
        "rows": rows,
        "fit_rms": float(np.sqrt(np.nanmean(np.square(fitted)))),
        "held_out_rms": float(np.sqrt(np.nanmean(np.square(held)))) if held else float("nan"),
        "held_out_max_abs": float(np.nanmax(np.abs(held))) if held else float("nan"),
        "function_evaluations": evaluations["n"],
        "accuracy": accuracy,
        "revolutions": revolutions,
        "wall_time_s": time.perf_counter() - start,
    }


def _fmt(value: float, spec: str) -> str:
    return format(value, spec) if math.isfinite(value) else "-"


def main_calibrate(names: list[str] | None, as_json: bool) -> int:
    from cardan_exudyn.io import dumps

    def progress(msg: str) -> None:
        print(f"  {msg}", file=sys.stderr, flush=True)

    result = calibrate(tuple(names) if names else DEFAULT_PARAMETERS, progress=progress)
    failed = [r for r in result["rows"] if r.get("status", "ok") != "ok"]
    if as_json:
        print(dumps(result))
        return 3 if failed else 0
    print("fitted parameters (paste into reference/data/paper.toml [calibrated.parameters]):")
    for n, v in result["parameters"].items():
        print(f"  {n} = {v:.6g} {CALIBRATION_PARAMETERS[n]['unit']}")
    print("\n| case | used in fit | paper | model | difference |\n|---|---|---|---|---|")
    for r in result["rows"]:
        ok = r.get("status", "ok") == "ok"  # a failed run has no efficiency: its status instead
        print(f"| {r['case']} | {'yes' if r['used_in_fit'] else 'no'} | {r['paper']:.3f} | "
              f"{_fmt(r['model'], '.4f') if ok else r['status']} | {_fmt(r['difference'], '+.4f')} |")
    print(f"\nfit RMS {_fmt(result['fit_rms'], '.4f')}; held-out RMS {_fmt(result['held_out_rms'], '.4f')}, "
          f"max |difference| {_fmt(result['held_out_max_abs'], '.4f')}; "
          f"{result['function_evaluations']} evaluations, {result['wall_time_s']:.0f} s")
    for r in failed:
        print(f"status: {r['case']}: {r['status']}: {r['reason']}", file=sys.stderr)
    return 3 if failed else 0
