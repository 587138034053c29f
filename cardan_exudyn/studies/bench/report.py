"""The results folder of ``cardan bench``: ``bench.csv`` (environment header), ``bench.json``,
``report.md`` and ``work_precision.png``, written atomically.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table
from cardan_exudyn.studies.bench.result import BenchResult, accuracy_measure, at_accuracy
from reference.results.summary import Status

__all__ = ["ROW_COLUMNS", "MEASURE_LABELS", "header", "table", "bench_command", "intro",
           "accuracy_section", "rows_section", "report_markdown", "work_precision_figure",
           "write_bench"]

ROW_COLUMNS = ["scene", "config", "steps_per_revolution", "status", "wall_per_simulated_s",
               "speed_ratio_error", "torque_in_error", "torque_in_error_steady",
               "mean_efficiency_error", "mean_torque_in_error", "newton_iterations",
               "friction_evaluations_per_step"]
MEASURE_LABELS = {"mean_efficiency_error": "mean-efficiency error",
                  "speed_ratio_error": "max speed-ratio error"}
ACCURACY_COLUMNS = ["scene", "config", "accuracy", "steps_per_revolution", "error",
                    "wall_per_simulated_s", "fastest_wall_per_simulated_s"]
ACCURACY_FORMATS = {"accuracy": "g", "steps_per_revolution": ".0f", "error": ".2g",
                    "wall_per_simulated_s": ".3g", "fastest_wall_per_simulated_s": ".3g"}
MARKERS = {"exudyn": "o", "mujoco": "s", "reference": "^"}


def header(env: Mapping[str, Any], title: str = "cardan bench") -> str:
    """The ``#`` lines that open a results file: ``title``, then ``env``'s date, commit, CPU, versions."""
    lines = [f"# {title}, {env['date']}", f"# commit {env['commit']}",
             f"# cpu {env['cpu']} ({env['cpu_count']} logical), {env['platform']}",
             f"# python {env['python']}, " + ", ".join(f"{k} {v}" for k, v in env["packages"].items())]
    return "\n".join(lines) + "\n"


def table(frame: pd.DataFrame, columns: Sequence[str], formats: Mapping[str, str] | None = None) -> str:
    """Markdown table of ``columns`` of ``frame``; ``formats``: column -> spec (floats: 3 digits)."""
    floats = {c: ".3g" for c in columns if c in frame and frame[c].dtype.kind == "f"}
    return markdown_table(frame, columns, {**floats, **(formats or {})})


def bench_command(settings: Mapping[str, Any]) -> str:
    """The ``cardan bench`` command line that runs the bench of ``settings`` again."""
    parts = ["cardan bench"]
    if settings.get("quick"):
        parts.append("--quick")
    if settings.get("repeats") is not None:
        parts.append(f"--repeats {settings['repeats']}")
    options = list(settings.get("scene_options") or [])
    if options:
        parts += options
    elif settings.get("scenes"):
        parts.append(f"--scenes {','.join(settings['scenes'])}")
    if settings.get("engines"):
        parts.append(f"--engines {','.join(settings['engines'])}")
    return " ".join(parts)


def intro(result: BenchResult, title: str = "cardan bench", command: str | None = None) -> str:
    """Title, environment, the ``command`` that ran ``result`` (if given) and how to read the numbers."""
    env = result.environment
    return (f"# {title}{' (quick)' if result.settings.get('quick') else ''}\n"
            f"{env['date']}, commit `{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical "
            f"CPUs), Python {env['python']}, "
            + ", ".join(f"{k} {v}" for k, v in env["packages"].items() if v) + ".\n"
            f"Median of {result.settings.get('repeats')} runs per configuration, run in rounds; "
            f"whole bench {result.wall_s:.0f} s. Wall time is the engine's `run` call (build, solve, "
            "result table) per simulated second. Errors against the reference engine (exact for "
            "prescribed motion). Machines are often shared: compare ratios within this run, not "
            "absolute times across runs.\n" + (f"\n`{command}`\n" if command else ""))


