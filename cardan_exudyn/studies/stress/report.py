"""The report folder of ``cardan stress`` (``report.md``, ``map_cells.csv``, ``stability_map.png``,
``stress.json``), written atomically with the map's sweeps moved in.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report import plots
from cardan_exudyn.report.environment import environment
from cardan_exudyn.report.format import markdown_table
from cardan_exudyn.studies.stress.classify import CLASSES, as_float
from cardan_exudyn.studies.stress.map import StressMap
from cardan_exudyn.studies.stress.panels import DEFAULT_RPM, DEFAULT_STEPS, PANEL_FRICTION, X_LABELS, Panel
from reference.results.summary import Status

__all__ = ["SYMBOLS", "TESTS", "problems", "summary", "write_stress", "class_mark", "error_mark",
           "panel_table", "map_markdown", "plot_map"]

TESTS = ("The map's classification, cells either side of the self-locking boundary and this "
         "command are tested by `pytest tests/test_stress.py` (a source checkout).")


def problems(stress: StressMap) -> list[str]:
    """What makes the command exit 3: map cells that raised in the harness."""
    n = int((stress.cells["cell_class"] == "error").sum())
    return [f"{n} map cells raised in the harness"] if n else []


def summary(stress: StressMap, wall_s: float) -> dict[str, Any]:
    """``stress.json`` without the environment: ``wall_s`` (``{"map": wall_s}``), ``problems`` and
    ``map`` (:meth:`StressMap.counts`, scene, ``quick``, sweeps).
    """
    return {"wall_s": {"map": wall_s}, "problems": problems(stress),
            "map": {**stress.counts(), "scene": stress.scene, "quick": stress.quick,
                    "sweeps": stress.sweeps}}


def write_stress(stress: StressMap, out: str | os.PathLike, wall_s: float) -> Path:
    """``stress``'s folder ``out`` (replaced atomically; ``wall_s`` [s]), with ``out/runs`` moved in."""
    out = Path(out)
    env = environment()
    found = problems(stress)
    sections = [f"# Stress report{' (--quick)' if stress.quick else ''}", "",
                f"{env['date']}, commit `{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical "
                f"CPUs), exudyn {env['packages'].get('exudyn')}; wall time map {wall_s:.1f} s.", "",
                ("**Problems:** " + "; ".join(found)) if found
                else "No problems: no map cell raised in the harness.", "", TESTS, "",
                map_markdown(stress), "![stability map](stability_map.png)", ""]
    with atomic_directory(out) as folder:
        stress.cells.to_csv(folder / "map_cells.csv", index=False)
        plots.save(plot_map(stress), folder / "stability_map.png")
        (folder / "report.md").write_text("\n".join(sections), encoding="utf-8")
        (folder / "stress.json").write_text(dumps({**summary(stress, wall_s), "environment": env})
                                            + "\n", encoding="utf-8")
        if (out / "runs").exists():
            os.replace(out / "runs", folder / "runs")
    return out


SYMBOLS = {"converged": "C", "drift": "D", "self_locking": "L", "integration_failure": "F",
           "error": "E"}


def class_mark(r: pd.Series) -> str:
    """Class letter, ``*`` where the reference self-locks, ``!`` where the engines disagree."""
    return (SYMBOLS[r["cell_class"]] + ("*" if r["reference"] == Status.SELF_LOCKING else "")
            + ("!" if not r["agrees"] else ""))


def error_mark(r: pd.Series) -> str:
    """Efficiency error against the reference (promise in brackets), else :func:`class_mark`."""
    err = as_float(r["efficiency_error"])
    promise = as_float(r["efficiency_promise"])
    if not math.isfinite(err):
        return class_mark(r)
    return f"{err:.1e}" + (f" ({promise:.0e})" if math.isfinite(promise) else "")


