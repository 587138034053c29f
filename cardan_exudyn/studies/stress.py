"""``cardan stress``: where the Exudyn model stops giving the right answer, and why.

The stability map
-----------------
Panels of cells over shaft angle (0 to 80 deg) against one more quantity each: the friction
coefficient (0 to 1, the same in all four pairs) for each coupling scheme and node type, the input
speed (10 to 10,000 rpm) and the step (steps per input revolution). Every cell is one revolution
of the paper's scene (table 1 bodies, 2 N m load) from the assembled start at constant input
speed, run by the reference engine and by Exudyn at the cell's step ``h`` and at ``h / 2``. The
runs go through the sweep runner (:mod:`cardan_exudyn.sweep.runner`, one sweep per node type in
``OUT/runs/``), so an interrupted map resumes where it stopped.

A cell is classified from its measurements alone (:func:`classify`):

``converged``
    Exudyn's status is ok and its answer is within what the step promises: the largest error of
    ``omega_out / omega_in`` against Hooke's closed form is at most ``SAFETY * K(beta) h^2 +
    RATIO_FLOOR`` (the a-priori error model of :mod:`cardan_exudyn.model.stepsize`), the mean
    efficiency is within ``SAFETY * 2^p / (2^p - 1) |eta_h - eta_h/2| + EFFICIENCY_FLOOR`` of the
    reference's (the step-halving estimate of an error of order ``p``: 2 with the converged
    friction coupling, 1 with the lagged one, as ``cardan study coupling`` measures), it lies in
    [0, 1], and the pair constraints hold to ``CONSTRAINT_LIMIT``.
``drift``
    Exudyn's status is ok but one of those checks fails: an answer that looks valid and is not.
``self_locking``
    Exudyn stopped the run because its friction fixed point does not converge (the engine's
    detection, :mod:`cardan_exudyn.model.coupling`).
``integration_failure``
    Newton or the integrator failed (or the run diverged, ended early).
``error``
    The harness raised (a bug; the record keeps the traceback).

The reference's verdict is physical: ``self_locking`` when its friction fixed point has no
solution at some instant of the revolution (loop gain >= 1, :mod:`reference.dynamics`), else ok.
Exudyn's failure boundary (self_locking or integration_failure) is compared with it cell by cell;
:func:`classify` names the category of every disagreement, and ``docs/stress.md`` explains them.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from reference.engine import ReferenceOptions
from reference.engine import run as reference_run
from reference.kinematics import speed_ratio
from reference.paper import named_scene
from reference.scene import DEG, PAIR_NAMES, RPM, Scene, replace

BASE_SCENE = "paper-10deg-2000rpm"
REVOLUTIONS = 1.0
DEFAULT_STEPS = 200          # steps per input revolution of the panels that do not vary it
DEFAULT_RPM = 2000.0
PANEL_FRICTION = 0.2         # friction coefficient of the speed and step panels

SAFETY = 3.0                 # factor on the promised error
RATIO_FLOOR = 1e-8           # speed-ratio error the Newton tolerance leaves at zero shaft angle
EFFICIENCY_FLOOR = 1e-4      # efficiency difference below which the engines count as equal
CONSTRAINT_LIMIT = 1e-6      # [m] and [rad]: pair constraints of an index-3 solve hold far better
ORDER = {"converged": 2, "lagged": 1}  # convergence order of the mean efficiency in the step
REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=72, quadrature_rtol=1e-8)

CLASSES = ("converged", "drift", "self_locking", "integration_failure", "error")
EXUDYN_FAILURES = ("integration_failure", "diverged", "incomplete", "no_whole_revolution",
                   "loop_does_not_close")


class StressError(ValueError):
    """Bad input to the stress command (unknown part, bad output folder)."""


# ------------------------------------------------------------------------------------ panels
@dataclass(frozen=True)
class Panel:
    """One 2-D slice of the map: shaft angle (rows) against ``x`` (columns)."""

    key: str
    title: str
    x: str                         # "friction", "rpm" or "steps"
    x_values: tuple[float, ...]
    angles: tuple[float, ...]      # [deg]
    node_type: str = "Rxyz"
    coupling: str = "converged"
    friction: float = PANEL_FRICTION
    rpm: float = DEFAULT_RPM
    steps: int = DEFAULT_STEPS

    def cell(self, angle: float, x: float) -> dict[str, Any]:
        """The cell's settings: shaft angle [deg], friction, rpm, steps per revolution."""
        values = {"angle_deg": angle, "friction": self.friction, "rpm": self.rpm,
                  "steps": self.steps}
        values[{"friction": "friction", "rpm": "rpm", "steps": "steps"}[self.x]] = x
        values["steps"] = int(values["steps"])
        return values

    def overrides(self, angle: float, x: float) -> dict[str, Any]:
        """Scene overrides (dotted paths) of one cell."""
        c = self.cell(angle, x)
        speed = c["rpm"] * RPM
        out: dict[str, Any] = {
            "joint.geometry.shaft_angle": c["angle_deg"] * DEG,
            "drive": {"kind": "speed", "speed": speed},
            "numerics.dt": 2.0 * math.pi / speed / c["steps"],
            "friction.coupling": self.coupling,
        }
        for pair in PAIR_NAMES:
            out[f"joint.pairs.{pair}.friction_coefficient"] = c["friction"]
        return out


