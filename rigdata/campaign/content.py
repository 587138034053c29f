"""What a campaign report says, built from ``results.json`` alone (:meth:`CampaignResult.as_dict`) as a
:mod:`rigdata.campaign.document`: verdicts, calibration, comparison, budget, engines, failures, environment.
Uncertainties show two significant digits and the values beside them as many decimals.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from cardan_exudyn.report.format import is_number, number
from rigdata.campaign.document import (
    BANNER,
    CALIBRATION,
    FAILED,
    NOT_RESOLVABLE,
    RESOLVABLE,
    WARNING,
    Block,
    Image,
    Items,
    Section,
    Table,
    Text,
)

__all__ = ["MAX_DECIMALS", "HOW_TO_READ", "uncertainty", "value", "verdict", "document"]

MAX_DECIMALS = 10
"""Most decimals a value is shown with, however small the uncertainty beside it."""


def uncertainty(u: Any) -> str:
    """``u`` to two significant digits (``0.0023``, ``6.3e-12``, ``0``); ``-`` if not a finite number."""
    return "0" if is_number(u) and u == 0 else number(u, "#.2g").rstrip(".")


def _decimals(u: Any) -> int | None:
    """Decimals that show ``u`` [any unit] to two significant digits (None for no positive ``u``)."""
    if not is_number(u) or u <= 0:
        return None
    rounded = float(format(u, ".2g"))
    return min(max(1 - math.floor(math.log10(rounded)), 0), MAX_DECIMALS)


def value(x: Any, u: Any, fallback: str = ".4f") -> str:
    """``x`` with the decimals of ``u`` shown to two significant digits (``fallback`` without ``u``)."""
    d = _decimals(u)
    return number(x, f".{d}f" if d is not None else fallback)


def verdict(rec: Mapping[str, Any]) -> tuple[str, str]:
    """A recording's verdict and its tone: a calibration recording never gets a validation verdict."""
    if rec["status"] != "ok":
        return f"no comparison ({rec['status']})", FAILED
    if rec["use"] == "calibration":
        return "calibration (not a validation)", CALIBRATION
    if rec["resolvable"]:
        return "resolvable model error", RESOLVABLE
    return "not resolvable", NOT_RESOLVABLE


def _level(data: Mapping[str, Any]) -> str:
    """The chi-square test's level in per cent (``5`` for 95 % coverage)."""
    return number(100 * (1 - data["campaign"]["coverage"]), ".3g")


def _labels(recs: Sequence[Mapping[str, Any]]) -> str:
    """Recording labels in a line, ``none`` for none."""
    return ", ".join(f"`{r['label']}`" for r in recs) or "none"


def _synthetic(data: Mapping[str, Any]) -> list[Block]:
    """The SYNTHETIC banner when any recording's provenance says so."""
    recs = [r for r in data["recordings"] if (r.get("provenance") or {}).get("synthetic")]
    if not recs:
        return []
    generators = sorted({str(r["provenance"]["synthetic"].get("generator")) for r in recs})
    return [Text(f"**SYNTHETIC DATA** - {len(recs)} of {len(data['recordings'])} recordings were generated "
                 f"by {', '.join(generators)}, not measured: {_labels(recs)}. Their generator settings "
                 "(true friction, true efficiency) are in the provenance of results.json.", BANNER)]


def _summary(data: Mapping[str, Any]) -> list[Block]:
    """The campaign's verdict in a few lines."""
    valid = [r for r in data["recordings"] if r["use"] == "validation"]
    compared = [r for r in valid if r["status"] == "ok"]
    resolvable = [r for r in compared if r["resolvable"]]
    failed = [r for r in data["recordings"] if r["status"] != "ok"]
    lines = [f"**{len(resolvable)} of {len(compared)} validation recordings compared show a resolvable model "
             f"error** (|E| > k u_val): {_labels(resolvable)}.",
             f"Not resolvable at this level of data: {_labels([r for r in compared if not r['resolvable']])}"
             ".",
             f"Recordings without a comparison: {_labels(failed)}."]
    cal = data.get("calibration")
    if cal and cal.get("rejected"):
        lines.append(f"The calibration recordings reject the model at the {_level(data)} % level "
                     "(see Calibration).")
    return [Items(tuple(lines))]


