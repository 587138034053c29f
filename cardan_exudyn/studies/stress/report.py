"""``cardan stress``'s parts and report folder: the stability map (:mod:`.stress_map`) and the
long runs (:mod:`.longrun`), run and written into one folder.

The library measures and reports; the verdicts on the long runs' measurements (each tolerance with
its reason) are the tests of ``tests/test_longrun.py``, and bad input at every entry point is
``tests/test_hardening.py``. A part that raised in the harness is the command's only problem.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory, check_output_folder
from cardan_exudyn.report import plots
from cardan_exudyn.report.environment import environment
from cardan_exudyn.report.format import markdown_table
from cardan_exudyn.studies.stress.longrun import LongRuns, long_runs
from cardan_exudyn.studies.stress.longrun_report import markdown as long_markdown
from cardan_exudyn.studies.stress.longrun_report import write_long
from cardan_exudyn.studies.stress.map import (
    BASE_SCENE,
    CLASSES,
    DEFAULT_RPM,
    DEFAULT_STEPS,
    PANEL_FRICTION,
    X_LABELS,
    Panel,
    StressMap,
    as_float,
    run_map,
)
from reference.results.summary import Status

PARTS = ("map", "long")
#: Where the parts that left ``cardan stress`` now live.
MOVED_PARTS = {"inputs": "the bad-input table is `pytest tests/test_hardening.py` (a source checkout)"}
SYMBOLS = {"converged": "C", "drift": "D", "self_locking": "L", "integration_failure": "F",
           "error": "E"}
TESTS = ("The verdicts are tests: `pytest tests/test_longrun.py` holds the long runs' measurements to "
         "stated tolerances (`-m slow` for the quick and full variants), `pytest tests/test_hardening.py` "
         "feeds every entry point bad input, `pytest tests/test_stress.py` checks the map's classes.")


class StressError(ValueError):
    """Bad input to the stress command (unknown part)."""


def parse_parts(text: str | None) -> tuple[str, ...]:
    """The parts named by ``--only`` (``None``: all of :data:`PARTS`)."""
    if text is None:
        return PARTS
    parts = tuple(p.strip() for p in text.split(",") if p.strip())
    moved = [f"`{p}`: {MOVED_PARTS[p]}" for p in parts if p in MOVED_PARTS]
    if moved:
        raise StressError(f"--only: no longer a part of cardan stress: {'; '.join(moved)}")
    unknown = sorted(set(parts) - set(PARTS))
    if unknown or not parts:
        raise StressError(f"--only must be a comma-separated subset of {list(PARTS)}, got {text!r}")
    return parts


@dataclass
class StressReport:
    """What ``cardan stress`` ran: the map, the long runs, wall time per part [s]."""

    map: StressMap | None = None
    long: LongRuns | None = None
    wall_s: dict[str, float] = field(default_factory=dict)

    def problems(self) -> list[str]:
        """What makes the command exit 3: map cells or long-run cases that raised in the harness."""
        out = []
        if self.map is not None:
            n = int((self.map.cells["cell_class"] == "error").sum())
            if n:
                out.append(f"{n} map cells raised in the harness")
        if self.long is not None:
            out += [f"long run: {name} raised in the harness ({reason})"
                    for name, reason in self.long.errors()]
        return out

    def summary(self) -> dict[str, Any]:
        """The content of ``stress.json`` (without the environment)."""
        out: dict[str, Any] = {"wall_s": self.wall_s, "problems": self.problems()}
        if self.map is not None:
            out["map"] = {**self.map.counts(), "quick": self.map.quick, "sweeps": self.map.sweeps}
        if self.long is not None:
            out["long"] = self.long.summary
        return out


def run_stress(out: str | os.PathLike, *, quick: bool = False, parts: Sequence[str] = PARTS,
               workers: int | None = None, restart: bool = False, progress: bool | None = None,
               say: Callable[[str], None] | None = None) -> StressReport:
    """Run the chosen parts and write the report folder ``out`` atomically.

    Parameters
    ----------
    out : path
        Report folder; the map's sweeps live in ``out/runs`` and are kept, so a rerun resumes.
    quick : bool
        The coarse map and the quick long runs (CI variant).
    parts : sequence of str
        Subset of :data:`PARTS`.
    workers, restart, progress
        The map's sweeps, as :func:`cardan_exudyn.sweep.run_sweep`.
    say : callable, optional
        Called with a line of text as each part starts and each long run ends.

    Raises
    ------
    cardan_exudyn.outputs.OutputError
        ``out`` cannot be a folder; raised before anything runs.
    """
    say = say or (lambda text: None)
    out = check_output_folder(out)
    runs = out / "runs"
    report = StressReport()
    if "map" in parts:
        start = time.perf_counter()
        say("stability map ...")
        report.map = run_map(runs, quick, workers=workers, restart=restart, progress=progress)
        report.wall_s["map"] = time.perf_counter() - start
    if "long" in parts:
        start = time.perf_counter()
        say("long runs ...")
        report.long = long_runs(quick=quick, progress=say)
        report.wall_s["long"] = time.perf_counter() - start
    with atomic_directory(out) as folder:
        write_report(report, folder, quick)
        if runs.exists():
            os.replace(runs, folder / "runs")
    return report


def write_report(report: StressReport, folder: Path, quick: bool) -> None:
    """``report.md``, ``stress.json`` and each part's files into the existing ``folder``."""
    env = environment()
    walls = ", ".join(f"{k} {v:.1f} s" for k, v in report.wall_s.items())
    sections = [f"# Stress report{' (--quick)' if quick else ''}", "",
                f"{env['date']}, commit `{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical "
                f"CPUs), exudyn {env['packages'].get('exudyn')}; wall time {walls}.", ""]
    problems = report.problems()
    sections += (["**Problems:** " + "; ".join(problems), ""] if problems
                 else ["No problems: no map cell and no long run raised in the harness.", ""])
    sections += [TESTS, ""]
    if report.map is not None:
        report.map.cells.to_csv(folder / "map_cells.csv", index=False)
        plots.save(plot_map(report.map), folder / "stability_map.png")
        sections += [map_markdown(report.map), "![stability map](stability_map.png)", ""]
    if report.long is not None:
        write_long(report.long, folder)
        sections += [long_markdown(report.long), ""]
    (folder / "report.md").write_text("\n".join(sections), encoding="utf-8")
    (folder / "stress.json").write_text(dumps({**report.summary(), "environment": env}) + "\n",
                                        encoding="utf-8")


