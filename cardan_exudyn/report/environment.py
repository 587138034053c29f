"""Where a result was computed: versions, CPU, date and commit, for the head of every results file."""

from __future__ import annotations

import contextlib
import datetime
import os
import platform
import subprocess
from pathlib import Path
from typing import Any

__all__ = ["ENVIRONMENT_PACKAGES", "environment"]

ENVIRONMENT_PACKAGES = ("cardan-exudyn", "numpy", "scipy", "exudyn", "distributed", "pandas",
                        "mujoco", "matplotlib")
"""Packages whose versions head a results file (None for one not installed)."""


def environment() -> dict[str, Any]:
    """Versions, CPU, date and commit, for the head of ``sweep.json`` (and other reports)."""
    from importlib import metadata  # import cost: ~15 ms, for a report only

    versions = {}
    for package in ENVIRONMENT_PACKAGES:
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    return {"python": platform.python_version(), "platform": platform.platform(),
            "machine": platform.machine(), "cpu": _cpu_model(),
            "cpu_count": os.cpu_count(), "packages": versions, "commit": _git_commit(),
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def _cpu_model() -> str:
    """The CPU's model name (Linux's ``/proc/cpuinfo``), else what ``platform`` says."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def _git_commit() -> str | None:
    """The commit of the source tree this package runs from, None outside a git checkout."""
    try:
        proc = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                              capture_output=True, text=True, timeout=5)
    except (OSError, subprocess.SubprocessError):
        return None
    return proc.stdout.strip() or None if proc.returncode == 0 else None
