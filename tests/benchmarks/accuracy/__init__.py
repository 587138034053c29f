"""The accuracy grid: its cells (:mod:`.grid`), what they say (:mod:`.verdict`) and the
command (:mod:`.command`)."""

from __future__ import annotations

__all__: list[str] = []
