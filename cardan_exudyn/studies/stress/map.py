"""The stability map of ``cardan stress``: where the Exudyn model of a joint stops giving the
right answer, and why.

Every cell of the panels (:mod:`.panels`) is measured (:mod:`.cell`) and classified from its
measurements alone (:mod:`.classify`). The cells run as sweeps (:mod:`cardan_exudyn.sweep`, one
sweep per node type in ``OUT/runs/``), so an interrupted map resumes where it stopped
(:func:`run_map`).
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
    """The classified cells (one row each) and how they were obtained.

    Attributes
    ----------
    cells : pandas.DataFrame
        One row per cell: panel, node type, coupling, the cell's settings, measurements
        (:func:`~cardan_exudyn.studies.stress.classify.measured`) and classification.
    panels : list of Panel
        The panels, in the order of the report.
    quick : bool
        The coarse map.
    sweeps : dict
        Per node type the sweep's ``run_now``, ``wall_time_s`` [s] and ``executor``.
    scene : str
        The base scene's name.
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
    """One explicit-case sweep spec per node type (the map's panels grouped by node type).

    Parameters
    ----------
    quick : bool
        The coarse map.
    scene : Scene, optional
        The joint (default :data:`~cardan_exudyn.studies.stress.panels.BASE_SCENE`); the base scene
        is :func:`~cardan_exudyn.studies.stress.panels.base_scene` of it.
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
    """One row per cell of the panels: its settings, measurements and classification.

    Parameters
    ----------
    chosen : list of Panel
        The panels.
    records : dict
        Cell id (:func:`~cardan_exudyn.studies.stress.panels.cell_id`) -> sweep record.
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

    Parameters
    ----------
    runs : path
        Folder of the sweeps (one per node type); kept between invocations.
    quick : bool
        The coarse map of :func:`~cardan_exudyn.studies.stress.panels.panels`.
    scene : Scene, optional
        The joint to map (default :data:`~cardan_exudyn.studies.stress.panels.BASE_SCENE`).
    workers, restart, progress
        As :func:`cardan_exudyn.sweep.run_sweep`; cells that raised are always rerun.

    Raises
    ------
    cardan_exudyn.sweep.SweepError
        ``runs`` holds the sweeps of another map (another scene, or ``quick`` then not).
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
