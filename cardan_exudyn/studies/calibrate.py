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

import argparse
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput
from cardan_exudyn.engines import run
from cardan_exudyn.io import dumps
from cardan_exudyn.report.format import markdown_table, number
from reference.paper import CALIBRATION_PARAMETERS, paper_cases, paper_scene
from reference.scene import replace
from reference.schema import Status

DEFAULT_FIT = ("table2:0:2000", "table2:10:2000", "table2:20:2000", "table2:30:2000",
               "speed:10:1000")
DEFAULT_PARAMETERS = ("spider_lever", "frame_lever", "input_eccentricity")
CASE_COLUMNS = ["case", "used in fit", "paper", "model", "difference"]
CASE_FORMATS = {"paper": ".3f", "model": ".4f", "difference": "+.4f"}


def case_key(case: Mapping[str, Any]) -> str:
    """``study:angle:rpm``, the name of one of :func:`reference.paper.paper_cases`."""
    return f"{case['study']}:{case['shaft_angle_deg']:g}:{case['speed_rpm']:g}"


def in_fit(case: Mapping[str, Any], fit: Sequence[str]) -> bool:
    """Whether ``case`` is one of the fit cases or the same scene (angle and speed) as one:
    the speed study's 10 deg, 2000 rpm case is Table 2's 10 deg case."""
    scene = (case["shaft_angle_deg"], case["speed_rpm"])
    return any((float(k.split(":")[1]), float(k.split(":")[2])) == scene for k in fit)


def efficiency(case: Mapping[str, Any], values: Mapping[str, float], accuracy: float,
               revolutions: float) -> float:
    """Mean efficiency [-] of ``case`` with the parameter ``values``; NaN when the run failed."""
    return run_case(case, values, accuracy, revolutions)[0]


def run_case(case: Mapping[str, Any], values: Mapping[str, float], accuracy: float,
             revolutions: float) -> tuple[float, Status, str]:
    """Mean efficiency [-] (NaN when the run failed), status and reason of ``case`` run by Exudyn.

    Parameters
    ----------
    case : mapping
        One of :func:`reference.paper.paper_cases`.
    values : mapping
        Calibration parameter -> value (units of :data:`reference.paper.CALIBRATION_PARAMETERS`).
    accuracy : float
        ``numerics.accuracy`` of the run [-].
    revolutions : float
        Input revolutions to simulate [-].
    """
    scene = paper_scene(case["shaft_angle_deg"], case["speed_rpm"], parameters=dict(values))
    scene = replace(scene, **{"numerics.accuracy": accuracy, "revolutions": revolutions,
                              "record.timeseries": False})
    result = run(scene, "exudyn")
    if not result.success:
        return float("nan"), result.status, result.message
    return float(result.mean_efficiency), Status.OK, ""


def check_parameters(names: Sequence[str]) -> None:
    """Refuse a parameter :data:`reference.paper.CALIBRATION_PARAMETERS` does not know."""
    unknown = [n for n in names if n not in CALIBRATION_PARAMETERS]
    if unknown:
        raise ValueError(f"unknown parameter(s) {unknown}; choose from {list(CALIBRATION_PARAMETERS)}")


def fit_cases(fit: Sequence[str]) -> list[dict[str, Any]]:
    """The paper's cases named by ``fit`` (:func:`case_key`), in that order."""
    by_key = {case_key(c): c for c in paper_cases()}
    missing = [k for k in fit if k not in by_key]
    if missing:
        raise ValueError(f"unknown fit case(s) {missing}; cases are {list(by_key)}")
    return [by_key[k] for k in fit]


def residuals(cases: Sequence[Mapping[str, Any]], values: Mapping[str, float], accuracy: float,
              revolutions: float) -> np.ndarray:
    """Model minus paper mean efficiency [-] per case; a failed (self-locking) case counts as
    efficiency 0: a large, finite residual."""
    out = []
    for case in cases:
        eta = efficiency(case, values, accuracy, revolutions)
        out.append((eta if math.isfinite(eta) else 0.0) - case["paper_mean_efficiency"])
    return np.asarray(out)


def fit_parameters(names: Sequence[str], cases: Sequence[Mapping[str, Any]], accuracy: float,
                   revolutions: float,
                   progress: Callable[[str], None] | None = None) -> tuple[dict[str, float], int]:
    """Least-squares values of ``names`` (on a log scale, within their physical bounds) for
    ``cases``, and the number of function evaluations."""
    from scipy.optimize import least_squares  # import cost: this module registers a CLI command

    spec = [CALIBRATION_PARAMETERS[n] for n in names]
    lo, hi = np.log([s["bounds"][0] for s in spec]), np.log([s["bounds"][1] for s in spec])
    x0 = np.clip(np.log([s["start"] for s in spec]), lo, hi)
    evaluations = 0

    def values_of(x: np.ndarray) -> dict[str, float]:
        return {n: float(math.exp(v)) for n, v in zip(names, x, strict=True)}

    def fun(x: np.ndarray) -> np.ndarray:
        nonlocal evaluations
        values = values_of(x)
        out = residuals(cases, values, accuracy, revolutions)
        evaluations += 1
        if progress:
            progress(f"evaluation {evaluations}: "
                     + ", ".join(f"{n} = {v:.5g}" for n, v in values.items())
                     + f"; RMS residual {np.sqrt(np.mean(np.square(out))):.5f}")
        return out

    solution = least_squares(fun, x0, bounds=(lo, hi), diff_step=1e-3, xtol=1e-6, ftol=1e-8)
    return values_of(solution.x), evaluations


