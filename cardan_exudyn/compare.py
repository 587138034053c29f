"""Cross-engine comparison: one scene, several engines, differences per column.

``compare(scene, engines)`` runs each engine on the same scene, joins the time tables on the
input angle and reports, per shared column, the maximum and RMS difference of every engine from
the first one (the *base*), with the scale of the column, plus the differences of the mean
values. Fixed-step engines choose their step from the scene; the reference engine is then asked
for rows at the base engine's step (``numerics.dt``), which only sets where its exact solution
is sampled, so for constant-speed scenes the rows coincide and no interpolation enters the
differences. Otherwise the other engine's columns are interpolated onto the base's input angles
with a cubic spline, and the report says so.

The first ``skip_revolutions`` (default 0) can be left out of the per-column statistics, e.g. to
keep an integrator's start-up transient apart from its steady-state error; the report gives both.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.engines import EngineUnavailable, get_engine
from cardan_exudyn.io import atomic_directory, dumps
from reference.scene import PAIR_NAMES, Scene, replace
from reference.schema import table_columns

SUMMARY_KEYS = ("mean_efficiency", "mean_instantaneous_efficiency", "work_ratio", "input_work",
                "output_work", "loss_work", "mean_torque_in",
                *(f"loss_work_{p}" for p in PAIR_NAMES))
# columns whose differences are reported (the schema's numerical columns but time)
COMPARED = [c for c in table_columns() if c != "t"]


def _finite(value: Any) -> bool:
    """A finite number (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _run(engine: str, scene: Scene) -> tuple[Any, float]:
    start = time.perf_counter()
    try:
        result = get_engine(engine)(scene)
    except NotImplementedError as exc:
        raise EngineUnavailable(f"engine {engine!r} cannot run scene {scene.name!r}: {exc}") from None
    return result, time.perf_counter() - start


def join_on_input_angle(base: Any, other: Any) -> tuple[dict[str, np.ndarray], str]:
    """``other``'s columns at ``base``'s input angles, and how they were obtained.

    Rows are taken as they are when both tables have the same input angles (to 1e-9 rad);
    otherwise each column is interpolated by a cubic spline in the input angle, over the span
    both tables cover (base rows outside it are NaN).
    """
    theta_b = base["theta_in"].to_numpy(float)
    theta_o = other["theta_in"].to_numpy(float)
    if theta_b.shape == theta_o.shape and np.max(np.abs(theta_b - theta_o)) <= 1e-9:
        return {c: other[c].to_numpy(float) for c in COMPARED if c in other}, "same rows"
    from scipy.interpolate import CubicSpline

    sign = 1.0 if theta_o[-1] >= theta_o[0] else -1.0
    x = sign * theta_o
    keep = np.concatenate([[True], np.diff(x) > 0])  # strictly increasing for the spline
    out = {}
    inside = (sign * theta_b >= x[keep][0]) & (sign * theta_b <= x[keep][-1])
    for c in COMPARED:
        if c not in other:
            continue
        y = other[c].to_numpy(float)[keep]
        values = np.full(theta_b.shape, np.nan)
        if np.all(np.isfinite(y)):
            values[inside] = CubicSpline(x[keep], y)(sign * theta_b[inside])
        out[c] = values
    return out, "cubic spline in the input angle"


def column_differences(base: Any, joined: dict[str, np.ndarray],
                       mask: np.ndarray) -> dict[str, dict[str, float]]:
    """Max and RMS of ``joined - base`` over the rows in ``mask``, and the column's scale."""
    out = {}
    for c, values in joined.items():
        b = base[c].to_numpy(float)[mask]
        d = values[mask] - b
        ok = np.isfinite(d)
        if not np.any(ok):
            continue
        scale = float(np.max(np.abs(b[np.isfinite(b)]))) if np.any(np.isfinite(b)) else float("nan")
        out[c] = {"max_abs": float(np.max(np.abs(d[ok]))),
                  "rms": float(np.sqrt(np.mean(d[ok] ** 2))),
                  "scale": scale,
                  "rows": int(np.count_nonzero(ok))}
    return out


def compare(scene: Scene, engines: list[str], skip_revolutions: float = 0.0,
            progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Run ``engines`` on ``scene`` and compare every later engine with the first.

    Returns
    -------
    dict
        ``scene``; ``engines``: per engine the status, reason, version, wall time, step and the
        :data:`SUMMARY_KEYS`; ``differences``: per later engine the join method, the mean-value
        differences (other - base) and, per column, the statistics of
        :func:`column_differences` over all rows (``all``) and after ``skip_revolutions``
        (``steady``); ``tables``: the time tables (not serialised).
    """
    if len(engines) < 2:
        raise ValueError(f"`--engines` needs at least two engines, got {engines!r}")
    if len(set(engines)) != len(engines):
        raise ValueError(f"`--engines` lists an engine twice: {engines!r}")
    if skip_revolutions < 0 or not math.isfinite(skip_revolutions):
        raise ValueError(f"`skip_revolutions` must be >= 0, got {skip_revolutions!r}")
    for engine in engines:  # every name known before the first engine runs
        get_engine(engine)
    scene = replace(scene, **{"record.timeseries": True, "record.every": 1})
    results, tables = {}, {}
    base_dt = None
    for engine in engines:
        run_scene = scene
        if engine == "reference" and base_dt is not None and scene.numerics.dt is None:
            run_scene = replace(scene, **{"numerics.dt": base_dt})  # rows at the base's step
        if progress:
            progress(f"{scene.name}: running {engine}")
        result, wall = _run(engine, run_scene)
        s = result.summary
        results[engine] = {"status": s.get("status"), "reason": s.get("reason", ""),
                           "engine_version": s.get("engine_version"), "wall_time_s": wall,
                           "dt": s.get("dt"), "steps": s.get("steps"),
                           **{k: s.get(k) for k in SUMMARY_KEYS if k in s}}
        tables[engine] = result.table
        if base_dt is None:
            base_dt = s.get("dt")
    base_name = engines[0]
    base = tables[base_name]
    differences = {}
    if base is not None:
        theta = base["theta_in"].to_numpy(float)
        steady = np.abs(theta - theta[0]) >= 2.0 * math.pi * skip_revolutions
        for engine in engines[1:]:
            if tables[engine] is None:
                continue
            joined, how = join_on_input_angle(base, tables[engine])
            both_ok = results[engine]["status"] == results[base_name]["status"] == "ok"
            means = {k: results[engine][k] - results[base_name][k] for k in SUMMARY_KEYS
                     if both_ok and _finite(results[engine].get(k)) and _finite(results[base_name].get(k))}
            differences[engine] = {"against": base_name, "join": how, "means": means,
                                   "all": column_differences(base, joined, np.ones_like(steady)),
                                   "steady": column_differences(base, joined, steady)}
    return {"scene": scene.name, "skip_revolutions": skip_revolutions, "engines": results,
            "differences": differences, "tables": tables}


def report_markdown(comparison: dict[str, Any]) -> str:
    """The comparison as a markdown report."""
    lines = [f"# Engine comparison: {comparison['scene']}", "",
             "| engine | status | mean efficiency | work ratio | dt [s] | steps | wall [s] |",
             "|---|---|---|---|---|---|---|"]
    for name, r in comparison["engines"].items():
        def fmt(v: Any, spec: str) -> str:
            return format(v, spec) if _finite(v) else "-"

        ok = r["status"] == "ok"  # a failed run has no efficiency to show
        lines.append(f"| {name} {r.get('engine_version') or ''} | {r['status']} "
                     f"{r['reason'][:60] if r['reason'] else ''} | "
                     f"{fmt(r.get('mean_efficiency') if ok else None, '.8f')} | "
                     f"{fmt(r.get('work_ratio') if ok else None, '.8f')} | "
                     f"{fmt(r.get('dt'), '.3g')} | {fmt(r.get('steps'), 'd')} | "
                     f"{fmt(r['wall_time_s'], '.3f')} |")
    for engine, d in comparison["differences"].items():
        lines += ["", f"## {engine} - {d['against']} (rows joined: {d['join']})", ""]
        lines += ["| mean value | difference |", "|---|---|"]
        lines += [f"| {k} | {v:+.3e} |" for k, v in d["means"].items()]
        skip = comparison["skip_revolutions"]
        lines += ["", f"Per column: max and RMS difference over all rows, and after the first "
                      f"{skip:g} revolutions (steady), with the column's largest magnitude.", "",
                  "| column | max all | RMS all | max steady | RMS steady | scale |",
                  "|---|---|---|---|---|---|"]
        for c, v in d["all"].items():
            st = d["steady"].get(c, {})
            lines.append(f"| {c} | {v['max_abs']:.3e} | {v['rms']:.3e} | "
                         f"{st.get('max_abs', float('nan')):.3e} | {st.get('rms', float('nan')):.3e} | "
                         f"{v['scale']:.3e} |")
    return "\n".join(lines) + "\n"


def overlay_plots(comparison: dict[str, Any], folder: Path) -> list[str]:
    """Overlay plots of the engines against the input angle; returns the file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cardan_exudyn.report.plots import save

    tables = {k: v for k, v in comparison["tables"].items() if v is not None}
    groups = {
        "kinematics": [("speed ratio [-]", lambda t: t["omega_out"] / t["omega_in"]),
                       ("torque_in [N m]", lambda t: t["torque_in"]),
                       ("efficiency [-]", lambda t: t["efficiency"])],
        "losses": [(f"power_loss_{p} [W]", lambda t, p=p: t[f"power_loss_{p}"])
                   for p in PAIR_NAMES],
        "reactions": [(f"{p} |F| [N]", lambda t, p=p: np.hypot(t[f"{p}_fx"], t[f"{p}_fy"]))
                      for p in PAIR_NAMES]
        + [(f"{p} |M| [N m]", lambda t, p=p: np.hypot(t[f"{p}_mx"], t[f"{p}_my"]))
           for p in PAIR_NAMES],
    }
    names = []
    for group, panels in groups.items():
        n = len(panels)
        cols = 2 if n > 3 else 1
        rows = math.ceil(n / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(7 * cols, 2.6 * rows), squeeze=False,
                                 sharex=True)
        for ax, (label, values) in zip(axes.ravel(), panels, strict=False):
            for k, (engine, table) in enumerate(tables.items()):
                ax.plot(np.degrees(table["theta_in"]), values(table), label=engine,
                        lw=1.6 if k == 0 else 1.0, ls="-" if k == 0 else "--")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        for ax in axes[-1]:
            ax.set_xlabel("input angle [deg]")
        axes[0, 0].legend()
        fig.suptitle(f"{comparison['scene']}: {', '.join(tables)}")
        fig.tight_layout()
        name = f"overlay_{group}.png"
        save(fig, folder / name)
        plt.close(fig)
        names.append(name)
    return names


def write_report(comparison: dict[str, Any], out: str | Path) -> Path:
    """Report folder: ``comparison.json``, ``report.md``, ``<engine>.csv`` tables, overlay plots.

    Written into a temporary folder renamed into place, so a failure leaves nothing half-written.
    """
    with atomic_directory(out) as folder:
        serial = {k: v for k, v in comparison.items() if k != "tables"}
        (folder / "comparison.json").write_text(dumps(serial))
        (folder / "report.md").write_text(report_markdown(comparison))
        for engine, table in comparison["tables"].items():
            if table is not None:
                table.to_csv(folder / f"{engine}.csv", index=False)
        overlay_plots(comparison, folder)
    return Path(out)


def main_compare(scene: Scene, engines: list[str], skip_revolutions: float, out: str | None,
                 as_json: bool) -> int:
    """``cardan compare``: exit 0 when every engine ran to status ok, 3 otherwise."""
    def progress(msg: str) -> None:
        print(msg, flush=True)

    comparison = compare(scene, engines, skip_revolutions, progress=None if as_json else progress)
    if out:
        write_report(comparison, out)
    if as_json:
        print(dumps({k: v for k, v in comparison.items() if k != "tables"}))
    else:
        print(report_markdown(comparison))
        if out:
            print(f"report written to {out}")
    return 0 if all(r["status"] == "ok" for r in comparison["engines"].values()) else 3
