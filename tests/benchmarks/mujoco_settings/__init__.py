"""The MuJoCo settings study: the study (:mod:`.study`, needs MuJoCo) and its command
(:mod:`.command`)."""

from __future__ import annotations

__all__: list[str] = []