def case_rows(values: Mapping[str, float], fit: Sequence[str], accuracy: float,
              revolutions: float) -> list[dict[str, Any]]:
    """Every paper case with the fitted ``values``: paper and model mean efficiency [-], their
    difference, whether it was used in the fit, status and reason."""
    rows = []
    for case in paper_cases():
        eta, status, reason = run_case(case, values, accuracy, revolutions)
        rows.append({"case": case_key(case), "used_in_fit": in_fit(case, fit),
                     "paper": case["paper_mean_efficiency"], "model": eta,
                     "difference": eta - case["paper_mean_efficiency"], "status": status.value,
                     "reason": reason})
    return rows


def fit_statistics(rows: Sequence[Mapping[str, Any]]) -> dict[str, float]:
    """RMS difference of the fit cases, RMS and largest magnitude of the held-out ones [-]."""
    held = [r["difference"] for r in rows if not r["used_in_fit"]]
    fitted = [r["difference"] for r in rows if r["used_in_fit"]]
    return {"fit_rms": float(np.sqrt(np.nanmean(np.square(fitted)))),
            "held_out_rms": float(np.sqrt(np.nanmean(np.square(held)))) if held else float("nan"),
            "held_out_max_abs": float(np.nanmax(np.abs(held))) if held else float("nan")}


def calibrate(names: Sequence[str] = DEFAULT_PARAMETERS, fit: Sequence[str] = DEFAULT_FIT,
              accuracy: float = 1e-4, revolutions: float = 1.0,
              progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Least-squares fit of ``names`` to the ``fit`` cases; the held-out errors of the others.

    Parameters
    ----------
    names : sequence of str
        Keys of :data:`reference.paper.CALIBRATION_PARAMETERS`.
    fit : sequence of str
        Paper cases to fit (:func:`case_key`).
    accuracy : float
        ``numerics.accuracy`` of every run [-].
    revolutions : float
        Input revolutions per run [-].
    progress : callable, optional
        Called with one line of text after every function evaluation.

    Returns
    -------
    dict
        ``parameters`` (name -> fitted value, units of the parameter), ``fit_cases``, ``rows``
        (:func:`case_rows`), the statistics of :func:`fit_statistics`,
        ``function_evaluations``, ``accuracy``, ``revolutions`` and ``wall_time_s`` [s].
    """
    check_parameters(names)
    cases = fit_cases(fit)
    start = time.perf_counter()
    values, evaluations = fit_parameters(names, cases, accuracy, revolutions, progress)
    rows = case_rows(values, fit, accuracy, revolutions)
    return {"parameters": values, "fit_cases": list(fit), "rows": rows, **fit_statistics(rows),
            "function_evaluations": evaluations, "accuracy": accuracy, "revolutions": revolutions,
            "wall_time_s": time.perf_counter() - start}


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan calibrate`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("calibrate",
                              help="fit the paper's open parameters to a subset of its results")
    p.add_argument("--parameters", metavar="A,B",
                   help="parameters to fit (default spider_lever,frame_lever,input_eccentricity)")
    p.add_argument("--json", action="store_true", help="print the fit as JSON on stdout")
    p.set_defaults(func=handler)


def parameter_names(text: str | None) -> tuple[str, ...]:
    """The parameters of ``--parameters A,B`` (the default set when not given)."""
    if text is None:
        return DEFAULT_PARAMETERS
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise BadInput(f"--parameters names no parameter, got {text!r}; choose from "
                       f"{list(CALIBRATION_PARAMETERS)}")
    unknown = [n for n in names if n not in CALIBRATION_PARAMETERS]
    if unknown:
        raise BadInput(f"--parameters: unknown {unknown}; choose from {list(CALIBRATION_PARAMETERS)}")
    return tuple(names)


def handler(args: argparse.Namespace) -> int:
    """``cardan calibrate``: exit 0 when every case ran to status ok, 3 otherwise."""
    result = calibrate(parameter_names(args.parameters), progress=_say)
    failed = [r for r in result["rows"] if r.get("status", Status.OK) != Status.OK]
    if args.json:
        print(dumps(result))
        return EXIT_FAILED if failed else EXIT_OK
    print_fit(result)
    for r in failed:
        print(f"status: {r['case']}: {r['status']}: {r['reason']}", file=sys.stderr)
    return EXIT_FAILED if failed else EXIT_OK


def _say(message: str) -> None:
    print(f"  {message}", file=sys.stderr, flush=True)


def print_fit(result: Mapping[str, Any]) -> None:
    """The fitted values, the table of every case and the fit statistics, on stdout."""
    print("fitted parameters (paste into reference/data/paper.toml [calibrated.parameters]):")
    for n, v in result["parameters"].items():
        print(f"  {n} = {v:.6g} {CALIBRATION_PARAMETERS[n]['unit']}")
    rows = []
    for r in result["rows"]:
        ok = r.get("status", Status.OK) == Status.OK  # a failed run has no efficiency: its status
        rows.append({"case": r["case"], "used in fit": "yes" if r["used_in_fit"] else "no",
                     "paper": r["paper"], "model": r["model"] if ok else r["status"],
                     "difference": r["difference"]})
    print("\n" + markdown_table(rows, CASE_COLUMNS, CASE_FORMATS), end="")
    print(f"\nfit RMS {number(result['fit_rms'], '.4f')}; "
          f"held-out RMS {number(result['held_out_rms'], '.4f')}, "
          f"max |difference| {number(result['held_out_max_abs'], '.4f')}; "
          f"{result['function_evaluations']} evaluations, {number(result['wall_time_s'], '.0f')} s")
