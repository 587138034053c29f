"""The targets' measurements in one call (:func:`run_targets`): the work-precision runs of the
default scenes (``cardan bench``'s, each friction scene with its frictionless twin), the paper's
eleven scenes timed, the import cost of ``cardan run`` and the skip audit; and the targets
evaluated from them (:class:`TargetsResult`)."""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from benchmarks.audit import skip_audit
from benchmarks.startup import import_cost
from benchmarks.targets.paper import PAPER_EXUDYN_COUPLING, PAPER_EXUDYN_STEPS, paper_scenes_timing
from benchmarks.targets.targets import evaluate_targets, frictionless_twin_scene, is_friction_scene
from cardan_exudyn.studies.bench.configs import ENGINE_NAMES, SCENES, BenchError, Progress, fixed_scenes
from cardan_exudyn.studies.bench.result import BenchResult, run_bench
from reference.scene import COUPLINGS

__all__ = ["TargetsResult", "scene_keys", "check_paper", "run_targets"]


@dataclass
class TargetsResult:
    """Everything one targets run measured.

    Attributes
    ----------
    bench : BenchResult
        The work-precision runs of the default scenes.
    targets : list of dict
        :func:`benchmarks.targets.targets.evaluate_targets`.
    paper : dict or None
        The paper scenes' timing, None when not run.
    startup : dict or None
        The import cost of ``cardan run`` (:func:`benchmarks.startup.import_cost`), None when
        not measured.
    audit : pandas.DataFrame or None
        The skip audit, None when not run.
    settings : dict
        The bench's settings with ``audit``, ``paper``, ``startup``, ``paper_steps``,
        ``paper_coupling``.
    wall_s : float
        Wall time of the whole run [s].
    """

    bench: BenchResult
    targets: list[dict[str, Any]]
    paper: dict[str, Any] | None
    startup: dict[str, Any] | None
    audit: pd.DataFrame | None
    settings: dict[str, Any] = field(default_factory=dict)
    wall_s: float = 0.0

    def summary(self) -> dict[str, Any]:
        """What ``--json`` prints: the bench's summary, the targets, paper timing, startup, audit."""
        return {**self.bench.summary(), "settings": self.settings, "wall_s": self.wall_s,
                "targets": self.targets, "paper_scenes": self.paper, "startup": self.startup,
                "audit": None if self.audit is None else self.audit.to_dict(orient="records")}


def scene_keys(scenes: Iterable[str] | None) -> list[str]:
    """The default scenes' keys to run (default all), each friction scene's frictionless twin
    before it: a friction scene's cost is read against its twin at the same step.

    Raises
    ------
    BenchError
        An unknown key.
    """
    keys = list(fixed_scenes(scenes)) if scenes is not None else list(SCENES)
    return list(dict.fromkeys(twin for k in keys for twin in (
        (frictionless_twin_scene(k), k) if is_friction_scene(k) else (k,))))


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


def run_targets(quick: bool = False, repeats: int | None = None, scenes: Iterable[str] | None = None,
                engines: Iterable[str] = ENGINE_NAMES, audit: bool = True, paper: bool = True,
                progress: Progress | None = None, startup: bool = True,
                paper_steps: int | str = PAPER_EXUDYN_STEPS,
                paper_coupling: str = PAPER_EXUDYN_COUPLING) -> TargetsResult:
    """The work-precision runs, the paper scenes' timing, the import cost of ``cardan run``, the
    skip audit, and the targets from all of them.

    Parameters
    ----------
    quick : bool
        Short ladders, one repeat by default, a shorter audit without the fast module.
    repeats : int, optional
        Timed runs per configuration (default 3, quick 1).
    scenes : iterable of str, optional
        Keys of :data:`~cardan_exudyn.studies.bench.configs.SCENES` (default all; each friction
        scene brings its frictionless twin, :func:`scene_keys`).
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
    keys = scene_keys(scenes)
    check_paper(paper_steps, paper_coupling)
    start = time.perf_counter()
    bench = run_bench(fixed_scenes(keys), quick, repeats, engines, progress)
    engines = bench.settings["engines"]
    repeats = bench.settings["repeats"]
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
    targets = evaluate_targets(bench.rows, paper_result, startup_result)
    settings = {**bench.settings, "audit": audit, "paper": paper, "startup": startup,
                "paper_steps": paper_steps, "paper_coupling": paper_coupling}
    return TargetsResult(bench, targets, paper_result, startup_result, audit_table, settings,
                         time.perf_counter() - start)
