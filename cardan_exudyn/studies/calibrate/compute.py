"""``cardan calibrate``: identify a parameter set's open values from a subset of the paper's own
results, and (``--envelope``) bound what the plausible box can give for each of the paper's
numbers (:mod:`cardan_exudyn.studies.calibrate.envelope`).

``--set physical`` (default) fits the physical set's ``fitted`` values (arm radius, support
spacing, input eccentricity, spider centre-of-mass offset) inside the plausible box
(``[plausible]`` of ``reference/paper/data/paper.toml``) to the set's ``fit_cases`` by bounded least
squares (``scipy.optimize.least_squares``, trust-region reflective), once for every combination
of the box's discrete options (gravity, reading of the 2 N m), and keeps the combination with
the smallest RMS. ``--set matched`` refits the matched set's levers and eccentricity within wide
bounds (:data:`cardan_exudyn.studies.calibrate.fitting.MATCHED_BOUNDS`, log scale), its choices held. The
other cases are held out: their errors are reported next to the fitted ones.
``tests/test_calibration.py`` (slow) re-runs both and checks the stored values.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, BadInput, out_folder
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.studies.calibrate.envelope import envelope_study, envelope_text
from cardan_exudyn.studies.calibrate.fitting import (
    FIT_ENGINES,
    CaseModel,
    Space,
    cases_named,
    set_space,
)
from reference.paper.cases import case_key, in_fit, paper_cases
from reference.paper.parameter_sets import parameter_set

FIT_SETS = ("physical", "matched")
CASE_COLUMNS = ["case", "used in fit", "paper", "model", "difference"]
CASE_FORMATS = {"paper": ".3f", "model": ".4f", "difference": "+.4f"}
XTOL = 1e-8
"""``least_squares`` step tolerance in the unit box: 1e-8 of a parameter's range."""

__all__ = ["FIT_SETS", "calibrate", "fit", "fit_statistics", "register"]


def residuals(model: CaseModel, cases: Sequence[Mapping[str, Any]], values: Mapping[str, Any]) -> np.ndarray:
    """Model minus paper mean efficiency [-] per case; a failed (self-locking) case counts as
    efficiency 0: a large, finite residual."""
    etas = [model.efficiency(c, values) for c in cases]
    return np.asarray([(e if math.isfinite(e) else 0.0) - c["paper_mean_efficiency"]
                       for e, c in zip(etas, cases, strict=True)])


