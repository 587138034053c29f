"""The report folder of ``cardan compare``: ``comparison.json``, ``report.md``, ``<engine>.csv``
and ``overlay_<group>.png``, from a :class:`cardan_exudyn.comparison.Comparison`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table
from reference.scene.joint import PAIR_NAMES

if TYPE_CHECKING:
    from cardan_exudyn.comparison import Comparison, EngineDifference

__all__ = ["report_markdown", "engines_table", "difference_section", "overlay_groups",
           "overlay_plots", "overlay_figure", "write_report"]


ENGINE_COLUMNS = ["engine", "status", "mean efficiency", "work ratio", "dt [s]", "steps", "wall [s]"]
ENGINE_FORMATS = {"mean efficiency": ".8f", "work ratio": ".8f", "dt [s]": ".3g", "steps": "d",
                  "wall [s]": ".3f"}
COLUMN_COLUMNS = ["column", "max all", "RMS all", "max steady", "RMS steady", "scale"]


def report_markdown(comparison: Comparison) -> str:
    """The comparison as a markdown report: the runs, then per later engine its differences."""
    parts = [f"# Engine comparison: {comparison.scene.name}\n\n", engines_table(comparison)]
    for d in comparison.differences.values():
        parts.append(difference_section(d, comparison.skip_revolutions))
    return "".join(parts)


def engines_table(comparison: Comparison) -> str:
    """One row per engine: version, status, reason, mean efficiency and work ratio (ok runs), step [s],
    steps, wall time [s].
    """
    rows = []
    for name in comparison.results:
        r = comparison.engine_record(name)
        ok = comparison.results[name].success  # a failed run has no efficiency to show
        rows.append({"engine": f"{name} {r['engine_version'] or ''}",
                     "status": f"{r['status']} {r['reason'][:60] if r['reason'] else ''}",
                     "mean efficiency": r.get("mean_efficiency") if ok else None,
                     "work ratio": r.get("work_ratio") if ok else None,
                     "dt [s]": r["dt"], "steps": r["steps"], "wall [s]": r["wall_time_s"]})
    return markdown_table(rows, ENGINE_COLUMNS, ENGINE_FORMATS)


def difference_section(d: EngineDifference, skip_revolutions: float) -> str:
    """Mean-value differences and per-column statistics of engine difference ``d`` against the base
    (``skip_revolutions`` left out of the steady statistics).
    """
    means = [{"mean value": key, "difference": value} for key, value in d.means.items()]
    columns = []
    for column, v in d.overall.iterrows():
        st = d.steady.loc[column] if column in d.steady.index else {}
        columns.append({"column": column, "max all": v["max_abs"], "RMS all": v["rms"],
                        "max steady": st.get("max_abs"), "RMS steady": st.get("rms"),
                        "scale": v["scale"]})
    return (f"\n## {d.engine} - {d.against} (rows joined: {d.join})\n\n"
            + markdown_table(means, ["mean value", "difference"], {"difference": "+.3e"})
            + f"\nPer column: max and RMS difference over all rows, and after the first "
              f"{skip_revolutions:g} revolutions (steady), with the column's largest magnitude.\n\n"
            + markdown_table(columns, COLUMN_COLUMNS, {c: ".3e" for c in COLUMN_COLUMNS[1:]}))


def overlay_groups() -> dict[str, list[tuple[str, Callable[[Any], Any]]]]:
    """Plot panels per overlay figure: label and the values of a time table to draw."""
    hypot = np.hypot
    return {
        "kinematics": [("speed ratio [-]", lambda t: t["omega_out"] / t["omega_in"]),
                       ("torque_in [N m]", lambda t: t["torque_in"]),
                       ("efficiency [-]", lambda t: t["efficiency"])],
        "losses": [(f"power_loss_{p} [W]", lambda t, p=p: t[f"power_loss_{p}"]) for p in PAIR_NAMES],
        "reactions": [(f"{p} |F| [N]", lambda t, p=p: hypot(t[f"{p}_fx"], t[f"{p}_fy"]))
                      for p in PAIR_NAMES]
        + [(f"{p} |M| [N m]", lambda t, p=p: hypot(t[f"{p}_mx"], t[f"{p}_my"])) for p in PAIR_NAMES],
    }


def overlay_plots(comparison: Comparison, folder: Path) -> list[str]:
    """Overlay plots of ``comparison``'s engines with a time table against the input angle, one file
    per :func:`overlay_groups` group in ``folder``; returns the file names.
    """
    tables = {name: r.table for name, r in comparison.results.items() if r.table is not None}
    names = []
    for group, panels in overlay_groups().items():
        name = f"overlay_{group}.png"
        overlay_figure(comparison.scene.name, tables, panels, folder / name)
        names.append(name)
    return names


def overlay_figure(title: str, tables: dict[str, Any],
                   panels: list[tuple[str, Callable[[Any], Any]]], path: Path) -> None:
    """One figure ``title`` into ``path``: a panel per (label, values) of ``panels`` against the input
    angle [deg], a line per engine of ``tables`` (the base first, solid).
    """
    # import cost: matplotlib only when a report is written (report.plots selects the Agg backend
    # before any figure exists)
    import matplotlib.pyplot as plt

    from cardan_exudyn.report.plots import save

    cols = 2 if len(panels) > 3 else 1
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(7 * cols, 2.6 * rows), squeeze=False, sharex=True)
    for ax, (label, values) in zip(axes.ravel(), panels, strict=False):
        for k, (engine, table) in enumerate(tables.items()):
            ax.plot(np.degrees(table["theta_in"]), values(table), label=engine,
                    lw=1.6 if k == 0 else 1.0, ls="-" if k == 0 else "--")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("input angle [deg]")
    axes[0, 0].legend()
    fig.suptitle(f"{title}: {', '.join(tables)}")
    fig.tight_layout()
    save(fig, path)


def write_report(comparison: Comparison, out: str | Path) -> Path:
    """``comparison``'s folder ``out`` (replaced atomically): ``comparison.json``, ``report.md``,
    ``<engine>.csv``, overlay plots; returns ``out``.
    """
    with atomic_directory(out) as folder:
        (folder / "comparison.json").write_text(dumps(comparison.to_dict()))
        (folder / "report.md").write_text(report_markdown(comparison))
        for engine, result in comparison.results.items():
            if result.table is not None:
                result.table.to_csv(folder / f"{engine}.csv", index=False)
        overlay_plots(comparison, folder)
    return Path(out)
