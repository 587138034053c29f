"""The stability map of ``cardan stress``: every cell of the panels measured and classified, run as
one sweep per node type in ``OUT/runs/`` so an interrupted map resumes.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from cardan_exudyn.studies.stress.classify import classify, measured
from cardan_exudyn.studies.stress.panels import BASE_SCENE, ENGINE, Panel, base_scene, cell_id, panels
from cardan_exudyn.sweep import CASES_FILE, SweepSpec, read_records, run_sweep
from reference.results.summary import Status
from reference.scene.scene import Scene

__all__ = ["CELL_FUNCTION", "StressMap", "sweep_specs", "classified_cells", "run_map"]

CELL_FUNCTION = "cardan_exudyn.studies.stress.cell:cell"
"""The sweeps' case function (:func:`cardan_exudyn.studies.stress.cell.cell`)."""


@dataclass
class StressMap:
    """The classified cells and how they were obtained: ``cells`` (one row each: panel, node type,
    coupling, settings, measurements, classification), ``panels``, ``quick``, ``sweeps`` (per node
    type ``run_now``, ``wall_time_s``, ``executor``) and ``scene`` (the base scene's name).
    """

    cells: pd.DataFrame
    panels: list[Panel]
    quick: bool
    sweeps: dict[str, dict[str, Any]] = field(default_factory=dict)
    scene: str = BASE_SCENE

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


def sweep_specs(quick: bool = False, scene: Scene | None = None) -> dict[str, SweepSpec]:
    """One explicit-case sweep spec per node type (``quick``: coarse map) for joint ``scene``
    (default :data:`~.panels.BASE_SCENE`).
    """
    groups: dict[str, list[dict[str, Any]]] = {}
    for panel in panels(quick):
        for angle in panel.angles:
            for x in panel.x_values:
                groups.setdefault(panel.node_type, []).append(
                    {"id": cell_id(panel, angle, x), **panel.overrides(angle, x)})
    base = base_scene(scene)
    return {node: SweepSpec(scene=base, engine=ENGINE, cases=tuple(cases),
                            function=CELL_FUNCTION, function_args={"node_type": node})
            for node, cases in groups.items()}


def classified_cells(chosen: list[Panel], records: dict[str, dict[str, Any]]) -> pd.DataFrame:
    """One row per cell of panels ``chosen``: settings, measurements and classification from ``records``
    (cell id -> sweep record).
    """
    rows = []
    for panel in chosen:
        for angle in panel.angles:
            for x in panel.x_values:
                record = {**records[cell_id(panel, angle, x)], "coupling": panel.coupling}
                rows.append({"panel": panel.key, "node_type": panel.node_type,
                             "coupling": panel.coupling, "x_name": panel.x, "x": x,
                             **panel.cell(angle, x), **measured(record), **classify(record)})
    return pd.DataFrame(rows)


def run_map(runs: str | os.PathLike, quick: bool = False, *, scene: Scene | None = None,
            workers: int | None = None, restart: bool = False,
            progress: bool | None = None) -> StressMap:
    """Run (or resume) the map's sweeps into ``runs/<node type>/`` and classify every cell.

    ``quick``: the coarse map; ``scene``: the joint (default :data:`~.panels.BASE_SCENE`); ``workers``,
    ``restart``, ``progress``: as :func:`cardan_exudyn.sweep.run_sweep` (cells that raised always
    rerun). SweepError when ``runs`` holds another map's sweeps.
    """
    runs = Path(runs)
    records: dict[str, dict[str, Any]] = {}
    sweeps = {}
    for node, spec in sweep_specs(quick, scene).items():
        folder = runs / node.lower()
        summary = run_sweep(spec, folder, workers=workers, restart=restart, retry_failed=True,
                            progress=progress)
        sweeps[node] = {k: summary[k] for k in ("run_now", "wall_time_s", "executor")}
        records.update(read_records(folder / CASES_FILE))
    chosen = panels(quick)
    name = base_scene(scene).name
    return StressMap(classified_cells(chosen, records), chosen, quick, sweeps, name)
