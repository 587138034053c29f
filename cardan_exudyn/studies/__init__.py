"""Studies: jobs built on the engines, each a ``cardan`` subcommand.

The modules named in :data:`COMMANDS` register their subcommand: ``register(subparsers)`` adds
its parser and sets ``func`` to a handler ``(args) -> exit status``. The other modules are their
parts (``bench_*``, ``stress_*``, ``longrun_*``, ``reproduce_report``) or research scripts behind
a document (``mujoco_settings``: ``docs/mujoco.md``). Only :mod:`cardan_exudyn.cli` imports this
package; library code never does.

- ``reproduce``: the paper's studies, the main report; ``calibrate``: the calibrated set;
- ``compare``: the ``cardan compare`` report over :mod:`cardan_exudyn.comparison`;
- ``tolerance``: mounting errors, the paper's case and Monte Carlo;
- ``friction_numerics``: ``cardan study`` (friction coupling error against step, sign band);
- ``bench``: run time against error; ``stress``: stability map and long runs;
- ``accuracy_grid``: ``cardan accuracy``, the honesty of the mean-efficiency error estimate.
"""

from __future__ import annotations

__all__ = ["COMMANDS"]

COMMANDS: dict[str, str] = {
    "reproduce": "reproduce.command", "bench": "bench.command", "stress": "stress.command",
    "study": "study.compute", "calibrate": "calibrate.command", "compare": "compare.command",
    "tolerance": "tolerance.command", "accuracy": "accuracy.compute",
}
"""Modules of this package that register a subcommand, in the order ``cardan --help`` lists them."""
