"""Writing results: CSV time table plus JSON summary, atomically.

A command writes into a temporary sibling folder and renames it into place at the end, so an
interrupted or failed command leaves either the complete previous output or a complete new one.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterator
from enum import Enum
from pathlib import Path
from typing import IO, Any

import numpy as np

from reference.schema import Result, Summary


class OutputError(ValueError):
    """An output path cannot be written as asked (it exists and is not a folder, or its parent
    cannot hold it); raised before anything is written. The CLI prints it, exit status 2."""


def to_jsonable(value: Any) -> Any:
    """Plain JSON data: numpy scalars and arrays converted, NaN and infinities as null."""
    if isinstance(value, Summary):
        return to_jsonable(value.to_dict())
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, (np.bool_,)):
        return bool(value)
    return value


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "wb", **kwargs: Any) -> Iterator[IO]:
    """Open a temporary sibling of ``path``; on success flush, fsync and rename it onto ``path``.

    Parameters
    ----------
    path : path-like
        Target file; its folder must exist.
    mode : {"wb", "w"}
        Binary or text.
    **kwargs
        Passed to :func:`open` (``encoding``, ``newline``).

    Yields
    ------
    file object
        Write to it; on an exception (an interruption included) the temporary file is removed
        and the target is untouched.
    """
    target = Path(path)
    tmp = target.with_name(f".{target.name}.{secrets.token_hex(8)}.tmp")
    # os.open applies the umask to 0o666, as open() would; mkstemp would leave the file 0o600
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    try:
        with os.fdopen(fd, mode, **kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
    except BaseException:  # no half-written temporary file left behind
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def atomic_write(path: str | os.PathLike, write: Callable[[IO], Any]) -> None:
    """Write one binary file atomically and durably: ``write(f)`` fills it (:func:`atomic_open`)."""
    with atomic_open(path, "wb") as f:
        write(f)


def dumps(data: Any) -> str:
    return json.dumps(to_jsonable(data), indent=2, allow_nan=False)


def check_output_folder(target: str | os.PathLike, replace: bool = True) -> Path:
    """``target`` as a folder a command may create (and, with ``replace``, replace as a whole): it
    is a folder or does not exist, and its nearest existing parent is a folder; raises
    :class:`OutputError` otherwise."""
    target = Path(target)
    if replace and target.name in ("", ".", ".."):  # "", ".", "/", "..": a folder above the output's own
        raise OutputError(f"{str(target)!r} names no folder of its own (the current folder, a parent "
                          "or the root would be replaced)")
    if target.exists() and not target.is_dir():
        raise OutputError(f"{str(target)!r} exists and is not a folder")
    parent = target.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"cannot create {str(target)!r}: {str(parent)!r} is not a folder")
    return target


@contextlib.contextmanager
def atomic_directory(target: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary folder that replaces ``target`` only when the block succeeds.

    Raises :class:`OutputError` before the block runs when ``target`` exists and is not a folder
    (a file is never replaced by a folder) or its parent cannot be created."""
    target = check_output_folder(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the folder of {str(target)!r}: {exc.strerror}") from None
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old = None
    try:
        if target.exists():
            old = target.with_name(f".{target.name}.old-{os.getpid()}")
            os.replace(target, old)
        os.replace(tmp, target)
    except BaseException:  # put the previous output back; the new one is dropped
        if old is not None and not target.exists():
            os.replace(old, target)
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def write_result_files(result: Result, folder: Path) -> None:
    """``timeseries.csv`` (when recorded) and ``summary.json`` into an existing folder."""
    if result.table is not None:
        result.table.to_csv(folder / "timeseries.csv", index=False, float_format="%.12g")
    (folder / "summary.json").write_text(dumps(result.summary) + "\n", encoding="utf-8")


def write_result(result: Result, out: str | os.PathLike) -> Path:
    """Write a result folder atomically and return its path."""
    with atomic_directory(out) as tmp:
        write_result_files(result, tmp)
    return Path(out)
