"""One sweep runner: a scene over a grid, random samples, or a list of parameter overrides.

The public face::

    from cardan_exudyn.sweep import run_sweep

    summary = run_sweep({"scene": "paper-10deg", "engine": "reference",
                         "grid": {"joint.geometry.shaft_angle_deg": [0, 10, 20]}}, "out/angles")

Inside (``docs/sweep.md`` is the user's guide):

- :mod:`~cardan_exudyn.sweep.spec`: what to sweep (:class:`SweepSpec`, :class:`RandomSpec`,
  :class:`Distribution`, the case function by name, TOML spec files);
- :mod:`~cardan_exudyn.sweep.plan`: the spec expanded into cases with stable ids and validated
  (:class:`Plan`, :func:`make_plan`);
- :mod:`~cardan_exudyn.sweep.records`: ``cases.jsonl``, resume, the results table, the default
  case function :func:`summary_outputs`;
- :mod:`~cardan_exudyn.sweep.tasks`: what a worker runs, a case or a batch of cases of an engine
  with a batched pass (:data:`BATCH_SIZE`, :func:`plan_tasks`);
- :mod:`~cardan_exudyn.sweep.executors`: in the driver, a local process pool, a Dask cluster;
- :mod:`~cardan_exudyn.sweep.runner`: :func:`run_sweep`, which ties them together.
"""

from __future__ import annotations

from cardan_exudyn.sweep.executors import SweepIncomplete, SweepInterrupted, default_workers
from cardan_exudyn.sweep.plan import Case, Plan, expand_cases, make_plan
from cardan_exudyn.sweep.records import (
    CASES_FILE,
    PLAN_FILE,
    RESULTS_FILE,
    SUMMARY_FILE,
    read_records,
    results_table,
    scalar_summary,
    statistics,
    summary_outputs,
)
from cardan_exudyn.sweep.runner import run_sweep
from cardan_exudyn.sweep.spec import (
    DEFAULT_FUNCTION,
    CaseFunction,
    Distribution,
    RandomSpec,
    SweepError,
    SweepSpec,
    flatten_paths,
    load_spec,
    looks_like_path,
    read_spec_file,
    spec_from_mapping,
)
from cardan_exudyn.sweep.tasks import BATCH_SIZE, Batch, plan_tasks, run_case

__all__ = [
    "run_sweep", "SweepSpec", "RandomSpec", "Distribution", "CaseFunction", "SweepError",
    "SweepIncomplete", "SweepInterrupted", "BATCH_SIZE", "Batch", "plan_tasks", "spec_from_mapping",
    "read_spec_file", "load_spec", "looks_like_path",
    "flatten_paths", "Case", "Plan", "make_plan", "expand_cases", "run_case", "default_workers",
    "read_records", "results_table", "statistics", "scalar_summary", "summary_outputs",
    "DEFAULT_FUNCTION", "PLAN_FILE", "CASES_FILE", "RESULTS_FILE", "SUMMARY_FILE",
]
