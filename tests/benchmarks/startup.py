"""The import cost of ``cardan run`` before its scene is built (target: at most 150 ms).

:func:`import_cost` runs, in fresh interpreters under ``python -X importtime``, what ``cardan
run`` does before it hands the scene to an engine: import :mod:`cardan_exudyn.cli`, parse the
command line (:func:`cardan_exudyn.cli.parse_args`), then build the default scene
(:func:`cardan_exudyn.arguments.scene_from_args`; the paper's ``physical`` set reads its output
load from the data file). A marker written to stderr between the parse and
the scene splits the imports into those made before the scene is built (the target's figure) and
those made while it is built. The cost of a phase is the sum of the cumulative times of its
top-level imports (those ``-X importtime`` prints at indent 0, ``site`` included: the
interpreter's start-up and the editable install's finder are part of every ``cardan`` command);
the figures are medians over the runs.

Python's own bytecode cache decides much of it: without one every module of the project is
compiled from source at each start (an environment may set ``PYTHONDONTWRITEBYTECODE``). By
default the runs share a private cache folder (``PYTHONPYCACHEPREFIX``) warmed by one run that is
not counted, as an installed ``cardan`` has; ``bytecode_cache=False`` measures the environment
as it is. The machine's load moves every figure by tens of ms: ``baseline_ms`` (start-up and
numpy alone, measured between the runs) is the yardstick.
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Mapping
from typing import Any

__all__ = ["IMPORT_TARGET_MS", "STARTUP_CODE", "BASELINE_CODE", "SCENE_MARKER", "parse_importtime",
           "import_cost"]

IMPORT_TARGET_MS = 150.0
"""The target for the import cost of ``cardan run`` before its engine runs [ms]."""

SCENE_MARKER = "cardan-bench-startup: scene"
"""The line written to stderr between the parse and the scene build."""

STARTUP_CODE = (
    "import sys\n"
    "import cardan_exudyn.cli as cli\n"
    "args = cli.parse_args(['run'])\n"
    f"print({SCENE_MARKER!r}, file=sys.stderr, flush=True)\n"
    "cli.scene_from_args(args)\n"
)
"""What ``cardan run`` does before its engine dispatch, with the marker between parse and scene."""

BASELINE_CODE = f"import sys, numpy\nprint({SCENE_MARKER!r}, file=sys.stderr, flush=True)\n"
"""The floor of :data:`STARTUP_CODE`: the interpreter's start-up and numpy, which the scene needs."""

_LINE = re.compile(r"^import time:\s+(\d+) \|\s+(\d+) \| (\s*)(\S+)\s*$")


def parse_importtime(text: str, marker: str = SCENE_MARKER) -> tuple[dict[str, int], dict[str, int]]:
    """The top-level imports of a ``python -X importtime`` stderr ``text``, before and after the
    line ``marker``.

    Returns
    -------
    (before, after) : dict, dict
        Module name -> cumulative import time [us] of each indent-0 entry, in the order printed;
        ``after`` is empty when the marker does not occur. Lines other than importtime's (the
        header, warnings) are skipped.
    """
    phases: tuple[dict[str, int], dict[str, int]] = ({}, {})
    phase = 0
    for line in text.splitlines():
        if line.strip() == marker:
            phase = 1
            continue
        match = _LINE.match(line)
        if match and not match.group(3):
            name = match.group(4)
            phases[phase][name] = phases[phase].get(name, 0) + int(match.group(2))
    return phases


def _one_run(python: str, env: Mapping[str, str], cwd: str, timeout: float,
             code: str = STARTUP_CODE) -> tuple[dict, dict]:
    """One interpreter running ``code`` under ``-X importtime``: its two phases."""
    proc = subprocess.run([python, "-X", "importtime", "-c", code], capture_output=True,
                          text=True, env=dict(env), cwd=cwd, timeout=timeout, check=False)
    if proc.returncode != 0 or SCENE_MARKER not in proc.stderr:
        tail = "\n".join(proc.stderr.strip().splitlines()[-5:])
        raise RuntimeError(f"the start-up run failed (exit {proc.returncode}): {tail}")
    return parse_importtime(proc.stderr)


