"""The speed targets: the targets themselves (:mod:`.targets`), the paper's scenes timed
(:mod:`.paper`), every measurement in one call (:mod:`.run`), the folder (:mod:`.report`) and the
command (:mod:`.command`)."""

from __future__ import annotations

__all__: list[str] = []
