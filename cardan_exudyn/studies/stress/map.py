"""The stability map of ``cardan stress``: where the Exudyn model stops giving the right answer, and why.

Panels of cells over shaft angle (0 to 80 deg) against one more quantity each: the friction
coefficient (0 to 1, the same in all four pairs) for each coupling scheme and node type, the input
speed (10 to 10,000 rpm) and the step (steps per input revolution). Every cell is one revolution
of the paper's scene (table 1 bodies, 2 N m load) from the assembled start at constant input
speed, run by the reference engine and by Exudyn at the cell's step ``h`` and at ``h / 2``, all
through :func:`cardan_exudyn.engines.run`. The cells run as sweeps (:mod:`cardan_exudyn.sweep`,
one sweep per node type in ``OUT/runs/``), so an interrupted map resumes where it stopped.

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
    Newton or the integrator failed (or the run diverged, ended early, or its means came out
    impossible: status ``unphysical``, e.g. a mean efficiency outside [0, 1] at too coarse a step).
``error``
    The harness raised (a bug; the record keeps the traceback).

The reference's verdict is physical: ``self_locking`` when its friction fixed point has no
solution at some instant of the revolution (loop gain >= 1, :mod:`reference.engine.dynamics`), else ok.
Exudyn's failure boundary (self_locking or integration_failure) is compared with it cell by cell;
:func:`classify` names the category of every disagreement, and ``docs/stress.md`` explains them.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn.engines import run
from cardan_exudyn.model.stepsize import error_coefficient
from cardan_exudyn.report.format import number
from cardan_exudyn.sweep import CASES_FILE, SweepSpec, read_records, run_sweep
from reference.engine.options import ReferenceOptions
from reference.paper.scenes import named_scene
from reference.physics.kinematics import speed_ratio
from reference.results.summary import Status, Summary
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import DEG, RPM

#: The engine the map tests, and the one it is tested against.
ENGINE, REFERENCE = "exudyn", "reference"
BASE_SCENE = "paper-literal-10deg-2000rpm"
REVOLUTIONS = 1.0
DEFAULT_STEPS = 200          # steps per input revolution of the panels that do not vary it
DEFAULT_RPM = 2000.0
PANEL_FRICTION = 0.2         # friction coefficient of the speed and step panels

SAFETY = 3.0                 # factor on the promised error
RATIO_FLOOR = 1e-8           # speed-ratio error the Newton tolerance leaves at zero shaft angle
EFFICIENCY_FLOOR = 1e-4      # efficiency difference below which the engines count as equal
CONSTRAINT_LIMIT = 1e-6      # [m] and [rad]: pair constraints of an index-3 solve hold far better
ORDER = {"converged": 2, "extrapolated": 2, "lagged": 1}  # order of the mean efficiency in the step
REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=72, quadrature_rtol=1e-8)

CLASSES = ("converged", "drift", "self_locking", "integration_failure", "error")
# statuses of a numerical failure; ``unphysical``: means no run can have (an efficiency outside
# [0, 1] from too coarse a step), caught by the engine instead of reported as ``drift``
EXUDYN_FAILURES = ("integration_failure", "diverged", "incomplete", "no_whole_revolution",
                   "loop_does_not_close", "unphysical")
X_LABELS = {"friction": "friction coefficient (all pairs)", "rpm": "input speed [rpm]",
            "steps": "steps per input revolution"}


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
        values[self.x] = x
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


def panels(quick: bool = False) -> list[Panel]:
    """The map's panels (``quick``: coarser, for CI)."""
    if quick:  # a few cells on each side of the boundaries, incl. one where lagged runs on
        angles, few = (0.0, 10.0, 40.0, 80.0), (0.0, 40.0, 80.0)
        friction = (0.0, 0.2, 0.6)
        return [
            Panel("friction", "converged coupling, Rxyz", "friction", friction, angles),
            Panel("lagged", "lagged coupling, Rxyz", "friction", friction, angles, coupling="lagged"),
            Panel("extrapolated", "extrapolated coupling, Rxyz", "friction", friction, angles,
                  coupling="extrapolated"),
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
        Panel("extrapolated", "extrapolated coupling, Rxyz", "friction", friction, angles,
              coupling="extrapolated"),
        Panel("ep", "converged, Euler parameters", "friction", friction, angles, node_type="EP"),
        Panel("rotveclg", "converged, rotation vector (Lie group)", "friction", friction, angles,
              node_type="RotVecLG"),
        Panel("speed", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "rpm",
              (10.0, 100.0, 500.0, 2000.0, 5000.0, 10000.0), angles),
        Panel("steps", f"f = {PANEL_FRICTION:g}, converged, Rxyz", "steps",
              (12.0, 25.0, 50.0, 100.0, 200.0, 400.0, 800.0), angles),
    ]


