"""Studies: jobs built on the engines, each a ``cardan`` subcommand in a subpackage of its own.

Each subpackage's ``command`` module has ``register(subparsers)``, setting ``func`` to a handler
``(args) -> exit status``. Only :mod:`cardan_exudyn.cli` imports this package.
"""

from __future__ import annotations

__all__ = ["COMMANDS"]

COMMANDS: dict[str, str] = {
    "reproduce": "reproduce.command", "bench": "bench.command", "stress": "stress.command",
    "calibrate": "calibrate.command", "compare": "compare.command", "tolerance": "tolerance.command",
}
"""Modules of this package that register a subcommand, in the order ``cardan --help`` lists them."""
