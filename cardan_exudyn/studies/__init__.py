"""Studies: jobs built on the engines (the paper reproduction, calibration, comparison reports,
tolerance studies, benchmarks, stress tests, long runs, coupling studies).

Each study module registers its own ``cardan`` subcommand: ``register(subparsers)`` adds its
parser and sets ``func`` to a handler ``(args) -> exit status``. Only :mod:`cardan_exudyn.cli`
imports this package; library code never does.
"""

from __future__ import annotations

COMMANDS: tuple[str, ...] = ("reproduce", "bench", "stress", "coupling", "calibrate", "compare",
                             "tolerance")
"""Modules of this package that register a subcommand, in the order ``cardan --help`` lists them.
A module is added here when its ``register`` exists."""