X_LABELS = {"friction": "friction coefficient (all pairs)", "rpm": "input speed [rpm]",
            "steps": "steps per input revolution"}
NODE_TYPES = ("Rxyz", "EP", "RotVecLG")


def panels(quick: bool = False) -> list[Panel]:
    """The map's panels (``quick``: coarser, for CI)."""
    if quick:  # a few cells on each side of the boundaries, incl. one where lagged runs on
        angles, few = (0.0, 10.0, 40.0, 80.0), (0.0, 40.0, 80.0)
        friction = (0.0, 0.2, 0.6)
        return [
            Panel("friction", "converged coupling, Rxyz", "friction", friction, angles),
            Panel("lagged", "lagged coupling, Rxyz", "friction", friction, angles, coupling="lagged"),
            Panel("ep", "converged, Euler parameters", "friction", (0.0, 0.2), few, node_type="EP"),
            Panel("rotveclg", "converged, rotation vector (Lie group)", "friction", (0.0, 0.2),
                  few, node_type="RotVecLG"),
            Panel("speed", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "rpm", (10.0, 10000.0), few),
            Panel("steps", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "steps", (25.0, 200.0), few),
        ]
    angles = tuple(float(a) for a in range(0, 81, 10))
    friction = (0.0, 0.05, 0.1, 0.2, 0.3, 0.42, 0.6, 0.8, 1.0)
    return [
        Panel("friction", "converged coupling, Rxyz", "friction", friction, angles),
        Panel("lagged", "lagged coupling, Rxyz", "friction", friction, angles, coupling="lagged"),
        Panel("ep", "converged, Euler parameters", "friction", friction, angles, node_type="EP"),
        Panel("rotveclg", "converged, rotation vector (Lie group)", "friction", friction, angles,
              node_type="RotVecLG"),
        Panel("speed", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "rpm",
              (10.0, 100.0, 500.0, 2000.0, 5000.0, 10000.0), angles),
        Panel("steps", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "steps",
              (12.0, 25.0, 50.0, 100.0, 200.0, 400.0, 800.0), angles),
    ]


def base_scene() -> Scene:
    return replace(named_scene(BASE_SCENE), **{"revolutions": REVOLUTIONS,
                                               "record.skip_revolutions": 0.0})


def cell_id(panel: Panel, angle: float, x: float) -> str:
    return f"{panel.key}/{angle:g}deg/{panel.x}={x:g}"


