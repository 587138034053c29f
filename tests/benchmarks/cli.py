"""The command line of ``python tests/benchmarks``: one subcommand per entry of
:data:`benchmarks.BENCHMARKS`, with the exit statuses of ``cardan`` (0 ok, 2 bad input in one
line, 3 a run failed or a target is missed where the benchmark says so, 130 interrupted)."""

from __future__ import annotations

import argparse
import importlib
import sys

from benchmarks import BENCHMARKS
from cardan_exudyn.arguments import EXIT_BAD_INPUT, EXIT_INTERRUPTED, BadInput
from cardan_exudyn.outputs import OutputError
from reference.results.summary import OptionsError
from reference.scene.validation import SceneError

__all__ = ["build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """argparse's errors as one line on stderr, exit status 2."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The parser: a subcommand per benchmark of :data:`benchmarks.BENCHMARKS`."""
    parser = _Parser(prog="python tests/benchmarks",
                     description="The project's research benchmarks (docs/benchmarks.md).")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, module in BENCHMARKS.items():
        importlib.import_module(module).register(sub, name)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark named by ``argv`` (default: the process's arguments); the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (BadInput, SceneError, OptionsError, OutputError) as exc:
        print(f"python tests/benchmarks {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"python tests/benchmarks {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
