"""The reports of ``cardan calibrate`` (fit and envelope) and its ``--out`` folder."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table, number
from cardan_exudyn.studies.calibrate.fit import choices_label
from reference.paper import parameter_set

__all__ = ["CASE_COLUMNS", "CASE_FORMATS", "ENVELOPE_COLUMNS", "ENVELOPE_FORMATS", "fit_text",
           "envelope_text", "write_result"]

CASE_COLUMNS = ["case", "used in fit", "paper", "model", "difference"]
CASE_FORMATS = {"paper": ".3f", "model": ".4f", "difference": "+.4f"}
ENVELOPE_COLUMNS = ["case", "paper", "lowest", "highest", "reachable", "closest", "limited by"]
ENVELOPE_FORMATS = {"paper": ".3f", "lowest": ".4f", "highest": ".4f", "closest": ".4f"}


def write_result(out: str | Path, name: str, result: Mapping[str, Any], text: str) -> Path:
    """Folder ``out``, replaced atomically: ``result`` as JSON file ``name``, ``text`` as ``report.md``."""
    with atomic_directory(out) as tmp:
        (tmp / name).write_text(dumps(result))
        (tmp / "report.md").write_text(text)
    return Path(out)


def fit_text(result: Mapping[str, Any]) -> str:
    """The report of :func:`~cardan_exudyn.studies.calibrate.fit.calibrate`'s ``result``: what to paste
    into the data file, every combination's RMS, the eleven cases, the statistics.
    """
    stored = parameter_set(result["set"])["values"]
    lines = [f"parameter set {result['set']}, engine {result['engine']}; fit cases "
             f"{', '.join(result['fit_cases'])}", f"method: {result['method']}", "",
             f"paste into reference/paper/data/paper.toml [sets.{result['set']}.values] (reasons as stored):"]
    for k, v in result["values"].items():
        entry = dict(stored.get(k, {}), value=v)
        lines.append(f"{k} = {{ " + ", ".join(f"{f} = {_toml(x) if f == 'value' else _toml_raw(x)}"
                                             for f, x in entry.items()) + " }")
    lines += ["", "every combination of discrete choices (best first):"]
    for c in result["combinations"]:
        numbers = ", ".join(f"{k} = {c['values'][k]:.6g}" for k in result["parameters"])
        lines.append(f"  {choices_label(c['choices'])}: fit RMS {c['rms']:.5f} ({numbers}; "
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
    """A stored field (flag, text or number) as a TOML value."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, str):
        return '"' + x.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return _toml(x)


def envelope_text(result: Mapping[str, Any]) -> str:
    """The report of :func:`~cardan_exudyn.studies.calibrate.envelope.envelope_study`'s ``result``: the
    table, what to paste into ``[envelope]``, what would have to change for each number outside.
    """
    rows = [{**r, "reachable": "yes" if r["reachable"] else "no",
             "limited by": "; ".join(map(_limit, r.get("limiting", []))) + _choices(r)}
            for r in result["cases"]]
    lines = [f"engine {result['engine']}; method: {result['method']}", "",
             markdown_table(rows, ENVELOPE_COLUMNS, ENVELOPE_FORMATS).rstrip(),
             "", "paste into reference/paper/data/paper.toml:", "[envelope]",
             'command = "cardan calibrate --envelope"', f'method = "{result["method"]}"']
    for r in result["cases"]:
        lines.append(f'[envelope.cases."{r["case"]}"]')
        lines.append(f"lowest = {r['lowest']:.6f}")
        lines.append(f"highest = {r['highest']:.6f}")
        for key in ("lowest_at", "highest_at"):
            lines.append(f"{key} = {{ " + ", ".join(f"{n} = {_toml(v)}" for n, v in r[key].items()) + " }")
    lines.append(f"\n{result['corners']} corners, {result['runs']} engine runs, "
                 f"{result['wall_time_s']:.0f} s")
    return "\n".join(lines) + "\n"


def _limit(x: Mapping[str, Any]) -> str:
    """A parameter that limits the envelope, with its slope outwards [1/m]."""
    if x["bound"] == "lower" and x["value"] == 0.0:  # a distance: zero is a physical limit
        return f"{x['name']} at zero (a distance, cannot go lower)"
    return (f"{x['name']} at its {x['bound']} bound ({x['value']:.4g}; d eta/d x outwards "
            f"{x['slope_outwards']:+.3g} /m)")


def _choices(row: Mapping[str, Any]) -> str:
    """`` [name = option, ...]``: the discrete choices at the bound nearest the paper's number of a
    case outside the envelope; empty otherwise.
    """
    if row.get("reachable", True) or "limiting" not in row:
        return ""
    at = row["lowest_at"] if row["paper"] < row["lowest"] else row["highest_at"]
    picked = {k: v for k, v in at.items() if isinstance(v, str)}
    return (" [" + ", ".join(f"{k} = {v}" for k, v in picked.items()) + "]") if picked else ""


def _toml(v: Any) -> str:
    """A text or a number as a TOML value (numbers to six significant digits)."""
    return f'"{v}"' if isinstance(v, str) else f"{v:.6g}"