def fit(model: CaseModel, space: Space, combinations: Sequence[Mapping[str, Any]],
        start: Sequence[float], cases: Sequence[Mapping[str, Any]],
        progress: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Bounded least-squares fit of ``space``'s numbers to ``cases``, once per combination of
    discrete choices, from ``start`` (unit box).

    Returns
    -------
    list of dict
        Per combination, best first: ``choices``, ``values`` (every parameter), ``rms`` [-]
        (RMS residual on ``cases``), ``evaluations``, ``status`` (the optimiser's message).
    """
    from scipy.optimize import least_squares  # import cost: this module registers a CLI command

    out = []
    for choices in combinations:
        count = 0

        def fun(u: np.ndarray, choices: Mapping[str, Any] = choices) -> np.ndarray:
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
            progress(f"{_label(choices)}: fit RMS {rms:.5f} after {count} evaluations")
    return sorted(out, key=lambda r: r["rms"])


def _label(choices: Mapping[str, Any]) -> str:
    return ", ".join(f"{k} = {v}" for k, v in choices.items()) or "held choices"


def case_rows(model: CaseModel, values: Mapping[str, Any], fit_keys: Sequence[str]) -> list[dict[str, Any]]:
    """Every paper case under ``values``: paper and model mean efficiency [-], their difference,
    whether it was used in the fit (:func:`in_fit`), status and reason."""
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
    """Refit parameter set ``name``'s fitted values on its fit cases; the errors on all eleven.

    Parameters
    ----------
    name : {"physical", "matched"}
        The set (``[sets.<name>]`` of the data file).
    engine : {"reference", "exudyn"}
        Engine of every run.
    progress : callable, optional
        Called with a line of text as the fit proceeds.

    Returns
    -------
    dict
        ``set``, ``engine``, ``fit_cases``, ``parameters`` (fitted name -> value [m]),
        ``values`` (every value of the set), ``combinations`` (:func:`fit`, best first),
        ``rows`` (:func:`case_rows`), the statistics of :func:`fit_statistics`, ``runs``,
        ``method`` and ``wall_time_s`` [s].
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


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cardan calibrate`` to the ``cardan`` subcommands."""
    p = subparsers.add_parser("calibrate", help="fit a parameter set to a subset of the paper's results, "
                                                "or bound the paper's numbers over the plausible box")
    p.add_argument("--set", dest="parameter_set", default="physical", metavar="NAME",
                   help=f"parameter set to refit: {', '.join(FIT_SETS)} (default physical)")
    p.add_argument("--engine", default="reference", metavar="NAME",
                   help=f"engine of every run: {', '.join(FIT_ENGINES)} (default reference)")
    p.add_argument("--envelope", action="store_true",
                   help="instead of a fit: the lowest and highest value of each of the paper's "
                        "numbers over the plausible box")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    p.add_argument("--out", metavar="DIR", help="write the result (JSON) and the report (markdown) here")
    p.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    """``cardan calibrate``: exit 0 when every case ran to status ok, 3 otherwise."""
    if args.parameter_set not in FIT_SETS:
        hint = " (the literal set has nothing fitted)" if args.parameter_set == "literal" else ""
        raise BadInput(f"--set must be one of {list(FIT_SETS)}, got {args.parameter_set!r}{hint}")
    if args.engine not in FIT_ENGINES:
        raise BadInput(f"--engine must be one of {list(FIT_ENGINES)}, got {args.engine!r}")
    out_folder(args.out)
    if args.envelope:
        result = envelope_study(args.engine, progress=_say)
        text, failed = envelope_text(result), result["failed_runs"]
    else:
        result = calibrate(args.parameter_set, args.engine, progress=_say)
        text = fit_text(result)
        failed = [r for r in result["rows"] if r.get("status", "ok") != "ok"]
        for r in failed:
            print(f"status: {r['case']}: {r['status']}: {r['reason']}", file=sys.stderr)
    if args.out:
        with atomic_directory(args.out) as tmp:
            (tmp / ("envelope.json" if args.envelope else "calibrate.json")).write_text(dumps(result))
            (tmp / "report.md").write_text(text)
        _say(f"wrote {args.out}")
    print(dumps(result) if args.json else text, end="" if not args.json else "\n")
    return EXIT_FAILED if failed else EXIT_OK


def _say(message: str) -> None:
    print(f"  {message}", file=sys.stderr, flush=True)


def _toml_value(v: Any) -> str:
    return f'"{v}"' if isinstance(v, str) else f"{v:.6g}"


def fit_text(result: Mapping[str, Any]) -> str:
    """The report of :func:`calibrate`: what to paste into the data file, every combination's
    RMS, the table of the eleven cases and the statistics."""
    stored = parameter_set(result["set"])["values"]
    lines = [f"parameter set {result['set']}, engine {result['engine']}; fit cases "
             f"{', '.join(result['fit_cases'])}", f"method: {result['method']}", "",
             f"paste into reference/paper/data/paper.toml [sets.{result['set']}.values] (reasons as stored):"]
    for k, v in result["values"].items():
        entry = dict(stored.get(k, {}), value=v)
        lines.append(f"{k} = {{ " + ", ".join(f"{f} = {_toml_value(x) if f == 'value' else _toml_raw(x)}"
                                             for f, x in entry.items()) + " }")
    lines += ["", "every combination of discrete choices (best first):"]
    for c in result["combinations"]:
        numbers = ", ".join(f"{k} = {c['values'][k]:.6g}" for k in result["parameters"])
        lines.append(f"  {_label(c['choices'])}: fit RMS {c['rms']:.5f} ({numbers}; "
                     f"{c['evaluations']} evaluations)")
    rows = [{"case": r["case"], "used in fit": "yes" if r["used_in_fit"] else "no", "paper": r["paper"],
             "model": r["model"] if r.get("status", "ok") == "ok" else r["status"],
             "difference": r["difference"]} for r in result["rows"]]
    lines += ["", markdown_table(rows, CASE_COLUMNS, CASE_FORMATS).rstrip("\n"), ""]
    lines.append(f"fitted: RMS {number(result['fit_rms'], '.4f')}, largest "
                 f"{number(result['fit_max_abs'], '.4f')}; held out: RMS "
                 f"{number(result['held_out_rms'], '.4f')}, "
                 f"largest {number(result['held_out_max_abs'], '.4f')}")
    lines.append(f"{result.get('runs', '-')} engine runs, {number(result['wall_time_s'], '.0f')} s")
    return "\n".join(lines) + "\n"


def _toml_raw(x: Any) -> str:
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, str):
        return '"' + x.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return _toml_value(x)
