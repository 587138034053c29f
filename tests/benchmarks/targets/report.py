"""The results folder of the targets: ``bench.csv`` and ``audit.csv`` opening with an environment
header, ``targets.csv``, ``ladders.csv`` (every friction run next to its frictionless twin),
``targets.json``, ``report.md`` and ``work_precision.png`` (the target levels dashed), written
atomically."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from benchmarks.targets.run import TargetsResult
from benchmarks.targets.targets import (
    EFFICIENCY_TARGET,
    SPEED_RATIO_TARGET,
    TARGETS,
    friction_ladders,
    is_friction_scene,
)
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import number
from cardan_exudyn.studies.bench.report import header, intro, rows_section, table, work_precision_figure

__all__ = ["TARGET_COLUMNS", "targets_command", "report_markdown", "write_targets"]

TARGET_COLUMNS = ["target", "scene", "variant", "measured", "limit", "met", "exudyn", "other", "detail"]
AUDIT_COLUMNS = ["item", "removal", "without_s", "with_s", "with_over_without", "saved_share"]
AUDIT_FORMATS = {"without_s": ".4f", "with_s": ".4f", "with_over_without": ".2f", "saved_share": ".0%"}
LADDER_COLUMNS = ["config", "steps_per_revolution", "status", "mean_efficiency_error",
                  "wall_per_simulated_s", "frictionless_wall_per_simulated_s", "cost_ratio"]
LADDER_FORMATS = {"steps_per_revolution": "d", "cost_ratio": ".2f"}
TITLE = "python tests/benchmarks targets"


def targets_command(settings: Mapping[str, Any]) -> str:
    """The command line that runs the targets of ``settings`` again."""
    parts = [TITLE]
    if settings.get("quick"):
        parts.append("--quick")
    if settings.get("repeats") is not None:
        parts.append(f"--repeats {settings['repeats']}")
    for key in ("scenes", "engines"):
        if settings.get(key):
            parts.append(f"--{key} {','.join(settings[key])}")
    for key in ("audit", "paper", "startup"):
        if settings.get(key) is False:
            parts.append(f"--no-{key}")
    if settings.get("paper", True) and settings.get("paper_steps") is not None:
        parts.append(f"--paper-steps {settings['paper_steps']} "
                     f"--paper-coupling {settings['paper_coupling']}")
    return " ".join(parts)


def targets_section(result: TargetsResult) -> str:
    """The targets table, the command that produced it and what each target means."""
    out = f"## Targets\n`{targets_command(result.settings)}`\n\n"
    if result.targets:
        targets = pd.DataFrame(result.targets)
        targets["met"] = targets["met"].map({True: "yes", False: "**no**"})
        out += table(targets, TARGET_COLUMNS)
    return out + "\nTargets: " + "; ".join(f"**{k}**: {v}" for k, v in TARGETS.items()) + ".\n"


def _steps(part: Mapping[str, Any]) -> str:
    """``; steps/rev: ...`` per scene where the scenes' steps differ (an automatic step)."""
    steps = [s for s in part.get("steps_per_revolution") or [] if s is not None]
    return f"; steps/rev: {', '.join(str(s) for s in steps)}" if len(set(steps)) > 1 else ""


def paper_section(paper: Mapping[str, Any]) -> str:
    """One line per engine of the paper scenes' timing."""
    out = "\n## The paper's eleven scenes (summary only, one after the other)\n"
    for engine, part in paper.items():
        out += (f"- {engine} ({part['config']}): {part['wall_s']:.2f} s (median of "
                f"{part['repeats']}; all: {', '.join(f'{w:.2f}' for w in part['walls_s'])}), "
                f"largest mean-efficiency error {number(part['max_error'], '.2g')}, not ok: "
                f"{part['failed']}" + _steps(part) + "\n")
    return out


def ladders_section(rows: pd.DataFrame) -> str:
    """Per friction scene: every Exudyn configuration's ladder, its efficiency error and its cost
    over the frictionless twin at the same step (what the friction-cost target reads)."""
    ladders = friction_ladders(rows)
    if ladders.empty:
        return ""
    out = ("\n## Friction ladders: error against cost, per coupling\n"
           f"The friction-cost target reads the cheapest step with an error <= {EFFICIENCY_TARGET:g}; "
           "`cost_ratio` is the wall time over the same configuration without its coupling on the "
           "frictionless twin scene at the same step.\n")
    for scene, part in ladders.groupby("scene", sort=False):
        out += f"\n### {scene}\n" + table(part, LADDER_COLUMNS, LADDER_FORMATS)
    return out


def startup_section(startup: Mapping[str, Any]) -> str:
    """The import cost of ``cardan run`` and its most expensive top-level imports."""
    return (f"\n## Import cost of `cardan run` up to the engine\n"
            f"{number(startup.get('import_ms'), '.0f')} ms (median of {startup.get('repeats')} "
            f"fresh interpreters under `python -X importtime`): "
            f"{number(startup.get('import_ms'), '.0f')} ms before the scene is built, "
            f"{number(startup.get('scene_build_ms'), '.0f')} ms while it is built. Largest "
            f"top-level imports [ms]: "
            + ", ".join(f"`{name}` {ms:.0f}" for name, ms in startup.get("top") or []) + ".\n")


def audit_section(audit: pd.DataFrame) -> str:
    """The skip audit's table and its scene."""
    return ("\n## What each skip saves (Exudyn)\n" + table(audit, AUDIT_COLUMNS, AUDIT_FORMATS)
            + f"\nScene: {audit['scene'].iloc[0]}.\n")


def report_markdown(result: TargetsResult) -> str:
    """``report.md``: environment, targets, paper scenes, import cost, friction ladders, skip
    audit, the work-precision table and plot."""
    out = [intro(result.bench, TITLE), targets_section(result)]
    if result.paper:
        out.append(paper_section(result.paper))
    if result.startup:
        out.append(startup_section(result.startup))
    out.append(ladders_section(result.bench.rows))
    if result.audit is not None:
        out.append(audit_section(result.audit))
    out.append(rows_section(result.bench.rows))
    return "".join(out)


def write_targets(result: TargetsResult, out: str | os.PathLike) -> Path:
    """Write the results folder ``out`` (replaced as a whole, atomically); returns its path."""
    from cardan_exudyn.report.plots import close  # import cost: matplotlib only for the folder

    bench = result.bench
    head = header(bench.environment, TITLE)
    panels = {key: ("mean_efficiency_error", EFFICIENCY_TARGET) if is_friction_scene(key)
              else ("speed_ratio_error", SPEED_RATIO_TARGET) for key in bench.scenes}
    with atomic_directory(out) as tmp:
        rows = bench.rows.drop(columns=["options"])
        (tmp / "bench.csv").write_text(head + rows.to_csv(index=False, float_format="%.6g"),
                                       encoding="utf-8")
        pd.DataFrame(result.targets).to_csv(tmp / "targets.csv", index=False, float_format="%.4g")
        friction_ladders(bench.rows).to_csv(tmp / "ladders.csv", index=False, float_format="%.6g")
        if result.audit is not None:
            (tmp / "audit.csv").write_text(head + result.audit.to_csv(index=False, float_format="%.4g"),
                                           encoding="utf-8")
        data = {**result.summary(), "rows": bench.rows.to_dict(orient="records")}
        (tmp / "targets.json").write_text(dumps(data) + "\n", encoding="utf-8")
        fig = work_precision_figure(bench.rows, panels)
        fig.savefig(tmp / "work_precision.png", dpi=120)
        close(fig)
        (tmp / "report.md").write_text(report_markdown(result), encoding="utf-8")
    return Path(out)