def _scenes_lines(result: BenchResult) -> str:
    """One line per scene: its key, name and description."""
    return "".join(f"- `{key}`: {scene.name}" + (f" ({scene.description})" if scene.description else "")
                   + "\n" for key, scene in result.scenes.items())


def accuracy_section(result: BenchResult) -> str:
    """Per scene and configuration, the cheapest step at the scene's ``numerics.accuracy``."""
    rows = pd.DataFrame(at_accuracy(result))
    if rows.empty:
        return ""
    return ("\n## The cheapest run of each configuration at the scene's accuracy\n"
            "The error bounded by the scene's `numerics.accuracy`: the mean-efficiency error with "
            "friction, the speed-ratio error without. An empty `steps_per_revolution`: no step of "
            "the ladder reaches the accuracy.\n\nScenes:\n\n" + _scenes_lines(result) + "\n"
            + markdown_table(rows, ACCURACY_COLUMNS, ACCURACY_FORMATS, missing=""))


def rows_section(rows: pd.DataFrame) -> str:
    """The work-precision table and the plot."""
    return ("\n## Work-precision table\n" + table(rows, ROW_COLUMNS, {"steps_per_revolution": "d"})
            + "\n![work-precision](work_precision.png)\n")


def report_markdown(result: BenchResult) -> str:
    """``report.md``: environment, the cheapest run at the accuracy, the work-precision table and plot."""
    return (intro(result, command=bench_command(result.settings)) + accuracy_section(result)
            + rows_section(result.rows))


def _panel(ax: Any, sel: pd.DataFrame, key: str, label: str) -> None:
    """One line per configuration of ``sel``: ``key`` against the wall time, log-log."""
    for config, part in sel.groupby("config", sort=False):
        part = part.sort_values("steps_per_revolution")
        y = part[key].astype(float).clip(lower=1e-16)
        if not y.notna().any():
            continue
        ax.loglog(part["wall_per_simulated_s"], y, marker=MARKERS.get(part["engine"].iloc[0], "o"),
                  ms=4, lw=1, label=config)
    ax.set_xlabel("wall time per simulated second [s]")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=6)


def work_precision_figure(rows: pd.DataFrame, panels: Mapping[str, tuple[str, float]]) -> Any:
    """Error against wall time per simulated second, log-log, one column per scene of ``panels`` (key ->
    top row's error column and level [-]); bottom row: drive-torque error after the first revolution.
    """
    from cardan_exudyn.report.plots import plt  # import cost: matplotlib only when a plot is drawn

    fig, axes = plt.subplots(2, len(panels), figsize=(4.6 * len(panels), 7.5), squeeze=False,
                             constrained_layout=True)
    for j, (scene, (measure, level)) in enumerate(panels.items()):
        sel = rows[(rows["scene"] == scene) & (rows["status"] == Status.OK)]
        _panel(axes[0][j], sel, measure, MEASURE_LABELS.get(measure, measure))
        axes[0][j].axhline(level, color="k", ls="--", lw=0.8)
        axes[0][j].set_title(scene)
        _panel(axes[1][j], sel, "torque_in_error_steady", "drive-torque error after rev. 1 (rel.)")
    return fig


def write_bench(result: BenchResult, out: str | os.PathLike) -> Path:
    """Write ``result``'s folder ``out`` (replaced atomically); returns ``out``."""
    from cardan_exudyn.report.plots import close  # import cost, as above

    panels = {key: (accuracy_measure(scene), scene.numerics.accuracy)
              for key, scene in result.scenes.items()}
    with atomic_directory(out) as tmp:
        rows = result.rows.drop(columns=["options"])
        (tmp / "bench.csv").write_text(header(result.environment)
                                       + rows.to_csv(index=False, float_format="%.6g"), encoding="utf-8")
        data = {**result.summary(), "rows": result.rows.to_dict(orient="records")}
        (tmp / "bench.json").write_text(dumps(data) + "\n", encoding="utf-8")
        fig = work_precision_figure(result.rows, panels)
        fig.savefig(tmp / "work_precision.png", dpi=120)
        close(fig)
        (tmp / "report.md").write_text(report_markdown(result), encoding="utf-8")
    return Path(out)

