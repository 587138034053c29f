"""Studies: jobs built on the engines, each a ``cardan`` subcommand in a subpackage of its own.

Each subpackage's ``command`` module registers its subcommand: ``register(subparsers)`` adds its
parser and sets ``func`` to a handler ``(args) -> exit status``; the command prints, its
computation returns data, its report writes files. Only :mod:`cardan_exudyn.cli` imports this
package; library code never does.

- ``reproduce``: the paper's studies, the main report; ``calibrate``: the parameter sets' fits
  and the envelope of the plausible box;
- ``compare``: the ``cardan compare`` report over :mod:`cardan_exudyn.comparison`;
- ``tolerance``: mounting errors, the paper's case and Monte Carlo;
- ``bench``: run time against error of a scene; ``stress``: the stability map of a scene.
"""

from __future__ import annotations

__all__ = ["COMMANDS"]

COMMANDS: dict[str, str] = {
    "reproduce": "reproduce.command", "bench": "bench.command", "stress": "stress.command",
    "calibrate": "calibrate.command", "compare": "compare.command", "tolerance": "tolerance.command",
}
"""Modules of this package that register a subcommand, in the order ``cardan --help`` lists them."""
