"""The skip audit: what each thing the Exudyn build leaves out (or each solver
choice) saves, measured as pairs of runs that differ in that item only.

Items the engine's options or the scene can switch run through :func:`cardan_exudyn.engines.run`;
the others (a no-op pre-step function, the solution file) through the engine's one solve sequence,
:func:`cardan_exudyn.model.solve.solve`, with a ``tweak`` that adds the item and without the
post-processing. Exudyn's fast module can only be chosen before ``exudyn`` is imported, so it is
measured in child processes.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from dataclasses import replace as dc_replace
from typing import Any

import numpy as np
import pandas as pd

from cardan_exudyn import engines
from cardan_exudyn.model.build import ExudynModel
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.solve import solve
from cardan_exudyn.studies.bench.configs import EXUDYN_TUNED, SCENES, Progress, quiet, simulated_time
from reference.paper import named_scene
from reference.results.summary import Status
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["AUDIT_SCENE", "Tweak", "Clock", "AuditItem", "run_wall", "solve_only", "audit_items",
           "skip_audit"]

AUDIT_SCENE = SCENES["frictionless-10deg"]
Tweak = Callable[[ExudynModel, Any], None]
#: A timer [s]: ``time.perf_counter`` (wall time, what a user waits) or ``time.process_time``
#: (this process's CPU time, user and system: blind to other load on a shared machine).
Clock = Callable[[], float]


@dataclass(frozen=True)
class AuditItem:
    """One item of the audit: its name, what the build does instead, and the two timed runs
    (each returns its wall time [s])."""

    item: str
    removal: str
    without: Callable[[], float]
    with_: Callable[[], float]


def run_wall(scene: Scene, options: ExudynOptions, clock: Clock = time.perf_counter) -> float:
    """Wall time [s] (or the ``clock``'s time) of one Exudyn run of ``scene`` (build, solve,
    post-processing).

    Raises
    ------
    RuntimeError
        When the run does not end ok.
    """
    start = clock()
    result = engines.run(scene, "exudyn", options)
    wall = clock() - start
    if not result.success:
        raise RuntimeError(f"audit run failed: {result.message}")
    return wall


def solve_only(scene: Scene, options: ExudynOptions, tweak: Tweak | None = None,
               clock: Clock = time.perf_counter) -> float:
    """Wall time [s] (or the ``clock``'s time) of the build and solve of ``scene`` (no
    post-processing), with ``tweak(model, settings)`` applied before the solver starts.

    Raises
    ------
    RuntimeError
        When the solve does not end ok.
    """
    start = clock()
    solved = solve(scene, options, reactions=options.records_reactions(scene), tweak=tweak)
    wall = clock() - start
    if solved.status != Status.OK:
        raise RuntimeError(f"audit run failed: {solved.reason}")
    return wall


def no_op_pre_step(model: ExudynModel, settings: Any) -> None:
    """A tweak that sets a pre-step user function doing nothing (the cost of the call itself)."""
    def no_op(mbs, t):
        return True

    model.user_functions.append(no_op)
    model.mbs.SetPreStepUserFunction(no_op)


def solution_file(folder: str) -> Tweak:
    """A tweak that writes Exudyn's coordinates file into ``folder`` every step."""
    def tweak(model: ExudynModel, settings: Any) -> None:
        settings.solution.file.write = True
        settings.solution.file.name = os.path.join(folder, "solution.txt")
        settings.solution.file.writePeriod = 0.0
    return tweak


def as_angle_history(scene: Scene) -> Scene:
    """The same constant speed as an angle history (a Python offset function every evaluation)."""
    w = scene.drive.speed
    t = np.linspace(0.0, simulated_time(scene) * 1.5, 8)
    return replace(scene, drive={"kind": "angle", "time": t.tolist(), "angle": (w * t).tolist()})


def audit_items(base: Scene, folder: str, clock: Clock = time.perf_counter) -> list[AuditItem]:
    """The audited items on the summary-only scene ``base``, timed by ``clock``; ``folder`` takes
    the solution file."""
    tuned = EXUDYN_TUNED
    everything = dc_replace(EXUDYN_TUNED, sensors="all")

    def full(scene: Scene, options: ExudynOptions) -> Callable[[], float]:
        return lambda: run_wall(scene, options, clock)

    def solved(tweak: Tweak | None) -> Callable[[], float]:
        return lambda: solve_only(base, tuned, tweak, clock)

    return [
        AuditItem("pair-reaction sensors (summary only)", "8 stored sensors the summary does not use",
                  full(base, tuned), full(base, everything)),
        AuditItem("result table and its post-processing",
                  "columns and DataFrame when only the summary is asked", full(base, everything),
                  full(replace(base, **{"record.timeseries": True}), everything)),
        AuditItem("gravity loads when g = 0", "3 mass-proportional loads of zero effect",
                  full(replace(base, gravity=(0.0, 0.0, 0.0)), tuned),
                  full(replace(base, gravity=(0.0, 0.0, -1e-300)), tuned)),
        AuditItem("Python drive function", "constant speed as a velocity-level connector instead "
                  "of an angle history evaluated in Python", full(base, tuned),
                  full(as_angle_history(base), tuned)),
        AuditItem("Python pre-step function", "a no-op pre-step user function (needed only with "
                  "friction or a torque drive)", solved(None), solved(no_op_pre_step)),
        AuditItem("solution file", "Exudyn's default coordinates file, every step", solved(None),
                  solved(solution_file(folder))),
        AuditItem("full Newton (Jacobian every iteration)", "modified Newton, one Jacobian per step",
                  full(base, tuned),
                  full(base, dc_replace(tuned, modified_newton=False, jacobian_every_step=False))),
        AuditItem("Newton tolerance 1e-10", "relative tolerance 1e-8", full(base, tuned),
                  full(base, dc_replace(tuned, newton_relative_tolerance=1e-10))),
    ]


