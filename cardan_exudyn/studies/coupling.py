"""Numerical studies of the friction model: coupling schemes against step size, and the sign band.

``cardan study coupling``: for each scene and each coupling scheme (lagged, converged), the mean
efficiency at a ladder of step sizes, its error against a run of the converged scheme with a
step four times finer than the finest of the ladder, the observed order between neighbouring
steps, and the cost (wall time, Newton iterations, friction evaluations per step), measured side
by side in one process.

``cardan study sign-band``: the mean efficiency at 0 and 10 deg against the width of the
regularised sign, from far below the numerical noise of the relative speeds to far above it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.model.solve import run
from cardan_exudyn.io import atomic_directory, dumps
from reference.paper import named_scene
from reference.scene import Scene, replace


def _efficiency(scene: Scene) -> dict[str, Any]:
    start = time.perf_counter()
    result = run(replace(scene, **{"record.timeseries": False}))
    wall = time.perf_counter() - start
    s = result.summary
    out = {"status": s["status"], "reason": s.get("reason", ""), "wall_time_s": wall,
           "steps": s.get("steps"), "newton_iterations": s.get("newton_iterations"),
           "mean_efficiency": s.get("mean_efficiency", float("nan")),
           "mean_instantaneous_efficiency": s.get("mean_instantaneous_efficiency", float("nan"))}
    if "friction" in s:
        out["friction_evaluations_per_step"] = s["friction"]["mean_iterations_per_step"]
    return out


def _step(scene: Scene, steps_per_revolution: int) -> float:
    return 2.0 * math.pi / abs(scene.drive.speed) / steps_per_revolution


def coupling_study(names: list[str], ladder: list[int], revolutions: float = 1.0,
                   progress: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Rows (scene, coupling, steps/rev, dt, efficiency, error, order, cost) for every combination."""
    rows = []
    for name in names:
        base = replace(named_scene(name), revolutions=revolutions)
        fine = 4 * max(ladder)
        ref_scene = replace(base, **{"friction.coupling": "converged",
                                     "numerics.dt": _step(base, fine)})
        if progress:
            progress(f"{name}: reference run, converged, {fine} steps per revolution")
        ref = _efficiency(ref_scene)
        for coupling in ("lagged", "converged"):
            previous = None
            for n in ladder:
                if progress:
                    progress(f"{name}: {coupling}, {n} steps per revolution")
                scene = replace(base, **{"friction.coupling": coupling,
                                         "numerics.dt": _step(base, n)})
                r = _efficiency(scene)
                error = r["mean_efficiency"] - ref["mean_efficiency"]
                order = float("nan")
                if previous is not None and error != 0.0 and previous[1] != 0.0:
                    order = math.log(abs(previous[1] / error)) / math.log(n / previous[0])
                rows.append({"scene": name, "coupling": coupling, "steps_per_revolution": n,
                             "dt": scene.numerics.dt, **r, "reference": ref["mean_efficiency"],
                             "reference_steps_per_revolution": fine, "error": error,
                             "observed_order": order})
                previous = (n, error)
    return rows


