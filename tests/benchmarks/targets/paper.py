"""The paper's eleven scenes with friction timed one after the other with Exudyn and the
reference engine (:func:`paper_scenes_timing`), their errors against the reference at its tight
defaults: the ``paper_exudyn`` and ``paper_reference`` targets."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from benchmarks.targets.targets import EFFICIENCY_TARGET
from cardan_exudyn import engines
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.studies.bench.configs import EXUDYN_TUNED, Progress, quiet
from cardan_exudyn.studies.bench.ladders import yardstick
from reference.engine import ReferenceOptions
from reference.paper import paper_cases, paper_scene
from reference.results.result import Result
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["PAPER_EXUDYN_STEPS", "PAPER_EXUDYN_COUPLING", "PAPER_REFERENCE_OPTIONS", "paper_scenes",
           "timing_part", "paper_exudyn_scene", "paper_scenes_timing"]


# The paper scenes' Exudyn run: the one-solve coupling, each scene at the step the engine plans
# for `numerics.accuracy` = EFFICIENCY_TARGET (what a user asking for 1e-4 gets, pilot run
# included); a fixed number of steps per revolution instead is a choice made knowing the errors.
# Both are parameters of `paper_scenes_timing` and of `--paper-steps` / `--paper-coupling`.
PAPER_EXUDYN_STEPS: int | str = "auto"
PAPER_EXUDYN_COUPLING = "extrapolated"
PAPER_REFERENCE_OPTIONS = ReferenceOptions(samples_per_revolution=36, quadrature_rtol=1e-6)
"""The reference engine's settings in the paper scenes' timing."""


def paper_scenes(parameters: str = "literal") -> list[Scene]:
    """The paper's eleven scenes with friction (Table 2 and the speed study), summary only."""
    return [replace(paper_scene(c["shaft_angle_deg"], c["speed_rpm"], parameters=parameters),
                    **{"record.timeseries": False}) for c in paper_cases()]


def timing_part(config: str, walls: list[float], results: list[Result], exact: list[float],
                scenes: list[Scene]) -> dict[str, Any]:
    """One engine's entry of :func:`paper_scenes_timing`; ``steps_per_revolution`` per scene
    from each run's step (None where a run has none)."""
    errors = [abs(r.summary.mean_efficiency - e) if r.success else float("nan")
              for r, e in zip(results, exact, strict=True)]
    finite = [e for e in errors if np.isfinite(e)]
    steps = [round(2.0 * math.pi / s.drive.max_speed() / r.summary.dt) if r.summary.dt else None
             for r, s in zip(results, scenes, strict=True)]
    return {"config": config, "wall_s": float(np.median(walls)), "walls_s": walls,
            "max_error": max(finite) if finite else float("nan"), "errors": errors,
            "failed": sum(not r.success for r in results), "repeats": len(walls),
            "scenes": [s.name for s in scenes], "steps_per_revolution": steps}


def paper_exudyn_scene(scene: Scene, steps: int | str, coupling: str) -> Scene:
    """``scene`` as :func:`paper_scenes_timing` runs it with Exudyn: ``steps`` per revolution, or
    (``"auto"``) no step and ``numerics.accuracy`` = :data:`EFFICIENCY_TARGET`; ``coupling``."""
    if steps == "auto":
        return replace(scene, **{"numerics.dt": None, "numerics.accuracy": EFFICIENCY_TARGET,
                                 "friction.coupling": coupling})
    return replace(scene, **{"numerics.dt": 2.0 * math.pi / scene.drive.max_speed() / steps,
                             "friction.coupling": coupling})


def paper_scenes_timing(repeats: int = 3, exudyn_steps: int | str = PAPER_EXUDYN_STEPS,
                        exudyn_options: ExudynOptions = EXUDYN_TUNED,
                        reference_options: ReferenceOptions = PAPER_REFERENCE_OPTIONS,
                        progress: Progress | None = None,
                        exudyn_coupling: str = PAPER_EXUDYN_COUPLING) -> dict[str, Any]:
    """Wall time of the eleven scenes, one after the other in this process, per engine.

    Exudyn runs at ``exudyn_steps`` per revolution (``"auto"``: the step it plans for
    ``numerics.accuracy`` = :data:`EFFICIENCY_TARGET`, from a pilot run when ``exudyn_options``
    has no error estimate) with ``exudyn_options`` and the friction coupling ``exudyn_coupling``;
    the reference with ``reference_options``. Errors are against the reference at its default
    (tight) settings.

    Returns
    -------
    dict
        Per engine (``exudyn``, ``reference``): ``config``, ``wall_s`` (median of the rounds)
        and ``walls_s`` [s], ``errors`` and ``max_error`` (mean efficiency) [-], ``failed``,
        ``repeats``, ``scenes``.
    """
    say = progress or quiet
    scenes = paper_scenes()
    exact = [yardstick(s).summary.mean_efficiency for s in scenes]

    # the scenes are built before the clock starts: the rounds time the engines' runs only
    ex_scenes = [paper_exudyn_scene(s, exudyn_steps, exudyn_coupling) for s in scenes]
    runners = {"exudyn": lambda: [engines.run(s, "exudyn", exudyn_options) for s in ex_scenes],
               "reference": lambda: [engines.run(s, "reference", reference_options) for s in scenes]}
    walls: dict[str, list[float]] = {k: [] for k in runners}
    last: dict[str, list[Result]] = {}
    for round_ in range(repeats):
        for engine, runner in runners.items():
            start = time.perf_counter()
            last[engine] = runner()
            walls[engine].append(time.perf_counter() - start)
            say(f"paper scenes round {round_ + 1}/{repeats} {engine}: {walls[engine][-1]:.2f} s")
    steps = (f"its own step for accuracy {EFFICIENCY_TARGET:g}" if exudyn_steps == "auto"
             else f"{exudyn_steps} steps/rev")
    configs = {"exudyn": f"tuned, {exudyn_coupling} coupling, {steps}",
               "reference": f"samples {reference_options.samples_per_revolution}/rev, quadrature "
                            f"rtol {reference_options.quadrature_rtol:g}"}
    return {engine: timing_part(configs[engine], walls[engine], results, exact, scenes)
            for engine, results in last.items()}