# --------------------------------------------------------------------------- one cell's runs
def measure_cell(scene: Scene, node_type: str) -> dict[str, Any]:
    """Run the reference and Exudyn (at ``h`` and, when it is ok with friction, ``h / 2``) on
    one cell's scene and return the raw measurements (flat scalars)."""
    from cardan_exudyn.model.solve import ExudynOptions
    from cardan_exudyn.model.solve import run as exudyn_run

    out: dict[str, Any] = {}
    ref = reference_run(replace(scene, **{"record.timeseries": False}), REFERENCE_OPTIONS).summary
    out.update(ref_status=ref["status"], ref_reason=str(ref.get("reason") or ""),
               ref_efficiency=ref.get("mean_efficiency"),
               ref_loop_gain_max=ref.get("max_friction_loop_gain"))
    options = ExudynOptions(node_type=node_type)
    result = exudyn_run(scene, options)
    s = result.summary
    friction = s.get("friction") or {}
    out.update(exu_status=s["status"], exu_reason=str(s.get("reason") or "")[:300],
               exu_efficiency=s.get("mean_efficiency"),
               exu_loop_gain_max=friction.get("loop_gain_estimate_max"),
               exu_steps=s.get("steps"), exu_newton_iterations=s.get("newton_iterations"),
               exu_wall_s=s.get("wall_time_s"),
               constraint_violation_m=s.get("max_constraint_violation_m"),
               constraint_violation_rad=s.get("max_constraint_violation_rad"))
    beta = scene.joint.geometry.shaft_angle
    h = scene.drive.speed * scene.numerics.dt
    from cardan_exudyn.model.stepsize import error_coefficient

    out["ratio_promise"] = SAFETY * error_coefficient(beta, node_type) * h * h + RATIO_FLOOR
    if result.table is not None and len(result.table):
        t = result.table
        ratio = t["omega_out"].to_numpy() / t["omega_in"].to_numpy()
        err = np.abs(ratio - speed_ratio(t["theta_in"].to_numpy(), beta))
        out["ratio_error"] = float(np.max(err)) if np.all(np.isfinite(err)) else None
    if s["status"] == "ok" and scene.has_friction:
        half = exudyn_run(replace(scene, **{"numerics.dt": scene.numerics.dt / 2,
                                            "record.timeseries": False}), options).summary
        out.update(half_status=half["status"], exu_efficiency_half=half.get("mean_efficiency"))
    return out


def _cell(scene: Scene, engine: str, node_type: str) -> dict[str, Any]:
    if engine != "exudyn":
        raise ValueError(f"stress cells compare Exudyn with the reference; engine {engine!r}")
    return measure_cell(scene, node_type)


def cell_rxyz(scene: Scene, engine: str) -> dict[str, Any]:
    """Sweep case function: one map cell with Rxyz nodes."""
    return _cell(scene, engine, "Rxyz")


def cell_ep(scene: Scene, engine: str) -> dict[str, Any]:
    """Sweep case function: one map cell with Euler-parameter nodes."""
    return _cell(scene, engine, "EP")


def cell_rotveclg(scene: Scene, engine: str) -> dict[str, Any]:
    """Sweep case function: one map cell with Lie-group rotation-vector nodes."""
    return _cell(scene, engine, "RotVecLG")


CELL_FUNCTIONS = {"Rxyz": "cardan_exudyn.studies.stress:cell_rxyz", "EP": "cardan_exudyn.studies.stress:cell_ep",
                  "RotVecLG": "cardan_exudyn.studies.stress:cell_rotveclg"}