def sign_band_study(names: list[str], bands: list[float], revolutions: float = 1.0,
                    progress: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Mean efficiency against the sign band, for each scene (converged coupling)."""
    rows = []
    for name in names:
        base = replace(named_scene(name), revolutions=revolutions)
        for band in bands:
            if progress:
                progress(f"{name}: sign band {band:g} m/s")
            r = _efficiency(replace(base, **{"friction.sign_band": band}))
            rows.append({"scene": name, "sign_band_m_s": band, **r})
        ref = next((r["mean_efficiency"] for r in rows
                    if r["scene"] == name and r["status"] == "ok" and r["sign_band_m_s"] > 0),
                   float("nan"))
        for r in rows:
            if r["scene"] == name:
                r["change_from_smallest_positive_band"] = r["mean_efficiency"] - ref
    return rows


# ------------------------------------------------------------------ report


def _plot_coupling(rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = sorted({r["scene"] for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for name in scenes:
        for coupling, marker in (("lagged", "s--"), ("converged", "o-")):
            sel = [r for r in rows if r["scene"] == name and r["coupling"] == coupling
                   and r["status"] == "ok"]
            if not sel:
                continue
            n = [r["steps_per_revolution"] for r in sel]
            err = [max(abs(r["error"]), 1e-16) for r in sel]
            wall = [r["wall_time_s"] for r in sel]
            axes[0].loglog(n, err, marker, label=f"{name} {coupling}")
            axes[1].loglog(wall, err, marker, label=f"{name} {coupling}")
    n_ref = np.array(sorted({r["steps_per_revolution"] for r in rows}), dtype=float)
    if n_ref.size:
        top = max(abs(r["error"]) for r in rows if r["status"] == "ok")
        axes[0].loglog(n_ref, top * (n_ref[0] / n_ref), "k:", lw=0.8, label="first order")
        axes[0].loglog(n_ref, top * (n_ref[0] / n_ref) ** 2, "k-.", lw=0.8, label="second order")
    axes[0].set_xlabel("steps per input revolution")
    axes[0].set_ylabel("|error of mean efficiency|")
    axes[1].set_xlabel("wall time per run [s]")
    axes[1].set_ylabel("|error of mean efficiency|")
    axes[0].legend(fontsize=7)
    axes[0].set_title("error against step size")
    axes[1].set_title("error against cost")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _plot_band(rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for name in sorted({r["scene"] for r in rows}):
        sel = [r for r in rows if r["scene"] == name and r["status"] == "ok"]
        ax.semilogx([r["sign_band_m_s"] for r in sel], [r["mean_efficiency"] for r in sel],
                    "o-", label=name)
    ax.set_xlabel("sign band (surface speed) [m/s]")
    ax.set_ylabel("mean efficiency")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _markdown(rows: list[dict[str, Any]], columns: list[str]) -> str:
    def fmt(v: Any) -> str:
        if isinstance(v, float):
            return f"{v:.6g}" if math.isfinite(v) else "-"  # a failed run has no value
        return str(v)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(fmt(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def write_study(kind: str, rows: list[dict[str, Any]], out: str) -> Path:
    """Write ``rows`` as CSV, JSON, a markdown table and a plot into ``out`` (atomically)."""
    import pandas as pd

    with atomic_directory(out) as tmp:
        tmp = Path(tmp)
        pd.DataFrame(rows).to_csv(tmp / f"{kind}.csv", index=False)
        (tmp / f"{kind}.json").write_text(dumps(rows))
        if kind == "coupling":
            cols = ["scene", "coupling", "steps_per_revolution", "mean_efficiency", "error",
                    "observed_order", "wall_time_s", "newton_iterations",
                    "friction_evaluations_per_step", "status"]
            _plot_coupling(rows, tmp / "coupling.png")
        else:
            cols = ["scene", "sign_band_m_s", "mean_efficiency", "change_from_smallest_positive_band",
                    "mean_instantaneous_efficiency", "status"]
            _plot_band(rows, tmp / "sign_band.png")
        (tmp / f"{kind}.md").write_text(_markdown(rows, cols) + "\n")
    return Path(out)


COUPLING_DEFAULT = {"names": ["paper-10deg", "paper-30deg"], "ladder": [100, 200, 400, 800, 1600]}
COUPLING_QUICK = {"names": ["paper-10deg"], "ladder": [100, 200, 400]}
BAND_DEFAULT = {"names": ["paper-0deg", "paper-10deg"],
                "bands": [0.0, 1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1]}
BAND_QUICK = {"names": ["paper-0deg"], "bands": [0.0, 1e-6, 1e-3, 1e-1]}


def main_study(kind: str, out: str | None, quick: bool, as_json: bool) -> int:
    import sys

    def progress(msg: str) -> None:
        print(f"  {msg}", file=sys.stderr, flush=True)

    if kind == "coupling":
        spec = COUPLING_QUICK if quick else COUPLING_DEFAULT
        rows = coupling_study(spec["names"], spec["ladder"], progress=progress)
        cols = ["scene", "coupling", "steps_per_revolution", "mean_efficiency", "error",
                "observed_order", "wall_time_s", "friction_evaluations_per_step"]
    else:
        spec = BAND_QUICK if quick else BAND_DEFAULT
        rows = sign_band_study(spec["names"], spec["bands"], progress=progress)
        cols = ["scene", "sign_band_m_s", "mean_efficiency", "change_from_smallest_positive_band"]
    if out:
        write_study(kind, rows, out)
        progress(f"wrote {out}")
    if as_json:
        print(dumps(rows))
    else:
        print(_markdown(rows, cols))
    return 0 if all(r["status"] == "ok" for r in rows) else 3