def _environment(cache: str | None) -> dict[str, str]:
    """The runs' environment: this one, with a private bytecode cache folder when ``cache``."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPYCACHEPREFIX", "PYTHONPROFILEIMPORTTIME")}
    if cache is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = cache
    return env


def import_cost(repeats: int = 5, *, bytecode_cache: bool = True, python: str | None = None,
                timeout: float = 120.0) -> dict[str, Any]:
    """The import cost of ``cardan run`` before its scene is built, and while it is built,
    medians of ``repeats`` runs.

    Parameters
    ----------
    repeats : int
        Fresh interpreters measured (>= 1); the median is reported.
    bytecode_cache : bool
        Share a private bytecode cache, warmed by one uncounted run (default), or run with the
        environment's own settings.
    python : str, optional
        The interpreter (default: this one).
    timeout : float
        Limit of one run [s].

    Returns
    -------
    dict
        ``import_ms``: median total [ms] of the imports before the scene is built (interpreter
        start-up, CLI module, parse), the figure :data:`IMPORT_TARGET_MS` is for; ``runs_ms``:
        each run's [ms]; ``top``: its 10 most expensive top-level imports, ``[module, median
        cumulative ms]``, most expensive first; ``scene_build_ms``: median of the imports made
        while the default scene is built [ms] (none when the default scene needs no module
        the parse has not loaded), ``scene_top`` its 5 most expensive; ``through_scene_ms``: median of both
        phases' totals [ms]; ``baseline_ms``: median total [ms] of :data:`BASELINE_CODE`
        (start-up and numpy alone, run between the others: what no change to this project can
        remove, and a gauge of the machine's load); ``target_ms``; ``repeats``;
        ``bytecode_cache``; ``python``; ``command``: :data:`STARTUP_CODE`.

    Raises
    ------
    ValueError
        ``repeats`` is not a positive integer.
    RuntimeError
        A run failed (its last stderr lines are in the message).
    """
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"`repeats` must be a positive integer, got {repeats!r}")
    python = python or sys.executable
    with tempfile.TemporaryDirectory(prefix="cardan-startup-") as folder:
        env = _environment(os.path.join(folder, "pycache") if bytecode_cache else None)
        if bytecode_cache:
            _one_run(python, env, folder, timeout)  # fills the cache; not counted
        runs = []
        floor = []
        for _ in range(repeats):  # interleaved, so that both see the same load of the machine
            runs.append(_one_run(python, env, folder, timeout))
            floor.append(sum(_one_run(python, env, folder, timeout, BASELINE_CODE)[0].values()) / 1000)
    return {**_summary(runs), "baseline_ms": statistics.median(floor), "target_ms": IMPORT_TARGET_MS,
            "repeats": repeats, "bytecode_cache": bytecode_cache, "python": python,
            "command": STARTUP_CODE}


def _top(phase: list[dict[str, int]], n: int) -> list[list]:
    """The ``n`` modules of largest median cumulative time [ms] over the runs of one phase."""
    names = {name for run in phase for name in run}
    median = {name: statistics.median(run.get(name, 0) / 1000 for run in phase) for name in names}
    return [[name, ms] for name, ms in sorted(median.items(), key=lambda item: (-item[1], item[0]))[:n]]


def _summary(runs: list[tuple[dict, dict]]) -> dict[str, Any]:
    """:func:`import_cost`'s timings from the parsed runs (times in us)."""
    before = [sum(b.values()) / 1000 for b, _ in runs]
    during = [sum(a.values()) / 1000 for _, a in runs]
    return {"import_ms": statistics.median(before), "runs_ms": before,
            "scene_build_ms": statistics.median(during),
            "through_scene_ms": statistics.median(b + a for b, a in zip(before, during, strict=True)),
            "top": _top([b for b, _ in runs], 10), "scene_top": _top([a for _, a in runs], 5)}
