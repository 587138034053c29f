"""The campaign's journal: every model run's outcome, one JSON line each, on disk as it finishes, so an
interrupted or failed campaign resumes without running any model again.
"""

from __future__ import annotations

import contextlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.outputs import write_error
from reference.results.summary import Status

__all__ = ["JOURNAL_FILE", "Outcome", "Journal"]

JOURNAL_FILE = "runs.jsonl"
"""The journal's file name in the campaign's output folder."""


@dataclass(frozen=True)
class Outcome:
    """What one model run gave.

    Attributes
    ----------
    status : str
        The engine's status (``ok``, ``locked``, ``failed``, ...).
    reason : str or None
    efficiency : float or None
        Mean efficiency over the recording's window [-] (None unless ``ok``).
    error_estimate : float or None
        The engine's own estimate of the mean efficiency's error [-].
    wall_s : float
    reused : bool
        Taken from the journal, not run now.
    """

    status: str
    reason: str | None
    efficiency: float | None
    error_estimate: float | None
    wall_s: float
    reused: bool = field(default=False, compare=False)

    @property
    def ok(self) -> bool:
        """True when the run ended ``ok`` with an efficiency."""
        return self.status == Status.OK and self.efficiency is not None

    def as_dict(self) -> dict[str, Any]:
        """JSON fields (without ``reused``)."""
        return {"status": str(self.status), "reason": self.reason, "efficiency": self.efficiency,
                "error_estimate": self.error_estimate, "wall_s": self.wall_s}


class Journal:
    """Appends outcomes to ``folder/runs.jsonl`` (flushed and fsync'ed); :attr:`outcomes` holds the ones
    found there when opened (a last line cut by a crash is dropped).
    """

    def __init__(self, folder: str | os.PathLike) -> None:
        self.path = Path(folder) / JOURNAL_FILE
        self.outcomes: dict[str, Outcome] = self._read()
        self._file = open(self.path, "ab")

    def _read(self) -> dict[str, Outcome]:
        """The outcomes already in the file."""
        if not self.path.is_file():
            return {}
        data = self.path.read_bytes()
        whole = data[:data.rfind(b"\n") + 1]
        if len(whole) < len(data):  # a line cut short when the run was killed: the next one starts clean
            with open(self.path, "r+b") as f:
                f.truncate(len(whole))
        out = {}
        for line in whole.splitlines():
            try:
                item: dict[str, Any] = json.loads(line)
                key = item.pop("key")
                out[key] = Outcome(**item, reused=True)
            except (ValueError, TypeError, KeyError):
                continue  # not a journal line: ignored, never trusted
        return out

    def add(self, key: str, outcome: Outcome) -> None:
        """Append one outcome; on disk when this returns (Ctrl-C and SIGTERM wait for it)."""
        line = json.dumps({"key": key, **outcome.as_dict()}, separators=(",", ":")) + "\n"
        with deferred_signals():
            try:
                self._file.write(line.encode("utf-8"))
                self._file.flush()
                os.fsync(self._file.fileno())
            except OSError as exc:  # a full disk: the runs before stay, the cut line is dropped on resume
                raise write_error(exc, self.path) from None

    def close(self) -> None:
        """Close the file (after a failed write its unwritten rest is dropped; the runs before are kept)."""
        with contextlib.suppress(OSError):
            self._file.close()
