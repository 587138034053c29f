"""Commands under test in processes of their own (the signal and output tests share these)."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

CLI = [sys.executable, "-m", "cardan_exudyn.cli"]


def start(argv: list[str], cwd: Path, preexec_fn=None) -> subprocess.Popen:
    """``cardan ARGV`` leading a session of its own, so that a signal to its process group
    reaches it (and its workers) as a terminal's Ctrl-C would; ``preexec_fn`` runs in the child
    (e.g. a file-size limit)."""
    def child() -> None:
        # a shell without job control starts background jobs (a CI runner's pytest, say) with
        # SIGINT ignored, and children inherit that: give the command the default a terminal gives
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        if preexec_fn is not None:
            preexec_fn()

    return subprocess.Popen([*CLI, *argv], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, preexec_fn=child)


def wait_for(condition, proc: subprocess.Popen, timeout: float = 90.0) -> None:
    """Poll ``condition()`` every 10 ms; fail when the command ends first or after ``timeout`` s."""
    end = time.monotonic() + timeout
    while not condition():
        if proc.poll() is not None:
            raise AssertionError(f"the command ended before the condition held: {proc.communicate()}")
        if time.monotonic() > end:
            raise AssertionError("timed out")
        time.sleep(0.01)