def _facts(data: Mapping[str, Any]) -> list[Block]:
    """Campaign file, scene, engines, coverage and k, recordings, stated inputs."""
    c = data["campaign"]
    recs = data["recordings"]
    engines = ", ".join(c["engines"])
    inputs = "; ".join(f"`{i['key']}` ({i['distribution']}, std {uncertainty(i['std'])})"
                       for i in c["inputs"]) or "none"
    n_cal = sum(r["use"] == "calibration" for r in recs)
    return [Items((f"Campaign file: `{c['file'] or '(in memory)'}`", f"Scene: `{c['scene']}`",
                   f"Engines: {engines} (the first, {c['engines'][0]}, calibrates and carries the budget)",
                   f"Coverage {number(100 * c['coverage'], 'g')} %, k = {number(c['k'], '.3f')}",
                   f"Recordings: {len(recs)} ({n_cal} calibration, {len(recs) - n_cal} validation)",
                   f"Measured efficiency: GUM, checked by {c['monte_carlo']} Monte Carlo draws (seed "
                   f"{c['seed']})", f"Stated input uncertainties: {inputs}"))]


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]], numeric: Sequence[bool],
           tones: Mapping[tuple[int, int], str] | None = None) -> Table:
    """A :class:`Table` of already formatted rows."""
    return Table(tuple(headers), tuple(tuple(r) for r in rows), tuple(numeric), dict(tones or {}))


def _interval(rec: Mapping[str, Any]) -> str:
    """``[low, high]`` of ``E ± k u_val`` with the decimals of u_val."""
    interval = rec.get("model_error_interval")
    if not interval:
        return "-"
    u = rec["u_val"]
    return f"[{value(interval[0], u)}, {value(interval[1], u)}]"


def _comparison_row(rec: Mapping[str, Any]) -> list[str]:
    """One recording in the comparison table."""
    op = rec.get("operating_point") or {}
    u = rec.get("u_val")
    return [rec["label"], rec["use"], number(rec["shaft_angle_deg"], "g"),
            number(op.get("speed_in_rpm"), ".1f"), number(op.get("torque_in"), ".3g"),
            value(rec["simulated"], u), value(rec["measured"], u),
            value(rec["comparison_error"], u), uncertainty(rec["u_num"]), uncertainty(rec["u_input"]),
            uncertainty(rec["u_D"]), uncertainty(u), _interval(rec), verdict(rec)[0]]


def _comparison(data: Mapping[str, Any]) -> Section:
    """The per-recording table and the efficiency and model-error figures."""
    recs = data["recordings"]
    headers = ("recording", "use", "shaft angle [deg]", "input speed [rpm]", "input torque [N m]", "S", "D",
               "E", "u_num", "u_input", "u_D", "u_val", "E ± k u_val", "verdict")
    numeric = (False, False, *([True] * 11), False)
    tones = {(i, 13): verdict(r)[1] for i, r in enumerate(recs)}
    engine = data["campaign"]["engines"][0]
    return Section("Comparison per recording", (
        Text(f"S: simulated ({engine}), D: measured, mean efficiency over whole revolutions [-]; E = S - D; "
             f"the uncertainties are standard (k = 1); the interval is E ± k u_val with k = "
             f"{number(data['campaign']['k'], '.3f')}."),
        _table(headers, [_comparison_row(r) for r in recs], numeric, tones),
        Image("efficiency", "Measured D (±k u_D) and simulated S of each engine (the first with ±k u_input) "
                            "per recording; calibration recordings shaded."),
        Image("model_error", "E = S - D with ±k u_val: red where the model error is resolvable, blue where "
                             "not, grey for calibration recordings (not a validation).")))


