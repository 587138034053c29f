"""What every ``cardan`` subcommand shares on its command line: exit statuses, one-line bad input,
number and count parsers, output-folder checks.

Exit status: 0 success; 2 bad input (one line on stderr, no traceback); 3 the run failed (summary
``status``); 4 a sweep stopped early (rerun to resume); 5 ``cardan run`` ended ok but missed
``--accuracy`` (``docs/accuracy.md``); 130 interrupted.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

from cardan_exudyn.outputs import OutputError, check_output_folder

__all__ = ["EXIT_OK", "EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_INCOMPLETE", "EXIT_INACCURATE",
           "EXIT_INTERRUPTED", "BadInput", "out_folder", "number", "count", "cli_value", "path_value",
           "COUNT_LIMITS", "MAX_COUNT", "refuse_options"]

EXIT_OK = 0
EXIT_BAD_INPUT = 2
EXIT_FAILED = 3
EXIT_INCOMPLETE = 4
EXIT_INACCURATE = 5
EXIT_INTERRUPTED = 130


class BadInput(Exception):
    """Raised for invalid command-line input; printed as one line, exit status 2."""


def out_folder(path: str | None, option: str = "--out", replace: bool = True) -> None:
    """Refuse output folder ``path`` of ``option`` (None: not given) before anything runs: :class:`BadInput`
    when empty or not writable as asked (``replace``: the command replaces it as a whole)."""
    if path is not None and not path.strip():
        raise BadInput(f"{option} is empty: give a folder")
    if path:
        try:
            check_output_folder(path, replace=replace)
        except OutputError as exc:
            raise BadInput(f"{option}: {exc}") from None


def number(kind: str, *, positive: bool = False, non_negative: bool = False,
           maximum: float | None = None) -> Callable[[str], float]:
    """An argparse ``type`` for a finite number (``kind``: unit shown in messages), optionally
    ``positive``, ``non_negative`` or at most ``maximum``."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number ({kind}), got {text!r}") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"expected a finite number ({kind}), got {text!r}")
        if positive and value <= 0:
            raise argparse.ArgumentTypeError(f"must be positive ({kind}), got {text!r}")
        if non_negative and value < 0:
            raise argparse.ArgumentTypeError(f"must be >= 0 ({kind}), got {text!r}")
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"must be at most {maximum:g} ({kind}), got {text!r}")
        return value

    return parse


COUNT_LIMITS = {"--samples": 100_000, "--workers": 1024, "--repeats": 1000, "--mc": 100_000,
                "--pulses-per-rev": 1_000_000, "--cells": 1_000_000, "--seed": 2**63 - 1}
"""Largest value of each count option (beyond it: memory or weeks; 1e5 Monte Carlo samples already
pin a 95 % interval to about 1e-3 of its width). Others take at most :data:`MAX_COUNT`."""
MAX_COUNT = 1_000_000
"""Largest value of a count option without a :data:`COUNT_LIMITS` entry."""


def count(name: str, minimum: int = 1, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse ``type`` for integer option ``name`` in [``minimum``, ``maximum``] (default
    :data:`COUNT_LIMITS` or :data:`MAX_COUNT`); ``1e3`` reads as 1000."""
    top = maximum if maximum is not None else COUNT_LIMITS.get(name, MAX_COUNT)

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            try:
                as_float = float(text)
            except ValueError:
                as_float = math.nan
            if not (math.isfinite(as_float) and as_float.is_integer()):
                raise argparse.ArgumentTypeError(f"expected an integer ({name}), got {text!r}") from None
            value = int(as_float)
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum} ({name}), got {text!r}")
        if value > top:
            raise argparse.ArgumentTypeError(f"must be at most {top} ({name}), got {text!r}")
        return value

    return parse


def cli_value(text: str) -> Any:
    """A TOML value (number, boolean, quoted string, array), else the text itself."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def path_value(option: str, text: str, form: str) -> tuple[str, str]:
    """``(path, value)`` of ``option``'s ``text`` ``PATH=VALUE`` split at the first ``=``, path
    stripped; :class:`BadInput` (showing ``form``) for no ``=`` or an empty side."""
    path, sep, value = text.partition("=")
    if not sep or not path.strip() or not value.strip():
        raise BadInput(f"{option} must look like {form}, got {text!r}")
    return path.strip(), value


def refuse_options(args: argparse.Namespace, dests: tuple[str, ...] | list[str], why: str) -> None:
    """:class:`BadInput` naming the first of ``dests`` given in ``args`` (not None/False): those options
    do not apply ``why``."""
    for dest in dests:
        value = getattr(args, dest, None)
        if value is not None and value is not False:
            raise BadInput(f"--{dest.replace('_', '-')} does not apply {why}")
