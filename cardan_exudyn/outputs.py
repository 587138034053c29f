"""A command's output: folders and files written atomically, one writer at a time, and a run's
result folder (CSV time table, JSON summary).

A command writes into a new hidden sibling of its output folder and exchanges it with the
previous one in one step when it is complete (:func:`atomic_directory`), so a command killed at
any instant leaves the complete previous output or the complete new one; the next command
removes what a killed one left. While a command runs, a second one writing to the same output
is refused (:func:`output_lock`). The guarantees and their limits: ``docs/outputs.md``.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import functools
import os
import re
import shutil
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.jsonable import dumps
from reference.results.result import Result

__all__ = ["OutputError", "WRITE_ERRORS", "write_error", "check_output_folder", "atomic_open", "atomic_write",
           "lock_path", "output_lock", "clean_leftovers", "exchange", "atomic_directory", "result_files",
           "write_result_files", "write_result"]


class OutputError(ValueError):
    """An output path cannot be written as asked: it exists and is not a folder, it may not be
    replaced, its parent cannot hold it or another command is writing it (raised before anything
    is written), or the disk is full (the previous output is kept). The CLI prints it, exit
    status 2."""


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
    tmp = target.with_name(f".{target.name}.{os.urandom(8).hex()}.tmp")
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
    """Write one binary file atomically and durably (:func:`atomic_open`).

    Parameters
    ----------
    path : path-like
        Target file; its folder must exist.
    write : callable
        ``write(f)`` fills the binary file object ``f``.
    """
    with atomic_open(path, "wb") as f:
        write(f)


def check_output_folder(target: str | os.PathLike, replace: bool = True) -> Path:
    """``target`` as a folder a command may create (and, with ``replace``, replace as a whole).

    A folder that is replaced as a whole must be one of its own: not the current folder, the home
    folder, the root or a folder above one of them (however it is spelt: ``.``, ``$(pwd)``,
    ``~/..``), and not a folder holding a ``.git`` repository.

    Parameters
    ----------
    target : path-like
        The output folder.
    replace : bool
        The command replaces the folder as a whole (False: it writes into it, as a sweep does).

    Returns
    -------
    Path
        ``target``.

    Raises
    ------
    OutputError
        ``target`` exists and is not a folder, its nearest existing parent is not a folder, or
        (with ``replace``) it is not a folder of its own.
    """
    target = Path(target)
    if replace and target.name in ("", ".", ".."):  # "", ".", "/", "..": a folder above the output's own
        raise OutputError(f"{str(target)!r} names no folder of its own (the current folder, a parent "
                          "or the root would be replaced)")
    if target.exists() and not target.is_dir():
        raise OutputError(f"{str(target)!r} exists and is not a folder")
    if replace and target.is_dir():
        _check_replaceable(target)
    parent = target.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"cannot create {str(target)!r}: {str(parent)!r} is not a folder")
    return target


def _check_replaceable(folder: Path) -> None:
    """Refuse to replace a folder that holds the current or home folder, or a repository."""
    resolved = folder.resolve()
    for place, what in ((Path.cwd(), "the current folder"), (Path.home(), "the home folder")):
        with contextlib.suppress(OSError, RuntimeError):
            place = place.resolve()
            if place == resolved or resolved in place.parents:
                raise OutputError(f"{str(folder)!r} is {what} or holds it: it would be replaced as a "
                                  "whole; give a folder of its own")
    if (folder / ".git").exists():
        raise OutputError(f"{str(folder)!r} holds a git repository: it would be replaced as a whole; "
                          "give a folder of its own")


WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS})
"""Errors of a write the disk refuses (full, over quota, over the file size limit, read-only):
reported in one line (:func:`write_error`), exit status 2."""
_LEFTOVER = re.compile(r"\.(?P<name>.+)\.cardan-(?P<kind>new|old)-(?P<pid>\d+)-[0-9a-f]+")
_held: dict[str, int] = {}  # lock files this process holds -> nesting depth (the lock is re-entrant)


def write_error(exc: OSError, target: str | os.PathLike) -> OutputError:
    """A write failure (full disk, quota, file size limit, read-only) as one line.

    Parameters
    ----------
    exc : OSError
        The failure.
    target : path-like
        The output it was writing.

    Returns
    -------
    OutputError
        To raise; names the target, the reason and the file.
    """
    return OutputError(f"cannot write {str(target)!r}: {exc.strerror or exc}"
                       + (f" ({exc.filename})" if exc.filename else ""))


def lock_path(target: str | os.PathLike) -> Path:
    """The lock file of an output ``target``: ``.NAME.lock`` next to it."""
    target = Path(os.path.abspath(target))
    return target.with_name(f".{target.name}.lock")


@contextlib.contextmanager
def output_lock(target: str | os.PathLike) -> Iterator[None]:
    """Hold ``target`` (an output folder or file) for this process: a second command writing to
    it meanwhile gets :class:`OutputError` naming this one. Re-entrant within a process.

    The lock is an advisory ``flock`` on ``.NAME.lock`` next to the target, removed on release;
    its folder must exist. Without ``fcntl`` (Windows), or where the lock file cannot be created
    (a read-only folder, which no command can write into anyway), nothing is locked."""
    path = lock_path(target)
    key = str(path)
    if key in _held:
        _held[key] += 1
        try:
            yield
        finally:
            _held[key] -= 1
        return
    fd = _acquire(path, target)
    _held[key] = 1
    try:
        yield
    finally:
        del _held[key]
        if fd is not None:
            with contextlib.suppress(OSError):  # unlinked before the unlock: see _acquire
                os.unlink(path)
            os.close(fd)


def _acquire(path: Path, target: str | os.PathLike) -> int | None:
    """Open and lock ``path``; retried when its holder removed it between our open and lock."""
    try:
        import fcntl
    except ImportError:  # Windows: no advisory lock
        return None
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
                return None
            raise write_error(exc, target) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 32).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            raise OutputError(f"{str(target)!r} is being written by another cardan command (process "
                              f"{holder}); wait for it to end or choose another output") from None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode("ascii"))
            return fd
        os.close(fd)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's process counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def clean_leftovers(target: str | os.PathLike) -> list[Path]:
    """Remove the temporary siblings ``.NAME.cardan-new-PID-*`` and ``.NAME.cardan-old-PID-*`` of
    ``target`` left by killed commands (their process is gone); when ``target`` itself is
    missing and a killed swap left the previous output aside (``old``), put it back first.

    Returns the leftovers found (restored or removed)."""
    target = Path(target)
    if not target.parent.is_dir():
        return []
    found = []
    for entry in target.parent.iterdir():
        match = _LEFTOVER.fullmatch(entry.name)
        if match and match["name"] == target.name and not _alive(int(match["pid"])):
            found.append((match["kind"], entry))
    if not os.path.lexists(target):
        olds = sorted((e for kind, e in found if kind == "old"), key=lambda e: e.stat().st_mtime)
        if olds:
            os.rename(olds[-1], target)
    for _, entry in found:
        _remove(entry)
    return [e for _, e in found]


def _remove(path: Path) -> None:
    """Delete a folder (or the symbolic link an output folder may have been) if it exists."""
    if path.is_symlink():
        path.unlink()
    elif path.exists():
        shutil.rmtree(path, ignore_errors=True)


def _sibling(target: Path, kind: str) -> Path:
    """A new hidden sibling of ``target``, ``.NAME.cardan-KIND-PID-TOKEN`` (``kind``: new or old)."""
    return target.with_name(f".{target.name}.cardan-{kind}-{os.getpid()}-{os.urandom(4).hex()}")


@functools.cache
def _renameat2():
    """libc's ``renameat2`` (Linux >= 3.15, glibc >= 2.28), or ``None``; looked up on first use,
    not at import."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        function = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError, TypeError):
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    function.restype = ctypes.c_int
    return function


