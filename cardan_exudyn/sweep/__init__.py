"""One sweep runner: a scene over a grid, random samples, or a list of parameter overrides::

    from cardan_exudyn.sweep import run_sweep
    summary = run_sweep({"scene": "paper-10deg", "engine": "reference",
                         "grid": {"joint.geometry.shaft_angle_deg": [0, 10, 20]}}, "out/angles")

User's guide: ``docs/sweep.md``. Names load on first use (PEP 562).
"""

from __future__ import annotations

from reference.lazy import lazy_face

_HOMES = {
    "cardan_exudyn.sweep.checks": ("SweepError",),
    "cardan_exudyn.sweep.executors": ("SweepIncomplete", "SweepInterrupted", "default_workers"),
    "cardan_exudyn.sweep.functions": ("DEFAULT_FUNCTION", "CaseFunction"),
    "cardan_exudyn.sweep.plan": ("Case", "Plan", "expand_cases", "make_plan"),
    "cardan_exudyn.sweep.records": ("CASES_FILE", "PLAN_FILE", "RESULTS_FILE", "SUMMARY_FILE",
                                    "read_records", "results_table", "scalar_summary", "statistics",
                                    "summary_outputs"),
    "cardan_exudyn.sweep.runner": ("run_sweep",),
    "cardan_exudyn.sweep.sampling": ("Distribution", "RandomSpec"),
    "cardan_exudyn.sweep.spec": ("SweepSpec", "flatten_paths", "load_spec", "looks_like_path",
                                 "read_spec_file", "spec_from_mapping"),
    "cardan_exudyn.sweep.tasks": ("BATCH_SIZE", "Batch", "plan_tasks", "run_case"),
}
_LAZY = {name: module for module, names in _HOMES.items() for name in names}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