def panel_table(cells: pd.DataFrame, panel: Panel, mark: Callable[[pd.Series], str] = class_mark) -> str:
    """Markdown grid of ``panel`` over ``cells``, a cell's text ``mark(row)`` (default :func:`class_mark`)."""
    sel = cells[cells["panel"] == panel.key]
    columns = ["angle", *(f"{x:g}" for x in panel.x_values)]
    rows = []
    for angle in panel.angles:
        row = sel[sel["angle_deg"] == angle].set_index("x")
        rows.append({"angle": f"{angle:g} deg",
                     **{f"{x:g}": mark(row.loc[x]) for x in panel.x_values}})
    headers = ["angle \\ " + X_LABELS[panel.x], *columns[1:]]
    return markdown_table(rows, columns, headers=headers).rstrip("\n")


def _map_intro(counts: dict[str, Any], scene: str) -> list[str]:
    """The map section's head: what a cell is, the legend, the counts."""
    return [
        "## Stability map",
        "",
        f"{counts['cells']} cells, each one revolution of `{scene}` at constant "
        f"input speed from the assembled start; reference engine (72 samples per revolution, "
        f"quadrature rtol 1e-8) and Exudyn (default options) at the cell's step and at half of it. "
        f"Unless a panel varies it: {DEFAULT_RPM:g} rpm, {DEFAULT_STEPS} steps per revolution, "
        f"friction coefficient {PANEL_FRICTION:g} in all four pairs.",
        "",
        "Legend: **C** converged (within the step's promise), **D** drift (status ok, answer "
        "outside the promise), **L** Exudyn reports self-locking, **F** integration failure, "
        "**E** harness error; `*` the reference's friction fixed point has no solution (physical "
        "self-locking); `!` Exudyn and the reference disagree.",
        "",
        "Classes: " + ", ".join(f"{k} {v}" for k, v in counts["classes"].items())
        + f"; reference self-locking in {counts['reference_self_locking']} cells; "
        f"{counts['disagreements']} disagreements.",
        "",
    ]


def _disagreements(cells: pd.DataFrame) -> list[str]:
    """The table of every cell where Exudyn and the reference disagree (none: nothing)."""
    bad = cells[~cells["agrees"]].copy()
    if not len(bad):
        return []
    bad["x_label"] = [f"{n}={x:g}" for n, x in zip(bad["x_name"], bad["x"], strict=True)]
    table = markdown_table(bad, ["panel", "angle_deg", "x_label", "cell_class", "reference", "category",
                                 "explanation"], formats={"angle_deg": "g"},
                           headers=["panel", "angle [deg]", "x", "Exudyn", "reference", "category",
                                    "explanation"])
    return ["", "### Every disagreement", "", table.rstrip("\n")]


def map_markdown(stress: StressMap) -> str:
    """The map's report section: legend, one grid per panel, every disagreement listed."""
    counts = stress.counts()
    parts = _map_intro(counts, stress.scene)
    for panel in stress.panels:
        parts += [f"### {panel.key}: shaft angle x {X_LABELS[panel.x]} ({panel.title})", "",
                  panel_table(stress.cells, panel), ""]
        if panel.x in ("rpm", "steps"):
            parts += ["Mean-efficiency error against the reference (promised error in brackets; "
                      "the class where there is no efficiency):", "",
                      panel_table(stress.cells, panel, error_mark), ""]
    categories = [{"category": k, "cells": v} for k, v in counts["categories"].items()]
    parts += ["### Agreement with the reference's self-locking boundary", "",
              markdown_table(categories, ["category", "cells"]).rstrip("\n")]
    parts += _disagreements(stress.cells)
    parts += ["", "Why each category happens: `docs/stress.md`.", ""]
    return "\n".join(parts)


def plot_map(stress: StressMap) -> Any:
    """One image per panel: colour = class, hatched = reference self-locks, ``!`` = disagreement, black
    line = the reference's self-locking boundary.
    """
    return plots.stability_map(stress.cells, [
        {"key": p.key, "title": p.title, "x": p.x, "x_label": X_LABELS[p.x],
         "x_values": p.x_values, "angles": p.angles} for p in stress.panels], CLASSES)
