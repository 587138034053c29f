"""One sweep runner: a scene over a grid, random samples, or a list of parameter overrides.

The public face::

    from cardan_exudyn.sweep import run_sweep

    summary = run_sweep({"scene": "paper-10deg", "engine": "reference",
                         "grid": {"joint.geometry.shaft_angle_deg": [0, 10, 20]}}, "out/angles")

Inside (``docs/sweep.md`` is the user's guide):

- :mod:`~cardan_exudyn.sweep.spec`: what to sweep (:class:`SweepSpec`, grids, TOML spec files);
  :mod:`~cardan_exudyn.sweep.sampling`: random samples (:class:`RandomSpec`,
  :class:`Distribution`); :mod:`~cardan_exudyn.sweep.functions`: the case function by name;
  :mod:`~cardan_exudyn.sweep.checks`: :class:`SweepError` and the largest sweep;
- :mod:`~cardan_exudyn.sweep.plan`: the spec expanded into cases with stable ids and validated
  (:class:`Plan`, :func:`make_plan`);
- :mod:`~cardan_exudyn.sweep.records`: ``cases.jsonl``, resume, the results table, the default
  case function :func:`summary_outputs`;
- :mod:`~cardan_exudyn.sweep.tasks`: what a worker runs, a case or a batch of cases of an engine
  with a batched pass (:data:`BATCH_SIZE`, :func:`plan_tasks`);
- :mod:`~cardan_exudyn.sweep.executors`: in the driver, a local process pool, a Dask cluster;
- :mod:`~cardan_exudyn.sweep.runner`: :func:`run_sweep`, which ties them together.

Names are imported on first use (PEP 562): ``from cardan_exudyn.sweep import SweepError`` loads
the checks alone, not the executors and the runner.
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
