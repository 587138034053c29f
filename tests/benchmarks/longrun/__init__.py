"""The long runs: what runs (:mod:`.plan`), the runs (:mod:`.runs`), the measurements
(:mod:`.measures`), the headline figures (:mod:`.summary`), the files and report section
(:mod:`.report`), the command (:mod:`.command`)."""

from __future__ import annotations

__all__: list[str] = []