def base_scene() -> Scene:
    """:data:`BASE_SCENE` for :data:`REVOLUTIONS` revolution, every revolution averaged."""
    return replace(named_scene(BASE_SCENE), **{"revolutions": REVOLUTIONS,
                                               "record.skip_revolutions": 0.0})


def cell_id(panel: Panel, angle: float, x: float) -> str:
    """The cell's case id in the sweeps, e.g. ``friction/10deg/friction=0.2``."""
    return f"{panel.key}/{angle:g}deg/{panel.x}={x:g}"


def reference_measures(scene: Scene) -> dict[str, Any]:
    """The reference engine's verdict on the cell: status, reason, efficiency, loop gain."""
    s = run(replace(scene, **{"record.timeseries": False}), REFERENCE, REFERENCE_OPTIONS).summary
    return {"ref_status": s.status.value, "ref_reason": str(s.reason or ""),
            "ref_efficiency": s.mean_efficiency, "ref_loop_gain_max": s.max_friction_loop_gain}


def exudyn_measures(s: Summary) -> dict[str, Any]:
    """Exudyn's status, efficiency, friction loop gain, cost and constraint violations."""
    return {"exu_status": s.status.value, "exu_reason": str(s.reason or "")[:300],
            "exu_efficiency": s.mean_efficiency, "exu_loop_gain_max": s.max_friction_loop_gain,
            "exu_steps": s.steps, "exu_newton_iterations": s.newton_iterations,
            "exu_wall_s": s.wall_time_s,
            "constraint_violation_m": s.max_constraint_violation_m,
            "constraint_violation_rad": s.max_constraint_violation_rad}


def ratio_error(table: pd.DataFrame, shaft_angle: float) -> float | None:
    """Largest error of ``omega_out / omega_in`` against Hooke's closed form (None if not finite)."""
    ratio = table["omega_out"].to_numpy() / table["omega_in"].to_numpy()
    err = np.abs(ratio - speed_ratio(table["theta_in"].to_numpy(), shaft_angle))
    return float(np.max(err)) if np.all(np.isfinite(err)) else None


def measure_cell(scene: Scene, node_type: str) -> dict[str, Any]:
    """Run the reference and Exudyn (at ``h`` and, when it is ok with friction, ``h / 2``) on
    one cell's scene and return the raw measurements (flat scalars)."""
    out = reference_measures(scene)
    result = run(scene, ENGINE, node_type=node_type)
    out.update(exudyn_measures(result.summary))
    h = scene.drive.speed * scene.numerics.dt  # [rad] of input angle per step
    out["ratio_promise"] = (SAFETY * error_coefficient(scene.joint.geometry.shaft_angle, node_type)
                            * h * h + RATIO_FLOOR)
    if result.table is not None and len(result.table):
        out["ratio_error"] = ratio_error(result.table, scene.joint.geometry.shaft_angle)
    if result.success and scene.has_friction:
        half = run(replace(scene, **{"numerics.dt": scene.numerics.dt / 2, "record.timeseries": False}),
                   ENGINE, node_type=node_type).summary
        out.update(half_status=half.status.value, exu_efficiency_half=half.mean_efficiency)
    return out


def cell(scene: Scene, engine: str, node_type: str) -> dict[str, Any]:
    """Sweep case function: one map cell with ``node_type`` nodes (a ``function_args`` value)."""
    if engine != ENGINE:
        raise ValueError(f"stress cells compare {ENGINE} with the {REFERENCE}; engine {engine!r}")
    return measure_cell(scene, node_type)


def as_float(value: Any) -> float:
    """``value`` as a float; NaN for None or anything else that is not a number."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def efficiency_promise(record: dict[str, Any]) -> float:
    """``SAFETY * 2^p / (2^p - 1) |eta_h - eta_h/2| + EFFICIENCY_FLOOR`` with the order ``p`` of
    the record's ``coupling`` (NaN without a halved run)."""
    a, b = as_float(record.get("exu_efficiency")), as_float(record.get("exu_efficiency_half"))
    if record.get("half_status") != Status.OK or not (math.isfinite(a) and math.isfinite(b)):
        return float("nan")
    p = ORDER[record.get("coupling", "converged")]
    return SAFETY * 2.0**p / (2.0**p - 1.0) * abs(a - b) + EFFICIENCY_FLOOR


