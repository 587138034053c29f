"""cardan-exudyn: the mechanical efficiency of Cardan (universal) joints with the Exudyn engine.

The public face. Run a scene with any engine and read one typed result::

    import cardan_exudyn
    from reference import named_scene

    result = cardan_exudyn.run(named_scene("paper-10deg"), engine="reference")
    if result.success:
        print(result.summary.mean_efficiency)

Names are imported on first use (PEP 562), so ``import cardan_exudyn`` stays cheap: Exudyn,
pandas and matplotlib load only when a run or a report needs them.
"""

from __future__ import annotations

from reference.lazy import lazy_face

__all__ = [
    "run", "run_batch", "make_options", "options_class", "ENGINES", "EngineUnavailable",
    "ExudynOptions", "compare", "Comparison", "sweep",
    "Result", "Summary", "Status", "OptionsError",
]

_LAZY = {
    "run": "cardan_exudyn.engines",
    "run_batch": "cardan_exudyn.engines",
    "make_options": "cardan_exudyn.engines",
    "options_class": "cardan_exudyn.engines",
    "ENGINES": "cardan_exudyn.engines",
    "EngineUnavailable": "cardan_exudyn.engines",
    "ExudynOptions": "cardan_exudyn.model.options",
    "compare": "cardan_exudyn.comparison",
    "Comparison": "cardan_exudyn.comparison",
    "Result": "reference.results.result",
    "Summary": "reference.results.summary",
    "Status": "reference.results.summary",
    "OptionsError": "reference.results.summary",
    "sweep": "cardan_exudyn.sweep",
}


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
