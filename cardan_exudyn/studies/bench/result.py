"""The whole of ``cardan bench`` in one call (:func:`run_bench`) and what it returns
(:class:`BenchResult`)."""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from cardan_exudyn.report.environment import environment
from cardan_exudyn.studies.bench.audit import skip_audit
from cardan_exudyn.studies.bench.configs import (
    ENGINE_NAMES,
    SCENES,
    BenchError,
    Progress,
    frictionless_twin_scene,
    is_friction_scene,
)
from cardan_exudyn.studies.bench.ladders import work_precision
from cardan_exudyn.studies.bench.startup import import_cost
from cardan_exudyn.studies.bench.targets import (
    PAPER_EXUDYN_COUPLING,
    PAPER_EXUDYN_STEPS,
    evaluate_targets,
    paper_scenes_timing,
)
from reference.results.summary import Status
from reference.scene.settings import COUPLINGS

__all__ = ["BenchResult", "check_inputs", "check_paper", "run_bench"]


@dataclass
class BenchResult:
    """Everything one bench run measured.

    Attributes
    ----------
    rows : pandas.DataFrame
        The work-precision rows, one per configuration.
    targets : list of dict
        :func:`cardan_exudyn.studies.bench.targets.evaluate_targets`.
    paper : dict or None
        The paper scenes' timing, None when not run.
    startup : dict or None
        The import cost of ``cardan run``
        (:func:`cardan_exudyn.studies.bench.startup.import_cost`), None when not measured.
    audit : pandas.DataFrame or None
        The skip audit, None when not run.
    environment : dict
        Versions, CPU, date and commit.
    settings : dict
        ``quick``, ``repeats``, ``scenes``, ``engines``, ``audit``, ``paper``, ``startup``,
        ``paper_steps``, ``paper_coupling``.
    wall_s : float
        Wall time of the whole bench [s].
    """

    rows: pd.DataFrame
    targets: list[dict[str, Any]]
    paper: dict[str, Any] | None
    audit: pd.DataFrame | None
    environment: dict[str, Any]
    startup: dict[str, Any] | None = None
    settings: dict[str, Any] = field(default_factory=dict)
    wall_s: float = 0.0

    def summary(self) -> dict[str, Any]:
        """What ``--json`` prints: environment, targets, paper timing, audit, best per scene."""
        best = []
        for (scene, config), sel in self.rows.groupby(["scene", "config"], sort=False):
            ok = sel[sel["status"] == Status.OK]
            best.append({"scene": scene, "config": config, "runs": len(sel), "ok": len(ok),
                         "fastest_wall_per_simulated_s": float(ok["wall_per_simulated_s"].min())
                         if not ok.empty else None})
        return {"environment": self.environment, "settings": self.settings, "wall_s": self.wall_s,
                "targets": self.targets, "paper_scenes": self.paper, "startup": self.startup,
                "audit": None if self.audit is None else self.audit.to_dict(orient="records"),
                "configurations": best}


def check_inputs(scenes: Iterable[str] | None, engines: Iterable[str],
                 repeats: int | None, quick: bool) -> tuple[list[str], list[str], int]:
    """The scene keys, engines and repeats of a bench run (defaults filled in; each friction
    scene's frictionless twin added before it).

    Raises
    ------
    BenchError
        For an unknown scene key or engine, or repeats that are not a positive integer.
    """
    keys = list(scenes) if scenes is not None else list(SCENES)
    unknown = [k for k in keys if k not in SCENES]
    if unknown:
        raise BenchError(f"`--scenes` must be among {list(SCENES)}, got {unknown}")
    # a friction scene's cost is read against its frictionless twin at the same step
    keys = list(dict.fromkeys(twin for k in keys for twin in (
        (frictionless_twin_scene(k), k) if is_friction_scene(k) else (k,))))
    engines = list(engines)
    bad = [e for e in engines if e not in ENGINE_NAMES]
    if bad:
        raise BenchError(f"`--engines` must be among {', '.join(ENGINE_NAMES)}, got {bad}")
    repeats = repeats if repeats is not None else (1 if quick else 3)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise BenchError(f"`--repeats` must be a positive integer, got {repeats!r}")
    return keys, engines, repeats


def check_paper(steps: int | str, coupling: str) -> None:
    """Check the paper timing's Exudyn steps per revolution (or ``"auto"``) and coupling.

    Raises
    ------
    BenchError
        Steps that are not a positive integer, or an unknown coupling.
    """
    if steps != "auto" and (isinstance(steps, bool) or not isinstance(steps, int) or steps < 1):
        raise BenchError(f"`--paper-steps` must be a positive integer or 'auto', got {steps!r}")
    if coupling not in COUPLINGS:
        raise BenchError(f"`--paper-coupling` must be one of {list(COUPLINGS)}, got {coupling!r}")


def run_bench(quick: bool = False, repeats: int | None = None, scenes: Iterable[str] | None = None,
              engines: Iterable[str] = ENGINE_NAMES, audit: bool = True, paper: bool = True,
              progress: Progress | None = None, startup: bool = True,
              paper_steps: int | str = PAPER_EXUDYN_STEPS,
              paper_coupling: str = PAPER_EXUDYN_COUPLING) -> BenchResult:
    """The whole bench: work-precision runs, the paper scenes' timing, the import cost of
    ``cardan run``, the skip audit, and the targets from all of them.

    Parameters
    ----------
    quick : bool
        Short ladders, one repeat by default, a shorter audit without the fast module.
    repeats : int, optional
        Timed runs per configuration (default 3, quick 1).
    scenes : iterable of str, optional
        Keys of :data:`~cardan_exudyn.studies.bench.configs.SCENES` (default all).
    engines : iterable of str
        Engines to run; the paper timing needs Exudyn and the reference, the audit Exudyn.
    audit, paper, startup : bool
        Run the skip audit, the paper scenes' timing, the import-cost measurement.
    progress : callable, optional
        Called with one line of text per finished piece of work.
    paper_steps : int or "auto"
        Exudyn's steps per revolution in the paper scenes' timing (``"auto"``: each scene's own
        step for the target accuracy).
    paper_coupling : str
        Exudyn's friction coupling there (one of :data:`reference.scene.settings.COUPLINGS`).

    Raises
    ------
    BenchError
        Bad scenes, engines, repeats, paper steps or coupling.
    """
    keys, engines, repeats = check_inputs(scenes, engines, repeats, quick)
    check_paper(paper_steps, paper_coupling)
    start = time.perf_counter()
    env = environment()
    rows = work_precision(keys, quick, repeats, engines, progress)
    paper_result = None
    if paper and "exudyn" in engines and "reference" in engines:
        paper_result = paper_scenes_timing(repeats=repeats, exudyn_steps=paper_steps,
                                           exudyn_coupling=paper_coupling, progress=progress)
    startup_result = None
    if startup:
        startup_result = import_cost(repeats=3 if quick else 5)
        if progress:
            progress("import cost of cardan run measured")
    audit_table = None
    if audit and "exudyn" in engines:
        audit_table = skip_audit(repeats=3 if quick else 7, progress=progress, fast_module=not quick)
    targets = evaluate_targets(rows, paper_result, startup_result)
    settings = {"quick": quick, "repeats": repeats, "scenes": keys, "engines": engines,
                "audit": audit, "paper": paper, "startup": startup, "paper_steps": paper_steps,
                "paper_coupling": paper_coupling}
    return BenchResult(rows, targets, paper_result, audit_table, env, startup_result, settings,
                       time.perf_counter() - start)