def _budget_row(rec: Mapping[str, Any], sampled: bool) -> list[str]:
    """One recording in the budget table."""
    b = rec.get("budget") or {}
    row = [rec["label"], rec["use"], *(uncertainty(b.get(k)) for k in ("u_parameters", "u_inputs", "u_load",
                                                                       "u_phase", "u_input"))]
    if sampled:
        row.append(uncertainty(b.get("u_input_sampled")))
    return [*row, uncertainty(rec["u_num"]), uncertainty(rec["u_D"]), uncertainty(b.get("covariance_SD")),
            uncertainty(rec["u_val"]), rec.get("dominant") or "-"]


def _budget(data: Mapping[str, Any]) -> Section:
    """The budget table and figure."""
    recs = data["recordings"]
    sampled = any((r.get("budget") or {}).get("u_input_sampled") is not None for r in recs)
    headers = ["recording", "use", "u_parameters", "u_inputs", "u_load", "u_phase", "u_input",
               *(["u_input sampled"] if sampled else []), "u_num", "u_D", "cov(S, D)", "u_val", "dominant"]
    numeric = [False, False, *([True] * (len(headers) - 3)), False]
    return Section("Uncertainty budget", (
        Text("u_input is the root sum of squares of u_parameters (calibrated parameters, their "
             "covariance), u_inputs (stated input uncertainties), u_load (the measured load driving the "
             "model) and u_phase (the yoke phase's half-turn ambiguity). cov(S, D) [-^2] is the shared "
             "output transducer's; dominant is the largest of u_num, u_input and u_D."),
        _table(headers, [_budget_row(r, sampled) for r in recs], numeric),
        Image("budget", "Standard uncertainties per recording on a log axis: u_num, the parts of u_input, "
                        "u_D; dashed: u_input, black: u_val.")))


def _engine_cells(rec: Mapping[str, Any], engine: str, first: str, k: float) -> list[str]:
    """One engine's S and u_num, and after the first its difference from the first and agreement."""
    comp = (rec.get("by_engine") or {}).get(engine) or {}
    if comp.get("status") != "ok":
        cells = [str(comp.get("status") or "-"), "-"]
        return cells if engine == first else [*cells, "-", "-"]
    cells = [value(comp["simulated"], rec.get("u_val")), uncertainty(comp["u_num"])]
    if engine == first:
        return cells
    u_first = ((rec.get("by_engine") or {}).get(first) or {}).get("u_num")
    diff = comp.get("difference_from_first")
    if not is_number(diff) or not is_number(u_first):
        return [*cells, "-", "-"]
    u = math.hypot(u_first, comp["u_num"])
    return [*cells, value(diff, u, ".2g"), "yes" if abs(diff) <= k * u else "no"]


def _engines(data: Mapping[str, Any]) -> Section:
    """Each engine's S beside its u_num, and its difference from the first engine."""
    engines = data["campaign"]["engines"]
    first = engines[0]
    k = data["campaign"]["k"]
    headers = ["recording"]
    for engine in engines:
        headers += [f"S ({engine})", f"u_num ({engine})"]
        if engine != first:
            headers += [f"S ({engine}) - S ({first})", "within k u_num"]
    rows = [[r["label"], *(c for e in engines for c in _engine_cells(r, e, first, k))]
            for r in data["recordings"]]
    return Section("Engines", (
        Text(f"Each engine's simulated efficiency S at the same parameter values, its numerical "
             f"uncertainty u_num and its difference from the first engine ({first}); \"within k u_num\": "
             "the difference is at most k times the root sum of squares of the two engines' u_num."),
        _table(headers, rows, [h not in ("recording", "within k u_num") for h in headers])))


def _estimate_row(p: Mapping[str, Any]) -> list[str]:
    """One parameter in the calibration table."""
    u = p.get("standard_uncertainty")
    shown = value(p["value"], u, ".6g")
    if p.get("calibrated") and not p.get("identifiable"):
        u_text = "not identified"
    else:
        u_text = uncertainty(u)
    at_bound = {True: "yes", False: "no"}.get(p.get("at_bound"), "-")
    identifiable = {True: "yes", False: "no"}.get(p.get("identifiable"), "-")
    bounds = f"[{number(p['bounds'][0], 'g')}, {number(p['bounds'][1], 'g')}]"
    return [p["name"], shown, u_text, identifiable, at_bound, bounds, ", ".join(p["keys"])]