def broken_promises(record: dict[str, Any]) -> list[str]:
    """The checks an Exudyn run with status ok fails (empty: converged): speed ratio within the
    step's promise, efficiency in [0, 1] and within its promise of the reference's, constraints."""
    reasons = []
    ratio_err, promise = as_float(record.get("ratio_error")), as_float(record.get("ratio_promise"))
    if not ratio_err <= promise:  # written so that NaN fails
        reasons.append(f"speed-ratio error {number(ratio_err, '.2g')} > promised {number(promise, '.2g')}")
    eta, eta_ref = as_float(record.get("exu_efficiency")), as_float(record.get("ref_efficiency"))
    if not 0.0 <= eta <= 1.0:
        reasons.append(f"mean efficiency {number(eta, '.4g')} outside [0, 1]")
    for key, unit in (("constraint_violation_m", "m"), ("constraint_violation_rad", "rad")):
        v = as_float(record.get(key))
        if not v <= CONSTRAINT_LIMIT:
            reasons.append(f"constraint violation {number(v, '.2g')} {unit} > {CONSTRAINT_LIMIT:g}")
    if record.get("ref_status") == Status.OK:
        promise = efficiency_promise(record)
        if not math.isfinite(promise):  # frictionless, or the halved run failed
            promise = EFFICIENCY_FLOOR
        if not abs(eta - eta_ref) <= promise:
            reasons.append(f"efficiency {number(eta, '.4f')} vs reference {number(eta_ref, '.4f')}: "
                           f"|error| {number(abs(eta - eta_ref), '.2g')} > promised {promise:.2g}")
    return reasons


def cell_class(record: dict[str, Any]) -> tuple[str, list[str]]:
    """Exudyn's class of the cell (:data:`CLASSES` but ``error``) and, for ``drift``, why."""
    exu = record.get("exu_status")
    if exu == Status.OK:
        reasons = broken_promises(record)
        locks = record.get("ref_status") == Status.SELF_LOCKING
        return ("drift" if reasons or locks else "converged"), reasons
    if exu == Status.SELF_LOCKING:
        return "self_locking", []
    return "integration_failure", ([] if exu in EXUDYN_FAILURES else [f"unexpected status {exu!r}"])


def _verdict(cls: str, reference: str, agrees: bool, category: str, explanation: str = "") -> dict[str, Any]:
    return {"cell_class": cls, "reference": reference, "agrees": agrees, "category": category,
            "explanation": explanation}


def _where_reference_runs(record: dict[str, Any], cls: str, reasons: list[str]) -> dict[str, Any]:
    """The verdict where the reference's friction fixed point has a solution throughout."""
    exu_reason = str(record.get("exu_reason") or "")[:120]
    if cls == "converged":
        return _verdict(cls, "ok", True, "agree: ok")
    if cls == "drift":
        return _verdict(cls, "ok", False, "wrong answer with status ok", "; ".join(reasons))
    if cls == Status.SELF_LOCKING:
        return _verdict(cls, "ok", False, "Exudyn locks, the reference does not",
                        f"reference loop gain max {number(as_float(record.get('ref_loop_gain_max')), '.3g')}"
                        f" < 1; Exudyn: {exu_reason}")
    return _verdict(cls, "ok", False, "numerical failure in a physically valid cell",
                    f"Exudyn {record.get('exu_status')}: {exu_reason}")


def _where_reference_locks(record: dict[str, Any], cls: str, reasons: list[str]) -> dict[str, Any]:
    """The verdict where the reference's friction fixed point has no solution: the joint locks."""
    if cls == Status.SELF_LOCKING:
        return _verdict(cls, "self_locking", True, "agree: self-locking")
    if cls == Status.INTEGRATION_FAILURE:
        return _verdict(cls, "self_locking", True, "agree: fails where the joint locks",
                        f"Exudyn {record.get('exu_status')} instead of a self-locking verdict: "
                        f"{str(record.get('exu_reason') or '')[:120]}")
    gain = as_float(record.get("exu_loop_gain_max"))
    explanation = (f"reference self-locks ({str(record.get('ref_reason'))[:80]}); Exudyn ok with "
                   f"efficiency {number(as_float(record.get('exu_efficiency')), '.4g')}"
                   + (f", loop gain estimate max {gain:.3g}" if math.isfinite(gain) else "")
                   + (f"; {'; '.join(reasons)}" if reasons else ""))
    return _verdict(cls, "self_locking", False, "runs on through a physical self-lock", explanation)


