"""Many scenes through the reference engine at once (issue 20).

CONTRACT (kept by every implementation; the sweep runner and the tolerance study build on it):

- :func:`batch_key(scene)` is a hashable key; scenes with equal keys can share one vectorised
  pass (same drive kind, same set of active friction pairs, same friction law and options that
  change the code path). ``None``: the scene must run on its own (torque drive, angle history...).
- :func:`run_batch(scenes, options)` returns one :class:`reference.schema.Result` per scene, in
  order, each equal to ``reference.engine.run(scene, options)`` (to rounding, or to the
  quadrature tolerance where the adaptivity differs). A scene that locks, fails or does not close
  its loop gets its own failed Result and does not spoil the others. Invalid scenes raise
  before anything runs (the error names the scene's index).

This first version runs the scenes one after the other: the vectorised pass replaces it.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence

from reference.engine import ReferenceOptions, run
from reference.schema import OptionsError, Result
from reference.validation import require_scene

__all__ = ["batch_key", "run_batch"]


def batch_key(scene) -> Hashable | None:
    """Scenes with the same key may run in one pass; None: on its own."""
    require_scene(scene)
    return None


def run_batch(scenes: Sequence, options: ReferenceOptions | None = None) -> list[Result]:
    """One :class:`Result` per scene, in order (see the module's contract)."""
    scenes = list(scenes)
    for i, scene in enumerate(scenes):
        require_scene(scene, f"scenes[{i}]")
    if options is not None and not isinstance(options, ReferenceOptions):
        raise OptionsError(f"`options` must be ReferenceOptions or None, got {type(options).__name__}")
    return [run(scene, options) for scene in scenes]