def audit_row(item: str, removal: str, without: float, with_: float) -> dict[str, Any]:
    """A row of the audit from the two median walls [s]."""
    return {"item": item, "removal": removal, "without_s": without, "with_s": with_,
            "with_over_without": with_ / without, "saved_share": 1.0 - without / with_}


def measure(items: list[AuditItem], repeats: int, say: Progress) -> list[dict[str, Any]]:
    """Both runs of every item, in ``repeats`` rounds; one row per item from the medians."""
    walls = [([], []) for _ in items]
    for round_ in range(repeats):
        for item, (without, with_) in zip(items, walls, strict=True):
            without.append(item.without())
            with_.append(item.with_())
        say(f"skip audit round {round_ + 1}/{repeats}")
    return [audit_row(item.item, item.removal, float(np.median(without)), float(np.median(with_)))
            for item, (without, with_) in zip(items, walls, strict=True)]


def fast_module_time(scene_name: str, steps: int, revolutions: float, runs: int,
                     fast: bool) -> float:
    """Median wall [s] of ``runs`` in-process runs in a child Python with or without Exudyn's
    fast module (chosen by ``sys.exudynFast`` before ``exudyn`` is imported)."""
    code = (
        "import sys, time, math, statistics\n"
        f"sys.exudynFast = {fast!r}\n"
        "import contextlib, io\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    import exudyn\n"
        "from cardan_exudyn.engines import run\n"
        "from cardan_exudyn.studies.bench.configs import EXUDYN_TUNED\n"
        "from reference.paper.scenes import named_scene\n"
        "from reference.scene.mapping import replace\n"
        f"s = named_scene({scene_name!r})\n"
        f"s = replace(s, **{{'numerics.dt': 2*math.pi/s.drive.speed/{steps}, "
        f"'record.timeseries': False, 'revolutions': {revolutions!r}}})\n"
        "run(s, 'exudyn', EXUDYN_TUNED)\n"
        "w = []\n"
        f"for _ in range({runs}):\n"
        "    t0 = time.perf_counter(); r = run(s, 'exudyn', EXUDYN_TUNED); "
        "w.append(time.perf_counter() - t0)\n"
        "    assert r.success, r.message\n"
        "print(statistics.median(w))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "EXUDYN_MODULE"}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
    return float(proc.stdout.strip().splitlines()[-1])


def fast_module_row(steps: int, revolutions: float, repeats: int) -> dict[str, Any]:
    """The range-checks item: the regular against the fast module, two child processes each."""
    item = "range checks (regular module)"
    try:
        regular = []
        fast = []
        for _ in range(2):
            regular.append(fast_module_time(AUDIT_SCENE, steps, revolutions, repeats, False))
            fast.append(fast_module_time(AUDIT_SCENE, steps, revolutions, repeats, True))
    except (RuntimeError, subprocess.SubprocessError, ValueError) as exc:
        nan = float("nan")
        return {"item": item, "removal": f"not measured: {exc}", "without_s": nan, "with_s": nan,
                "with_over_without": nan, "saved_share": nan}
    return audit_row(item, "Exudyn's fast module exudynCPPfast (no range checks, AVX2)",
                     float(np.median(fast)), float(np.median(regular)))


def skip_audit(repeats: int = 5, steps: int = 200, revolutions: float = 10.0,
               progress: Progress | None = None, fast_module: bool = True,
               clock: Clock = time.perf_counter) -> pd.DataFrame:
    """What each thing the Exudyn build leaves out (or each solver choice) saves, measured.

    Each item is a pair of runs that differ only in that item, on the frictionless 10 deg scene
    at ``steps`` per revolution for ``revolutions`` (summary only unless the item is the table;
    long enough that the run, not the timer, is measured); the pairs run in rounds, ``repeats``
    times, and the medians give ``with / without`` (how much slower the run is with the item)
    and the share of the run the removal saves. ``clock`` times the in-process runs
    (:data:`Clock`; the fast module's child processes report wall times).

    Returns
    -------
    pandas.DataFrame
        One row per item: ``scene``, ``item``, ``removal``, ``without_s`` and ``with_s`` [s],
        ``with_over_without`` [-], ``saved_share`` [-].
    """
    say = progress or quiet
    base = named_scene(AUDIT_SCENE)
    base = replace(base, **{"numerics.dt": 2.0 * math.pi / base.drive.speed / steps,
                            "record.timeseries": False, "revolutions": revolutions})
    with tempfile.TemporaryDirectory(prefix="cardan-audit-", ignore_cleanup_errors=True) as folder:
        rows = measure(audit_items(base, folder, clock), repeats, say)
    if fast_module:
        say("skip audit: Exudyn's fast module (child processes)")
        rows.append(fast_module_row(steps, revolutions, repeats))
    table = pd.DataFrame(rows)
    table.insert(0, "scene", f"{base.name}, {steps} steps/rev, summary only")
    return table