def _parameters_table(data: Mapping[str, Any]) -> Table:
    """The parameters' values, uncertainties, identifiability and bounds."""
    headers = ("parameter", "value", "standard uncertainty", "identifiable", "at bound", "bounds",
               "scene keys")
    return _table(headers, [_estimate_row(p) for p in data["parameters"]],
                  (False, True, True, False, False, True, False))


def _correlation(data: Mapping[str, Any]) -> list[Block]:
    """The parameters' correlation matrix (two or more parameters)."""
    names = [p["name"] for p in data["parameters"]]
    corr = data.get("correlation")
    if not corr or len(names) < 2:
        return []
    rows = [[name, *(number(c, ".2f") for c in row)] for name, row in zip(names, corr, strict=True)]
    return [Text("Correlation of the parameters (the covariance propagated into u_parameters):"),
            _table(["", *names], rows, [False, *([True] * len(names))])]


def _combinations(cal: Mapping[str, Any], data: Mapping[str, Any]) -> list[Block]:
    """The combinations the data determine when some parameter is not identifiable."""
    if not cal.get("combinations"):
        return []
    unidentified = [p["name"] for p in data["parameters"] if not p.get("identifiable")]
    lines = []
    for c in cal["combinations"]:
        terms = " + ".join(f"{number(v, '.3g')} {name}" for name, v in c["coefficients"].items())
        terms = re.sub(r"(^|\+ )1 ", r"\1", terms).replace("+ -", "- ")
        u = c["standard_uncertainty"]
        lines.append(f"{terms} = {value(c['value'], u, '.6g')} ± {uncertainty(u)}")
    return [Text(f"The calibration recordings do not identify {', '.join(unidentified)}; they determine "
                 "these combinations (standard uncertainty), and the bounds bound the rest:"),
            Items(tuple(lines))]


def _chi_square(cal: Mapping[str, Any], data: Mapping[str, Any]) -> Text:
    """The chi-square test of the fit, in plain words."""
    level = _level(data)
    p = cal.get("p_value")
    head = (f"Chi-square test of the fit: chi-square = {number(cal['chi_square'], '.3g')} with "
            f"{cal['dof']} degree{'' if cal['dof'] == 1 else 's'} of freedom, p = {number(p, '.2g')}. ")
    if cal.get("rejected") is None:
        return Text(head + "No degrees of freedom are left (as many identified directions as calibration "
                           "recordings): the fit cannot be tested.", WARNING)
    if cal["rejected"]:
        return Text(head + f"**The calibration recordings reject the model at the {level} % level: a "
                           "model-form error, not absorbed into the parameters' uncertainty.**", WARNING)
    return Text(head + f"The calibration recordings do not reject the model at the {level} % level: the "
                       "residuals are consistent with their stated uncertainties.")


def _fit_text(cal: Mapping[str, Any], data: Mapping[str, Any]) -> Text:
    """What was fitted to what, how, and what the uncertainties mean."""
    labels = {r["index"]: r for r in data["recordings"]}
    used = [labels[i] for i in cal["recordings"] if i in labels]
    message = str(cal["message"]).rstrip(".")
    return Text(f"Weighted least squares of S - D over {len(used)} calibration recordings ({_labels(used)}) "
                f"on the {data['campaign']['engines'][0]} engine, each residual scaled by its u_val at fixed "
                f"parameters; {cal['evaluations']} evaluations ({message}). The standard uncertainties come "
                "from the data alone, never scaled by the fit's chi-square.")


