"""The folder of the batched engine's measurements: ``batch.csv`` (cost against batch size,
opening with the environment header), ``batch_targets.csv``, ``batch.json``, ``report.md``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_directory
from cardan_exudyn.report.format import markdown_table
from cardan_exudyn.studies.bench.report import header

__all__ = ["COST_FORMATS", "TARGET_COLUMNS", "report_markdown", "write_batch_bench"]


COST_FORMATS = {"batch_size": "d", "wall_s": ".3g", "per_sample_ms": ".3g", "ok": "d", "speedup": ".3g"}
TARGET_COLUMNS = ["target", "measured", "limit", "met", "detail"]


def report_markdown(result: dict[str, Any]) -> str:
    """``report.md``: the command, the targets, the cost table, the memory."""
    s = result["settings"]
    env = result["environment"]
    mem = result["memory"]
    command = (f"python tests/benchmarks batch{' --quick' if s['quick'] else ''} --sizes "
               f"{','.join(map(str, s['sizes']))} --samples {s['samples']} "
               f"--dask-samples {s['dask_samples']}")
    targets = [{**t, "met": {True: "yes", False: "**no**", None: "not measured"}[t["met"]]}
               for t in result["targets"]]
    return (f"# The batched reference engine\n{env['date']}, commit `{env['commit']}`, "
            f"{env['cpu']} ({env['cpu_count']} logical CPUs); whole run {result['wall_s']:.0f} s.\n\n"
            f"`{command}`\n\n## Targets\n"
            + markdown_table(targets, TARGET_COLUMNS, {"measured": ".3g", "limit": "g"})
            + "\n## Per-sample cost against batch size\nRig scene (matched set) with Section 4.2's "
              "tolerances drawn as `cardan tolerance montecarlo` draws them; one "
              "`cardan_exudyn.engines.run_batch` per size, scenes built before the clock. The sweep "
              f"cuts batches of at most {result['batch_size_constant']} "
              "(`cardan_exudyn.sweep.BATCH_SIZE`).\n\n"
            + markdown_table(result["cost"], list(COST_FORMATS), COST_FORMATS)
            + f"\nPeak memory of one batch (tracemalloc): {mem['peak_mb'][0]:.3g} MB for "
              f"{mem['sizes'][0]} scenes, {mem['peak_mb'][1]:.3g} MB for {mem['sizes'][1]}: "
              f"{1e3 * mem['per_scene_mb']:.3g} kB more per scene, {mem['per_1000_mb']:.3g} MB for 1000 "
              f"scenes (the peak includes garbage awaiting Python's cycle collector); the results "
              f"returned hold {mem['retained_mb'][1]:.3g} MB for {mem['sizes'][1]} scenes.\n")


def write_batch_bench(result: dict[str, Any], out: str | Path) -> Path:
    """The folder ``out`` (replaced atomically): ``batch.csv`` (cost against batch size, opening
    with the environment header), ``batch_targets.csv``, ``batch.json``, ``report.md``."""
    with atomic_directory(Path(out)) as tmp:
        cost = pd.DataFrame(result["cost"]).to_csv(index=False, float_format="%.6g")
        (tmp / "batch.csv").write_text(header(result["environment"], "python tests/benchmarks batch") + cost,
                                       encoding="utf-8")
        pd.DataFrame(result["targets"]).to_csv(tmp / "batch_targets.csv", index=False, float_format="%.4g")
        (tmp / "batch.json").write_text(dumps(result) + "\n", encoding="utf-8")
        (tmp / "report.md").write_text(report_markdown(result), encoding="utf-8")
    return Path(out)