_AT_FDCWD = -100  # renameat2's "relative to the current folder"
_RENAME_EXCHANGE = 2  # renameat2's flag: swap the two paths


def exchange(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """Swap two existing paths in one atomic step (Linux ``renameat2(RENAME_EXCHANGE)``).

    Parameters
    ----------
    a, b : path-like
        The two paths.

    Returns
    -------
    bool
        True when swapped; False where the system or the file system cannot (the caller falls
        back to two renames).

    Raises
    ------
    OSError
        Any other failure.
    """
    renameat2 = _renameat2()
    if renameat2 is None:
        return False
    if renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), os.fspath(a), None, os.fspath(b))


def _swap(new: Path, target: Path) -> None:
    """Put the complete folder ``new`` at ``target``; the previous one is removed after. Ctrl-C
    and SIGTERM wait for the renames (:func:`cardan_exudyn.interrupts.deferred_signals`)."""
    with deferred_signals():
        if not os.path.lexists(target):
            os.rename(new, target)
            return
        if exchange(new, target):  # one step: at every instant target is the previous or the new
            old = new
        else:  # two steps: between them the previous is at `old`, and clean_leftovers puts it
            old = _sibling(target, "old")  # back if this process is killed there
            os.replace(target, old)
            try:
                os.replace(new, target)
            except BaseException:
                if not os.path.lexists(target):
                    os.replace(old, target)
                raise
    _remove(old)