def _calibration(data: Mapping[str, Any]) -> Section:
    """The calibrated parameters, their correlation, combinations and the fit's test; or why none."""
    cal = data.get("calibration")
    if not data["parameters"]:
        return Section("Calibration", (Text("No calibration was made: the campaign has no [parameters]; "
                                            "every model run used the scene's own values."),))
    if not cal:
        return Section("Calibration", (
            Text(f"**The calibration failed:** {data.get('calibration_error') or 'no reason given'}. Every "
                 "validation run used the parameters' initial values:", WARNING),
            _parameters_table(data)))
    return Section("Calibration", (
        _fit_text(cal, data), _parameters_table(data), *_correlation(data), *_combinations(cal, data),
        _chi_square(cal, data),
        Image("residuals", "Calibration residuals (S - D) / sigma at the estimate with ±1 and ±k.")))


def _failures(data: Mapping[str, Any]) -> list[Section]:
    """Recordings without a comparison, with their reasons, and checks that did not pass."""
    failed = [f"`{r['label']}` ({r['status']}): {r['reason']}" for r in data["recordings"]
              if r["status"] != "ok"]
    checks = [f"`{r['label']}`: check {f['check']} {f['status']}: {f['message']}" for r in data["recordings"]
              for f in r.get("checks", []) if f.get("status") != "ok"]
    blocks: list[Block] = [Items(tuple(failed)) if failed else Text("None: every recording was compared.")]
    if checks:
        blocks += [Text("Checks that did not pass:"), Items(tuple(checks))]
    return [Section("Failed recordings", tuple(blocks))]


HOW_TO_READ = (
    "The campaign follows ASME V&V 20. For each recording, E = S - D (simulated minus measured "
    "efficiency) estimates the model error δ_model.",
    "Its validation uncertainty is u_val² = u_num² + u_input² + u_D² - 2 cov(S, D): the numerics, "
    "the model's uncertain inputs (calibrated parameters included), the measurement, less what the "
    "simulation and the measurement share (the output transducer drives both).",
    "The interval E ± k u_val contains δ_model with the stated coverage.",
    "|E| > k u_val: a **resolvable model error** - the interval excludes zero: the data resolve the "
    "model's error, about E. "
    "|E| ≤ k u_val: **not resolvable** - the model error is not resolvable at this level of data; "
    "this is no proof that the model is right, only that the data cannot tell.",
    "Calibration recordings fitted the parameters: their E is no validation and gets no verdict; the "
    "chi-square test of the fit says whether they can be fitted at all.")


def _environment(data: Mapping[str, Any]) -> Section:
    """Versions, machine, commit, date and the stages' wall times."""
    env = data.get("environment") or {}
    timing = data.get("timing") or {}
    engines = ", ".join(f"{e} ({d.get('package')} {d.get('version')})"
                        for e, d in (env.get("engines") or {}).items())
    packages = ", ".join(f"{p} {v}" for p, v in (env.get("packages") or {}).items() if v is not None)
    stages = ", ".join(f"{k} {number(v, '.1f')} s" for k, v in timing.items() if not k.startswith("model_"))
    return Section("Environment and timing", (Items((
        f"Engines: {engines or '-'}", f"Python {env.get('python', '-')}; {packages or '-'}",
        f"Machine: {env.get('cpu', '-')} ({env.get('cpu_count', '-')} cores), {env.get('platform', '-')}",
        f"Commit {env.get('commit') or 'unknown'}; {env.get('date', '-')}",
        f"Wall time: {stages or '-'}; model runs made: {timing.get('model_runs', '-')}, requests answered "
        f"by a run already made (journal or this campaign): {timing.get('model_runs_reused', '-')}")),))


def document(data: Mapping[str, Any]) -> tuple[str, list[Section]]:
    """The report's title and sections from ``results.json`` (:meth:`CampaignResult.as_dict`)."""
    c = data["campaign"]
    name = c.get("title") or (Path(c["file"]).name if c.get("file") else "campaign")
    head = Section("", (*_synthetic(data), *_facts(data)))
    return f"Validation campaign: {name}", [
        head, Section("Verdict", tuple(_summary(data))), Section("How to read this", (Items(HOW_TO_READ),)),
        _calibration(data), _comparison(data), _budget(data), _engines(data), *_failures(data),
        _environment(data)]