def summary_lines(report: StressReport, out: str | os.PathLike) -> list[str]:
    """What ``cardan stress`` prints when it is done: the map's classes, the long runs' statuses."""
    lines = []
    if report.map is not None:
        counts = report.map.counts()
        lines.append("map: " + ", ".join(f"{v} {k}" for k, v in counts["classes"].items())
                     + f"; {counts['disagreements']} of {counts['cells']} cells disagree with the "
                     f"reference")
    if report.long is not None:
        lines.append(f"long runs: {report.long.status_line()} (verdicts: pytest tests/test_longrun.py)")
    lines.append(f"report: {out}/report.md")
    return lines


def class_mark(r: pd.Series) -> str:
    """Class letter, ``*`` where the reference self-locks, ``!`` where the engines disagree."""
    return (SYMBOLS[r["cell_class"]] + ("*" if r["reference"] == Status.SELF_LOCKING else "")
            + ("!" if not r["agrees"] else ""))


def error_mark(r: pd.Series) -> str:
    """Efficiency error against the reference (promise in brackets), else :func:`class_mark`."""
    err, promise = as_float(r["efficiency_error"]), as_float(r["efficiency_promise"])
    if not math.isfinite(err):
        return class_mark(r)
    return f"{err:.1e}" + (f" ({promise:.0e})" if math.isfinite(promise) else "")


def panel_table(cells: pd.DataFrame, panel: Panel, mark: Callable[[pd.Series], str] = class_mark) -> str:
    """Markdown grid of one panel, one ``mark(row)`` per cell (default: :func:`class_mark`)."""
    sel = cells[cells["panel"] == panel.key]
    columns = ["angle", *(f"{x:g}" for x in panel.x_values)]
    rows = []
    for angle in panel.angles:
        row = sel[sel["angle_deg"] == angle].set_index("x")
        rows.append({"angle": f"{angle:g} deg",
                     **{f"{x:g}": mark(row.loc[x]) for x in panel.x_values}})
    headers = ["angle \\ " + X_LABELS[panel.x], *columns[1:]]
    return markdown_table(rows, columns, headers=headers).rstrip("\n")


def _map_intro(counts: dict[str, Any]) -> list[str]:
    return [
        "## Stability map",
        "",
        f"{counts['cells']} cells, each one revolution of `{BASE_SCENE}` (2 N m load) at constant "
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
    parts = _map_intro(counts)
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
    """One image per panel: cell colour = class, hatched = reference self-locks, ``!`` =
    disagreement; the reference's self-locking boundary drawn as a black line."""
    return plots.stability_map(stress.cells, [
        {"key": p.key, "title": p.title, "x": p.x, "x_label": X_LABELS[p.x],
         "x_values": p.x_values, "angles": p.angles} for p in stress.panels], CLASSES)