def classify(record: dict[str, Any]) -> dict[str, Any]:
    """Class, agreement with the reference's physics, category and a one-line explanation of
    one cell from its measurements (a record of :func:`measure_cell`, or a harness error)."""
    if record.get("status", "ok") != Status.OK:  # the case function raised
        return _verdict("error", "unknown", False, "harness error", str(record.get("reason"))[:200])
    cls, reasons = cell_class(record)
    ref = record.get("ref_status")
    if ref == Status.OK:
        return _where_reference_runs(record, cls, reasons)
    if ref == Status.SELF_LOCKING:
        return _where_reference_locks(record, cls, reasons)
    return _verdict(cls, f"failed ({ref})", False, "reference failed",
                    f"reference {ref}: {str(record.get('ref_reason'))[:120]}")


MEASURED = ("ref_status", "ref_efficiency", "ref_loop_gain_max", "exu_status", "exu_efficiency",
            "exu_efficiency_half", "half_status", "exu_loop_gain_max", "ratio_error",
            "ratio_promise", "constraint_violation_m", "constraint_violation_rad", "exu_steps",
            "exu_newton_iterations", "exu_wall_s", "case_wall_s", "exu_reason", "ref_reason")


def measured(record: dict[str, Any]) -> dict[str, Any]:
    """The record's measurements (:data:`MEASURED`), the efficiency promise and error."""
    out = {k: record.get(k) for k in MEASURED}
    out["efficiency_promise"] = efficiency_promise(record)
    eta, ref = as_float(record.get("exu_efficiency")), as_float(record.get("ref_efficiency"))
    out["efficiency_error"] = abs(eta - ref) if math.isfinite(eta) and math.isfinite(ref) else None
    return out


@dataclass
class StressMap:
    """The classified cells (one row each) and how they were obtained."""

    cells: pd.DataFrame
    panels: list[Panel]
    quick: bool
    sweeps: dict[str, dict[str, Any]] = field(default_factory=dict)

    def counts(self) -> dict[str, Any]:
        """Cells, cells per class and per category, reference self-locking, disagreements."""
        c = self.cells
        return {
            "cells": int(len(c)),
            "classes": {k: int(v) for k, v in c["cell_class"].value_counts().items()},
            "reference_self_locking": int((c["reference"] == Status.SELF_LOCKING).sum()),
            "disagreements": int((~c["agrees"]).sum()),
            "categories": {k: int(v) for k, v in c["category"].value_counts().items()},
        }


def sweep_specs(quick: bool = False) -> dict[str, SweepSpec]:
    """One explicit-case sweep spec per node type (the map's panels grouped by node type)."""
    groups: dict[str, list[dict[str, Any]]] = {}
    for panel in panels(quick):
        for angle in panel.angles:
            for x in panel.x_values:
                groups.setdefault(panel.node_type, []).append(
                    {"id": cell_id(panel, angle, x), **panel.overrides(angle, x)})
    base = base_scene()
    return {node: SweepSpec(scene=base, engine=ENGINE, cases=tuple(cases),
                            function=f"{__name__}:cell", function_args={"node_type": node})
            for node, cases in groups.items()}


def classified_cells(chosen: list[Panel], records: dict[str, dict[str, Any]]) -> pd.DataFrame:
    """One row per cell of the panels: its settings, measurements and classification."""
    rows = []
    for panel in chosen:
        for angle in panel.angles:
            for x in panel.x_values:
                record = {**records[cell_id(panel, angle, x)], "coupling": panel.coupling}
                rows.append({"panel": panel.key, "node_type": panel.node_type,
                             "coupling": panel.coupling, "x_name": panel.x, "x": x,
                             **panel.cell(angle, x), **measured(record), **classify(record)})
    return pd.DataFrame(rows)


def run_map(runs: str | os.PathLike, quick: bool = False, *, workers: int | None = None,
            restart: bool = False, progress: bool | None = None) -> StressMap:
    """Run (or resume) the map's sweeps into ``runs/<node type>/`` and classify every cell.

    Parameters
    ----------
    runs : path
        Folder of the sweeps (one per node type); kept between invocations.
    quick : bool
        The coarse map of :func:`panels`.
    workers, restart, progress
        As :func:`cardan_exudyn.sweep.run_sweep`; cells that raised are always rerun.
    """
    runs = Path(runs)
    records: dict[str, dict[str, Any]] = {}
    sweeps = {}
    for node, spec in sweep_specs(quick).items():
        folder = runs / node.lower()
        summary = run_sweep(spec, folder, workers=workers, restart=restart, retry_failed=True,
                            progress=progress)
        sweeps[node] = {k: summary[k] for k in ("run_now", "wall_time_s", "executor")}
        records.update(read_records(folder / CASES_FILE))
    chosen = panels(quick)
    return StressMap(classified_cells(chosen, records), chosen, quick, sweeps)
