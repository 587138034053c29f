"""Numerical studies of the friction model: coupling schemes against step size, and the sign band.

``python tests/benchmarks coupling``: for each scene and each coupling scheme (lagged, converged), the mean
efficiency at a ladder of step sizes, its error against a run of the converged scheme with a
step four times finer than the finest of the ladder, the observed order between neighbouring
steps, and the cost (wall time, Newton iterations, friction evaluations per step), measured side
by side in one process.

``python tests/benchmarks sign-band``: the mean efficiency at 0 and 10 deg against the width of the
regularised sign, from far below the numerical noise of the relative speeds to far above it.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.arguments import EXIT_FAILED, EXIT_OK, out_folder
from cardan_exudyn.engines import run
from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table
from reference.paper import named_scene
from reference.results.summary import Status
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["COUPLING_DEFAULT", "COUPLING_QUICK", "BAND_DEFAULT", "BAND_QUICK", "efficiency_row",
           "step", "coupling_study", "ladder_rows", "sign_band_study", "run_study", "markdown",
           "plot_coupling", "plot_band", "write_study", "register", "handler"]

Progress = Callable[[str], None]

COUPLING_DEFAULT = {"names": ["paper-literal-10deg", "paper-literal-30deg"], "ladder": [100, 200, 400, 800,
                                                                                        1600]}
COUPLING_QUICK = {"names": ["paper-literal-10deg"], "ladder": [100, 200, 400]}
BAND_DEFAULT = {"names": ["paper-literal-0deg", "paper-literal-10deg"],
                "bands": [0.0, 1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1]}
BAND_QUICK = {"names": ["paper-literal-0deg"], "bands": [0.0, 1e-6, 1e-3, 1e-1]}

# columns of the printed table and of the markdown file, per study
PRINTED = {"coupling": ["scene", "coupling", "steps_per_revolution", "mean_efficiency", "error",
                        "observed_order", "wall_time_s", "friction_evaluations_per_step"],
           "sign-band": ["scene", "sign_band_m_s", "mean_efficiency",
                         "change_from_smallest_positive_band"]}
WRITTEN = {"coupling": ["scene", "coupling", "steps_per_revolution", "mean_efficiency", "error",
                        "observed_order", "wall_time_s", "newton_iterations",
                        "friction_evaluations_per_step", "status"],
           "sign-band": ["scene", "sign_band_m_s", "mean_efficiency",
                         "change_from_smallest_positive_band", "mean_instantaneous_efficiency",
                         "status"]}
FLOAT_COLUMNS = ("dt", "mean_efficiency", "mean_instantaneous_efficiency", "error", "observed_order",
                 "wall_time_s", "friction_evaluations_per_step", "reference", "sign_band_m_s",
                 "change_from_smallest_positive_band")
FORMATS = {c: ".6g" for c in FLOAT_COLUMNS}


def _value(value: float | None) -> float:
    return float("nan") if value is None else float(value)


def efficiency_row(scene: Scene) -> dict[str, Any]:
    """Run ``scene`` with Exudyn: status, reason, wall time [s], steps, Newton iterations, mean
    and mean instantaneous efficiency [-] (NaN unless ok), friction evaluations per step."""
    start = time.perf_counter()
    result = run(replace(scene, **{"record.timeseries": False}), "exudyn")
    wall = time.perf_counter() - start
    s = result.summary
    out = {"status": s.status.value, "reason": s.reason, "wall_time_s": wall, "steps": s.steps,
           "newton_iterations": s.newton_iterations, "mean_efficiency": _value(s.mean_efficiency),
           "mean_instantaneous_efficiency": _value(s.mean_instantaneous_efficiency)}
    if s.friction is not None:
        out["friction_evaluations_per_step"] = s.friction.mean_iterations_per_step
    return out


def step(scene: Scene, steps_per_revolution: int) -> float:
    """The time step [s] that makes ``steps_per_revolution`` steps per input revolution."""
    return 2.0 * math.pi / abs(scene.drive.speed) / steps_per_revolution


def coupling_study(names: Sequence[str], ladder: Sequence[int], revolutions: float = 1.0,
                   progress: Progress | None = None) -> list[dict[str, Any]]:
    """Rows (scene, coupling, steps/rev, dt [s], efficiency, error, order, cost) for every
    combination of scene, coupling scheme and step of the ``ladder`` (steps per revolution)."""
    rows = []
    for name in names:
        # the absolute 1 mm/s band: a ramp the ladder resolves (0.02 rad of input angle at 10 deg,
        # 2000 rpm), so the order measured is the coupling's; across the default relative ramp,
        # 10 times narrower, every scheme is first order up to ~18,000 steps per revolution
        base = replace(named_scene(name), revolutions=revolutions, **{"friction.sign_band": 1e-3})
        fine = 4 * max(ladder)
        if progress:
            progress(f"{name}: reference run, converged, {fine} steps per revolution")
        ref = efficiency_row(replace(base, **{"friction.coupling": "converged",
                                              "numerics.dt": step(base, fine)}))
        reference = {"reference": ref["mean_efficiency"], "reference_steps_per_revolution": fine}
        for coupling in ("lagged", "converged"):
            rows += ladder_rows(name, base, coupling, ladder, reference, progress)
    return rows


def ladder_rows(name: str, base: Scene, coupling: str, ladder: Sequence[int],
                reference: Mapping[str, Any], progress: Progress | None) -> list[dict[str, Any]]:
    """One coupling scheme over the ladder: the error against ``reference["reference"]`` (the
    fine converged run's mean efficiency) and the observed order between neighbouring steps."""
    rows: list[dict[str, Any]] = []
    previous = None
    for n in ladder:
        if progress:
            progress(f"{name}: {coupling}, {n} steps per revolution")
        scene = replace(base, **{"friction.coupling": coupling, "numerics.dt": step(base, n)})
        r = efficiency_row(scene)
        error = r["mean_efficiency"] - reference["reference"]
        order = float("nan")
        if previous is not None and error != 0.0 and previous[1] != 0.0:
            order = math.log(abs(previous[1] / error)) / math.log(n / previous[0])
        rows.append({"scene": name, "coupling": coupling, "steps_per_revolution": n,
                     "dt": scene.numerics.dt, **r, **reference, "error": error,
                     "observed_order": order})
        previous = (n, error)
    return rows


def sign_band_study(names: Sequence[str], bands: Sequence[float], revolutions: float = 1.0,
                    progress: Progress | None = None) -> list[dict[str, Any]]:
    """Mean efficiency [-] against the sign band [m/s], for each scene (converged coupling), with
    its change from the smallest positive band's."""
    rows = []
    for name in names:
        base = replace(named_scene(name), revolutions=revolutions)
        scene_rows = []
        for band in bands:
            if progress:
                progress(f"{name}: sign band {band:g} m/s")
            r = efficiency_row(replace(base, **{"friction.sign_band": band}))
            scene_rows.append({"scene": name, "sign_band_m_s": band, **r})
        ref = next((r["mean_efficiency"] for r in scene_rows
                    if r["status"] == Status.OK and r["sign_band_m_s"] > 0), float("nan"))
        for r in scene_rows:
            r["change_from_smallest_positive_band"] = r["mean_efficiency"] - ref
        rows += scene_rows
    return rows


def run_study(kind: str, quick: bool = False, progress: Progress | None = None) -> list[dict[str, Any]]:
    """The rows of the study ``kind`` (``coupling`` or ``sign-band``), at the default or the
    quick (``quick``) scenes and ladder."""
    if kind == "coupling":
        spec = COUPLING_QUICK if quick else COUPLING_DEFAULT
        return coupling_study(spec["names"], spec["ladder"], progress=progress)
    if kind == "sign-band":
        spec = BAND_QUICK if quick else BAND_DEFAULT
        return sign_band_study(spec["names"], spec["bands"], progress=progress)
    raise ValueError(f"`kind` must be 'coupling' or 'sign-band', got {kind!r}")


def markdown(rows: Sequence[Mapping[str, Any]], columns: Sequence[str]) -> str:
    """``rows`` as a markdown table (a failed run's missing numbers as '-')."""
    return markdown_table(rows, columns, FORMATS)


def plot_coupling(rows: Sequence[Mapping[str, Any]], path: Path) -> None:
    """Error of mean efficiency against steps per revolution and against wall time, log-log."""
    # import cost: matplotlib only when a study is written
    from cardan_exudyn.report.plots import plt, save

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    ok = [r for r in rows if r["status"] == Status.OK]
    for name in sorted({r["scene"] for r in rows}):
        for coupling, marker in (("lagged", "s--"), ("converged", "o-")):
            sel = [r for r in ok if r["scene"] == name and r["coupling"] == coupling]
            if not sel:
                continue
            err = [max(abs(r["error"]), 1e-16) for r in sel]
            axes[0].loglog([r["steps_per_revolution"] for r in sel], err, marker, label=f"{name} {coupling}")
            axes[1].loglog([r["wall_time_s"] for r in sel], err, marker, label=f"{name} {coupling}")
    n_ref = np.array(sorted({r["steps_per_revolution"] for r in rows}), dtype=float)
    if n_ref.size:
        top = max(abs(r["error"]) for r in ok)
        axes[0].loglog(n_ref, top * (n_ref[0] / n_ref), "k:", lw=0.8, label="first order")
        axes[0].loglog(n_ref, top * (n_ref[0] / n_ref) ** 2, "k-.", lw=0.8, label="second order")
    axes[0].set(xlabel="steps per input revolution", ylabel="|error of mean efficiency|",
                title="error against step size")
    axes[1].set(xlabel="wall time per run [s]", ylabel="|error of mean efficiency|",
                title="error against cost")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    save(fig, path, dpi=120)


def plot_band(rows: Sequence[Mapping[str, Any]], path: Path) -> None:
    """Mean efficiency against the sign band, one line per scene."""
    # import cost: matplotlib only when a study is written
    from cardan_exudyn.report.plots import plt, save

    fig, ax = plt.subplots(figsize=(6, 4))
    for name in sorted({r["scene"] for r in rows}):
        sel = [r for r in rows if r["scene"] == name and r["status"] == Status.OK]
        ax.semilogx([r["sign_band_m_s"] for r in sel], [r["mean_efficiency"] for r in sel],
                    "o-", label=name)
    ax.set_xlabel("sign band (surface speed) [m/s]")
    ax.set_ylabel("mean efficiency")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save(fig, path, dpi=120)


def write_study(kind: str, rows: Sequence[Mapping[str, Any]], out: str | Path) -> Path:
    """Write ``rows`` as CSV, JSON, a markdown table and a plot into ``out`` (atomically)."""
    import pandas as pd  # import cost: pandas when a study is written

    plot = plot_coupling if kind == "coupling" else plot_band
    with atomic_directory(out) as tmp:
        tmp = Path(tmp)
        pd.DataFrame(rows).to_csv(tmp / f"{kind}.csv", index=False)
        (tmp / f"{kind}.json").write_text(dumps(rows))
        plot(rows, tmp / ("coupling.png" if kind == "coupling" else "sign_band.png"))
        (tmp / f"{kind}.md").write_text(markdown(rows, WRITTEN[kind]))
    return Path(out)


HELP = {"coupling": "error of mean efficiency against step size for the lagged and converged "
                    "friction couplings",
        "sign-band": "mean efficiency against the width of the regularised sign"}


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add the study ``name`` (``coupling`` or ``sign-band``) to the benchmarks' subcommands."""
    p = subparsers.add_parser(name, help=HELP[name], description=HELP[name])
    p.add_argument("--out", metavar="DIR", help="write CSV, JSON, markdown and a plot here")
    p.add_argument("--quick", action="store_true", help="one scene, a short ladder")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=handler, kind=name)


def handler(args: argparse.Namespace) -> int:
    """Run the study ``args.kind``: exit 0 when every run ended ok, 3 otherwise."""
    out_folder(args.out)
    rows = run_study(args.kind, args.quick, progress=_say)
    if args.out:
        write_study(args.kind, rows, args.out)
        _say(f"wrote {args.out}")
    if args.json:
        print(dumps(rows))
    else:
        print(markdown(rows, PRINTED[args.kind]), end="")
    return EXIT_OK if all(r["status"] == Status.OK for r in rows) else EXIT_FAILED


def _say(message: str) -> None:
    """A progress line on stderr."""
    print(f"  {message}", file=sys.stderr, flush=True)