# ----------------------------------------------------------------------------- classification
def _num(value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return float("nan")
    return v


def efficiency_promise(record: dict[str, Any]) -> float:
    """``SAFETY * 2^p / (2^p - 1) |eta_h - eta_h/2| + EFFICIENCY_FLOOR`` with the order ``p`` of
    the record's ``coupling`` (NaN without a halved run)."""
    a, b = _num(record.get("exu_efficiency")), _num(record.get("exu_efficiency_half"))
    if record.get("half_status") != "ok" or not (math.isfinite(a) and math.isfinite(b)):
        return float("nan")
    p = ORDER[record.get("coupling", "converged")]
    return SAFETY * 2.0**p / (2.0**p - 1.0) * abs(a - b) + EFFICIENCY_FLOOR


def classify(record: dict[str, Any]) -> dict[str, Any]:
    """Class, agreement with the reference's physics, category and a one-line explanation of
    one cell from its measurements (a record of :func:`measure_cell`, or a harness error)."""
    if record.get("status", "ok") != "ok":  # the case function raised
        return {"cell_class": "error", "reference": "unknown", "agrees": False,
                "category": "harness error", "explanation": str(record.get("reason"))[:200]}
    ref, exu = record.get("ref_status"), record.get("exu_status")
    ref_locks = ref == "self_locking"
    g_ref = _num(record.get("ref_loop_gain_max"))
    g_exu = _num(record.get("exu_loop_gain_max"))
    eta, eta_ref = _num(record.get("exu_efficiency")), _num(record.get("ref_efficiency"))
    reasons = []
    if exu == "ok":
        ratio_err, ratio_promise = _num(record.get("ratio_error")), _num(record.get("ratio_promise"))
        if not ratio_err <= ratio_promise:
            reasons.append(f"speed-ratio error {ratio_err:.2g} > promised {ratio_promise:.2g}")
        if not 0.0 <= eta <= 1.0:
            reasons.append(f"mean efficiency {eta:.4g} outside [0, 1]")
        for key, unit in (("constraint_violation_m", "m"), ("constraint_violation_rad", "rad")):
            v = _num(record.get(key))
            if not v <= CONSTRAINT_LIMIT:
                reasons.append(f"constraint violation {v:.2g} {unit} > {CONSTRAINT_LIMIT:g}")
        if ref == "ok":
            promise = efficiency_promise(record)
            if not math.isfinite(promise):  # frictionless, or the halved run failed
                promise = EFFICIENCY_FLOOR
            if not abs(eta - eta_ref) <= promise:
                reasons.append(f"efficiency {eta:.4f} vs reference {eta_ref:.4f}: "
                               f"|error| {abs(eta - eta_ref):.2g} > promised {promise:.2g}")
        cls = "drift" if reasons or ref_locks else "converged"
    elif exu == "self_locking":
        cls = "self_locking"
    elif exu in EXUDYN_FAILURES:
        cls = "integration_failure"
    else:
        cls = "integration_failure"
        reasons.append(f"unexpected status {exu!r}")
    reference = "self_locking" if ref_locks else ("ok" if ref == "ok" else f"failed ({ref})")
    exu_reason = str(record.get("exu_reason") or "")[:120]
    if ref not in ("ok", "self_locking"):
        return {"cell_class": cls, "reference": reference, "agrees": False,
                "category": "reference failed",
                "explanation": f"reference {ref}: {str(record.get('ref_reason'))[:120]}"}
    if not ref_locks:
        if cls == "converged":
            return {"cell_class": cls, "reference": reference, "agrees": True, "category": "agree: ok",
                    "explanation": ""}
        if cls == "drift":
            return {"cell_class": cls, "reference": reference, "agrees": False,
                    "category": "wrong answer with status ok", "explanation": "; ".join(reasons)}
        if cls == "self_locking":
            return {"cell_class": cls, "reference": reference, "agrees": False,
                    "category": "Exudyn locks, the reference does not",
                    "explanation": f"reference loop gain max {g_ref:.3g} < 1; Exudyn: {exu_reason}"}
        return {"cell_class": cls, "reference": reference, "agrees": False,
                "category": "numerical failure in a physically valid cell",
                "explanation": f"Exudyn {exu}: {exu_reason}"}
    # the reference's friction fixed point has no solution: the joint self-locks
    if cls == "self_locking":
        return {"cell_class": cls, "reference": reference, "agrees": True,
                "category": "agree: self-locking", "explanation": ""}
    if cls == "integration_failure":
        return {"cell_class": cls, "reference": reference, "agrees": True,
                "category": "agree: fails where the joint locks",
                "explanation": f"Exudyn {exu} instead of a self-locking verdict: {exu_reason}"}
    return {"cell_class": cls, "reference": reference, "agrees": False,
            "category": "runs on through a physical self-lock",
            "explanation": (f"reference self-locks ({str(record.get('ref_reason'))[:80]}); Exudyn "
                            f"ok with efficiency {eta:.4g}"
                            + (f", loop gain estimate max {g_exu:.3g}" if math.isfinite(g_exu) else "")
                            + (f"; {'; '.join(reasons)}" if reasons else ""))}


# ------------------------------------------------------------------------------------ the map
@dataclass
class StressMap:
    """The classified cells (one row each) and how they were obtained."""

    cells: pd.DataFrame
    panels: list[Panel]
    quick: bool
    sweeps: dict[str, dict[str, Any]] = field(default_factory=dict)

    def counts(self) -> dict[str, Any]:
        c = self.cells
        return {
            "cells": int(len(c)),
            "classes": {k: int(v) for k, v in c["cell_class"].value_counts().items()},
            "reference_self_locking": int((c["reference"] == "self_locking").sum()),
            "disagreements": int((~c["agrees"]).sum()),
            "categories": {k: int(v) for k, v in c["category"].value_counts().items()},
        }


def sweep_specs(quick: bool = False) -> dict[str, Any]:
    """One explicit-case sweep spec per node type (the map's panels grouped by node type)."""
    from cardan_exudyn.sweep.runner import SweepSpec

    base = base_scene()
    groups: dict[str, list[dict[str, Any]]] = {}
    for panel in panels(quick):
        for angle in panel.angles:
            for x in panel.x_values:
                groups.setdefault(panel.node_type, []).append(
                    {"id": cell_id(panel, angle, x), **panel.overrides(angle, x)})
    return {node: SweepSpec(scene=base, engine="exudyn", cases=tuple(cases),
                            function=CELL_FUNCTIONS[node])
            for node, cases in groups.items()}


def run_map(runs: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
            restart: bool = False, progress: bool | None = None) -> StressMap:
    """Run (or resume) the map's sweeps into ``runs/<node type>/`` and classify every cell."""
    from cardan_exudyn.sweep.runner import CASES_FILE, read_records, run_sweep

    runs = Path(runs)
    chosen = panels(quick)
    records: dict[str, dict[str, Any]] = {}
    sweeps = {}
    for node, spec in sweep_specs(quick).items():
        folder = runs / node.lower()
        sweeps[node] = run_sweep(spec, folder, workers=workers, restart=restart,
                                 retry_failed=True, progress=progress)
        records.update(read_records(folder / CASES_FILE))
    rows = []
    for panel in chosen:
        for angle in panel.angles:
            for x in panel.x_values:
                record = {**records[cell_id(panel, angle, x)], "coupling": panel.coupling}
                rows.append({"panel": panel.key, "node_type": panel.node_type,
                             "coupling": panel.coupling, "x_name": panel.x, "x": x,
                             **panel.cell(angle, x), **_measured(record), **classify(record)})
    return StressMap(pd.DataFrame(rows), chosen, quick,
                     {k: {"run_now": v["run_now"], "wall_time_s": v["wall_time_s"],
                          "executor": v["executor"]} for k, v in sweeps.items()})


MEASURED = ("ref_status", "ref_efficiency", "ref_loop_gain_max", "exu_status", "exu_efficiency",
            "exu_efficiency_half", "half_status", "exu_loop_gain_max", "ratio_error",
            "ratio_promise", "constraint_violation_m", "constraint_violation_rad", "exu_steps",
            "exu_newton_iterations", "exu_wall_s", "case_wall_s", "exu_reason", "ref_reason")


def _measured(record: dict[str, Any]) -> dict[str, Any]:
    out = {k: record.get(k) for k in MEASURED}
    out["efficiency_promise"] = efficiency_promise(record)
    eta, ref = _num(record.get("exu_efficiency")), _num(record.get("ref_efficiency"))
    out["efficiency_error"] = abs(eta - ref) if math.isfinite(eta) and math.isfinite(ref) else None
    return out


# -------------------------------------------------------------------------------- reporting
SYMBOLS = {"converged": "C", "drift": "D", "self_locking": "L", "integration_failure": "F",
           "error": "E"}


def _class_mark(r: pd.Series) -> str:
    return (SYMBOLS[r["cell_class"]] + ("*" if r["reference"] == "self_locking" else "")
            + ("!" if not r["agrees"] else ""))


def _error_mark(r: pd.Series) -> str:
    err, promise = _num(r["efficiency_error"]), _num(r["efficiency_promise"])
    if not math.isfinite(err):
        return _class_mark(r)
    return f"{err:.1e}" + (f" ({promise:.0e})" if math.isfinite(promise) else "")


def panel_table(cells: pd.DataFrame, panel: Panel, mark: Callable[[pd.Series], str] = _class_mark) -> str:
    """Markdown grid of one panel, one ``mark(row)`` per cell (default: class letter, ``*``
    where the reference self-locks, ``!`` where Exudyn and the reference disagree)."""
    sel = cells[cells["panel"] == panel.key]
    head = "| angle \\ " + X_LABELS[panel.x] + " | " + " | ".join(f"{x:g}" for x in panel.x_values) + " |"
    lines = [head, "|" + "---|" * (len(panel.x_values) + 1)]
    for angle in panel.angles:
        row = sel[sel["angle_deg"] == angle].set_index("x")
        lines.append(f"| {angle:g} deg | " + " | ".join(mark(row.loc[x]) for x in panel.x_values) + " |")
    return "\n".join(lines)


def markdown(stress: StressMap) -> str:
    """The map's report section: legend, one grid per panel, every disagreement listed."""
    c = stress.cells
    counts = stress.counts()
    parts = [
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
    for panel in stress.panels:
        parts += [f"### {panel.key}: shaft angle x {X_LABELS[panel.x]} ({panel.title})", "",
                  panel_table(c, panel), ""]
        if panel.x in ("rpm", "steps"):
            parts += ["Mean-efficiency error against the reference (promised error in brackets; "
                      "the class where there is no efficiency):", "",
                      panel_table(c, panel, _error_mark), ""]
    parts += ["### Agreement with the reference's self-locking boundary", "",
              "| category | cells |", "|---|---|"]
    parts += [f"| {k} | {v} |" for k, v in counts["categories"].items()]
    bad = c[~c["agrees"]]
    if len(bad):
        parts += ["", "### Every disagreement", "",
                  "| panel | angle [deg] | x | Exudyn | reference | category | explanation |",
                  "|---|---|---|---|---|---|---|"]
        for _, r in bad.iterrows():
            expl = str(r["explanation"]).replace("|", "/")
            parts.append(f"| {r['panel']} | {r['angle_deg']:g} | {r['x_name']}={r['x']:g} | "
                         f"{r['cell_class']} | {r['reference']} | {r['category']} | {expl} |")
    parts += ["", "Why each category happens: `docs/stress.md`.", ""]
    return "\n".join(parts)


def plot_map(stress: StressMap):
    """One image per panel: cell colour = class, hatched = reference self-locks, ``!`` =
    disagreement; the reference's self-locking boundary drawn as a black line."""
    from cardan_exudyn.report import plots

    return plots.stability_map(stress.cells, [
        {"key": p.key, "title": p.title, "x": p.x, "x_label": X_LABELS[p.x],
         "x_values": p.x_values, "angles": p.angles} for p in stress.panels], CLASSES)


# ------------------------------------------------------------------------------- the command
PARTS = ("map", "long", "inputs")


@dataclass
class StressReport:
    map: StressMap | None = None
    long: Any = None
    inputs: pd.DataFrame | None = None
    wall_s: dict[str, float] = field(default_factory=dict)

    def problems(self) -> list[str]:
        """What makes the command exit 3: harness errors in the map, a bad input not rejected
        as expected, a long-run check over its stated tolerance."""
        out = []
        if self.map is not None:
            n = int((self.map.cells["cell_class"] == "error").sum())
            if n:
                out.append(f"{n} map cells raised in the harness")
        if self.inputs is not None:
            failed = self.inputs[~self.inputs["passed"].astype(bool)]
            out += [f"bad input {r['id']}: {r['problems']}" for _, r in failed.iterrows()]
        if self.long is not None:
            out += [f"long run: {c['check']} ({c['subject']}) failed"
                    for c in self.long.summary.get("checks", []) if not c["pass"]]
        return out

    def summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {"wall_s": self.wall_s, "problems": self.problems()}
        if self.map is not None:
            out["map"] = {**self.map.counts(), "quick": self.map.quick, "sweeps": self.map.sweeps}
        if self.long is not None:
            out["long"] = self.long.summary
        if self.inputs is not None:
            out["inputs"] = {"cases": int(len(self.inputs)),
                             "passed": int(self.inputs["passed"].astype(bool).sum())}
        return out


def parse_parts(text: str | None) -> tuple[str, ...]:
    if text is None:
        return PARTS
    parts = tuple(p.strip() for p in text.split(",") if p.strip())
    unknown = sorted(set(parts) - set(PARTS))
    if unknown or not parts:
        raise StressError(f"--only must be a comma-separated subset of {list(PARTS)}, got {text!r}")
    return parts


def run_stress(out: str | os.PathLike, *, quick: bool = False, parts: Sequence[str] = PARTS,
               workers: int | None = None, restart: bool = False,
               progress: bool | None = None, say: Callable[[str], None] | None = None) -> StressReport:
    """Run the chosen parts and write the report folder ``out`` atomically (the map's sweeps
    live in ``out/runs`` and are kept, so a rerun resumes)."""
    import time

    from cardan_exudyn.io import atomic_directory

    say = say or (lambda text: None)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise StressError(f"--out {str(out)!r} exists and is not a folder")
    runs = out / "runs"
    report = StressReport()
    if "map" in parts:
        t0 = time.perf_counter()
        say("stability map ...")
        report.map = run_map(runs, quick, workers=workers, restart=restart, progress=progress)
        report.wall_s["map"] = time.perf_counter() - t0
    if "long" in parts:
        from cardan_exudyn.studies.longrun import long_runs

        t0 = time.perf_counter()
        say("long runs ...")
        report.long = long_runs(quick=quick, progress=say)
        report.wall_s["long"] = time.perf_counter() - t0
    if "inputs" in parts:
        import tempfile

        from cardan_exudyn.hardening import run_cases

        t0 = time.perf_counter()
        say("bad inputs ...")
        with tempfile.TemporaryDirectory(prefix="cardan-stress-") as work:
            report.inputs = run_cases(Path(work))
        report.wall_s["inputs"] = time.perf_counter() - t0
    with atomic_directory(out) as folder:
        write_report(report, folder, quick)
        if runs.exists():
            os.replace(runs, folder / "runs")
    return report


def write_report(report: StressReport, folder: Path, quick: bool) -> None:
    from cardan_exudyn.report import plots
    from cardan_exudyn.io import dumps
    from cardan_exudyn.sweep.runner import environment

    env = environment()
    sections = [f"# Stress report{' (--quick)' if quick else ''}", "",
                f"{env['date']}, commit `{env['commit']}`, {env['cpu']} ({env['cpu_count']} logical "
                f"CPUs), exudyn {env['packages'].get('exudyn')}; wall time " + ", ".join(
                    f"{k} {v:.1f} s" for k, v in report.wall_s.items()) + ".", ""]
    problems = report.problems()
    sections += (["**Problems:** " + "; ".join(problems), ""] if problems
                 else ["No problems: no harness errors, every bad input rejected as expected, "
                       "every long-run check within its stated tolerance.", ""])
    if report.map is not None:
        report.map.cells.to_csv(folder / "map_cells.csv", index=False)
        plots.save(plot_map(report.map), folder / "stability_map.png")
        sections += [markdown(report.map), "![stability map](stability_map.png)", ""]
    if report.long is not None:
        from cardan_exudyn.studies.longrun import markdown as long_markdown
        from cardan_exudyn.studies.longrun import write_long

        write_long(report.long, folder)
        sections += [long_markdown(report.long), ""]
    if report.inputs is not None:
        from cardan_exudyn.hardening import markdown as inputs_markdown

        report.inputs.to_csv(folder / "bad_inputs.csv", index=False)
        sections += ["## Bad inputs", "", inputs_markdown(report.inputs), ""]
    (folder / "report.md").write_text("\n".join(sections), encoding="utf-8")
    (folder / "stress.json").write_text(dumps({**report.summary(), "environment": env}) + "\n",
                                        encoding="utf-8")


def print_summary(report: StressReport, out: str, file=sys.stdout) -> None:
    if report.map is not None:
        counts = report.map.counts()
        print("map: " + ", ".join(f"{v} {k}" for k, v in counts["classes"].items())
              + f"; {counts['disagreements']} of {counts['cells']} cells disagree with the "
              f"reference", file=file)
    if report.long is not None:
        checks = report.long.summary.get("checks", [])
        failed = [c for c in checks if not c["pass"]]
        print(f"long runs: {len(checks) - len(failed)} of {len(checks)} checks within their stated "
              f"tolerance" + "".join(f"; FAILED {c['check']} ({c['subject']})" for c in failed),
              file=file)
    if report.inputs is not None:
        n, ok = len(report.inputs), int(report.inputs["passed"].astype(bool).sum())
        print(f"bad inputs: {ok} of {n} rejected as expected", file=file)
    print(f"report: {out}/report.md", file=file)