def _fsync_tree(folder: Path) -> None:
    """Files and folders under ``folder`` on disk before the swap (a power cut then finds the new
    output complete, not files of zero length)."""
    for root, _, files in os.walk(folder):
        for name in [*files, "."]:
            fd = os.open(os.path.join(root, name), os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)


def _make_parents(target: Path) -> None:
    """Make the folders above ``target``; :class:`OutputError` when they cannot be made."""
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the folder of {str(target)!r}: {exc.strerror}") from None


@contextlib.contextmanager
def atomic_directory(target: str | os.PathLike) -> Iterator[Path]:
    """Yield a new empty folder that replaces ``target`` only when the block succeeds.

    The folder is ``.NAME.cardan-new-PID-*`` next to ``target``, made with the permissions the
    umask gives. When the block ends, its files are fsync'ed and it takes the place of
    ``target`` in one atomic exchange (where the file system cannot exchange: two renames, see
    :func:`clean_leftovers`); on an exception (an interruption included) it is removed and
    ``target`` is untouched. The command holds :func:`output_lock` throughout and first removes
    the leftovers of killed commands.

    Raises
    ------
    OutputError
        Before the block runs: ``target`` exists and is not a folder (a file is never replaced
        by a folder), may not be replaced (:func:`check_output_folder`), its parent cannot be
        made, or another command is writing it. After: the disk is full or the output cannot
        be written (:data:`WRITE_ERRORS`); the previous output is kept.
    """
    target = check_output_folder(target)
    _make_parents(target)
    with output_lock(target):
        clean_leftovers(target)
        new = _sibling(target, "new")
        try:
            os.mkdir(new, 0o777)  # not mkdtemp, which makes it 0o700 whatever the umask
        except OSError as exc:
            raise write_error(exc, target) from None
        try:
            yield new
            _fsync_tree(new)
            _swap(new, target)
        except OSError as exc:
            shutil.rmtree(new, ignore_errors=True)
            if exc.errno in WRITE_ERRORS:
                raise write_error(exc, target) from None
            raise
        except BaseException:
            shutil.rmtree(new, ignore_errors=True)
            raise


def result_files(result: Result) -> list[str]:
    """The files :func:`write_result_files` writes for ``result``: ``timeseries.csv`` only when a
    table was recorded (``record.timeseries``), then ``summary.json``."""
    return (["timeseries.csv"] if result.has_table else []) + ["summary.json"]


def write_result_files(result: Result, folder: Path) -> None:
    """Write ``timeseries.csv`` (when recorded) and ``summary.json`` into an existing folder.

    Parameters
    ----------
    result : Result
        The run; its table is built here (the one place a run's table is read to be written).
    folder : Path
        The folder.
    """
    if result.table is not None:
        result.table.to_csv(folder / "timeseries.csv", index=False, float_format="%.12g")
    (folder / "summary.json").write_text(dumps(result.summary) + "\n", encoding="utf-8")


def write_result(result: Result, out: str | os.PathLike) -> Path:
    """Write a run's result folder atomically (:func:`atomic_directory`).

    Parameters
    ----------
    result : Result
        The run.
    out : path-like
        The folder, replaced as a whole.

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    OutputError
        As :func:`atomic_directory`.
    """
    with atomic_directory(out) as tmp:
        write_result_files(result, tmp)
    return Path(out)
