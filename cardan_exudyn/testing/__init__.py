"""The harness inside a user's own pytest suite: the plugin :mod:`cardan_exudyn.testing.plugin`
(fixtures ``cardan_scene``, ``cardan_run``) and assertions that work with or without pytest.
See ``docs/pytest.md``. Names load on first use (PEP 562): pytest imports the plugin at every
start, and :func:`assert_engines_agree` pulls in pandas and scipy.
"""

from __future__ import annotations

from reference.lazy import lazy_face

__all__ = ["assert_efficiency", "assert_engines_agree", "CardanToleranceWarning", "DEFAULT_COLUMNS",
           "CachingRunner", "RunRecord", "make_scene"]

_LAZY = {
    "assert_efficiency": "cardan_exudyn.testing.assertions",
    "assert_engines_agree": "cardan_exudyn.testing.assertions",
    "CardanToleranceWarning": "cardan_exudyn.testing.assertions",
    "DEFAULT_COLUMNS": "cardan_exudyn.testing.assertions",
    "CachingRunner": "cardan_exudyn.testing.runner",
    "RunRecord": "cardan_exudyn.testing.runner",
    "make_scene": "cardan_exudyn.testing.scenes",
}


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
