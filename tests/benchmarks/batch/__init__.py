"""The batched reference engine: the measurements (:mod:`.measure`), its targets
(:mod:`.targets`), the folder (:mod:`.report`), the command (:mod:`.command`)."""

from __future__ import annotations

__all__: list[str] = []
