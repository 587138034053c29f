"""What every ``cardan`` subcommand (the CLI's, the studies' and ``rigdata``'s) shares on its
command line: exit statuses, one-line bad input, number and count parsers, output-folder checks.
The scene options and the scene they describe: :mod:`cardan_exudyn.scene_options`.

Exit status of every command: 0 success; 2 bad input (one line on stderr naming the argument, no
traceback); 3 the simulation failed or is physically meaningless (the reason is in the summary
``status``); 4 (``cardan sweep``) the sweep stopped before every case ran (rerun to resume); 5
(``cardan run``) the run ended ok but its estimated mean-efficiency error exceeds the target
``--accuracy`` (summary ``accuracy_met`` false; ``docs/accuracy.md``); 130 interrupted.
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
    """Refuse an output folder that cannot be one, before anything runs.

    Parameters
    ----------
    path : str or None
        The option's value; None: not given (nothing to check).
    option : str
        The option's name, for the message.
    replace : bool
        The command replaces the folder as a whole (not a sweep, which writes into it):
        :func:`cardan_exudyn.outputs.check_output_folder` refuses more.

    Raises
    ------
    BadInput
        An empty value, or a folder that cannot be written as asked.
    """
    if path is not None and not path.strip():
        raise BadInput(f"{option} is empty: give a folder")
    if path:
        try:
            check_output_folder(path, replace=replace)
        except OutputError as exc:
            raise BadInput(f"{option}: {exc}") from None


def number(kind: str, *, positive: bool = False, non_negative: bool = False,
           maximum: float | None = None) -> Callable[[str], float]:
    """An argparse ``type`` for a finite number.

    Parameters
    ----------
    kind : str
        The option's unit (or name), shown in the messages.
    positive, non_negative : bool
        Refuse values <= 0, or < 0.
    maximum : float, optional
        Refuse values above it.

    Returns
    -------
    callable
        ``parse(text) -> float``; ``argparse.ArgumentTypeError`` naming the rule broken.
    """
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
"""Largest value of each count option: a value above it would exhaust memory or run for weeks
(100 000 Monte Carlo samples or draws already pin a 95 % interval to about 1e-3 of its width;
no machine here has 1024 cores). Options not listed take at most :data:`MAX_COUNT`."""
MAX_COUNT = 1_000_000
"""Largest value of a count option without a :data:`COUNT_LIMITS` entry."""


def count(name: str, minimum: int = 1, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse ``type`` for an integer option in [``minimum``, ``maximum``]; ``1e3`` is read
    as 1000.

    Parameters
    ----------
    name : str
        The option (``"--workers"``), shown in the messages and looked up in :data:`COUNT_LIMITS`.
    minimum : int
        Smallest value allowed.
    maximum : int, optional
        Largest value allowed (default: the option's :data:`COUNT_LIMITS` entry, else
        :data:`MAX_COUNT`).

    Returns
    -------
    callable
        ``parse(text) -> int``; ``argparse.ArgumentTypeError`` naming the rule broken.
    """
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
    """``PATH=VALUE`` split at the first ``=``.

    Parameters
    ----------
    option : str
        The option (``"--set"``), for the message.
    text : str
        What was given.
    form : str
        The expected form (``"PATH=VALUE"``), for the message.

    Returns
    -------
    path : str
        Stripped of blanks.
    value : str
        As given.

    Raises
    ------
    BadInput
        No ``=``, or an empty path or value.
    """
    path, sep, value = text.partition("=")
    if not sep or not path.strip() or not value.strip():
        raise BadInput(f"{option} must look like {form}, got {text!r}")
    return path.strip(), value


def refuse_options(args: argparse.Namespace, dests: tuple[str, ...] | list[str], why: str) -> None:
    """Refuse options the command would otherwise silently ignore.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    dests : sequence of str
        Destinations of the options that do not apply.
    why : str
        Ends the message (``"to a Monte Carlo study"``).

    Raises
    ------
    BadInput
        Naming the first of ``dests`` that was given (not None, not False).
    """
    for dest in dests:
        value = getattr(args, dest, None)
        if value is not None and value is not False:
            raise BadInput(f"--{dest.replace('_', '-')} does not apply {why}")
