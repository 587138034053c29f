"""A command's output: folders and files written atomically, one writer at a time, and a run's
result folder (CSV time table, JSON summary).

A killed command leaves the complete previous output or the complete new one (:func:`atomic_directory`);
a second writer is refused (:func:`output_lock`). Guarantees and limits: ``docs/outputs.md``.
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
    """An output path cannot be written as asked (not a folder, not replaceable, parent unusable, another
    writer; raised before writing), or the disk refused it (previous output kept). CLI exit status 2."""


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "wb", **kwargs: Any) -> Iterator[IO]:
    """Open a temporary sibling of ``path`` (its folder must exist) with ``mode`` ``"wb"``/``"w"`` and
    ``open`` ``kwargs``; on success flush, fsync and rename it onto ``path``, on an exception remove it."""
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
    """Write binary file ``path`` atomically and durably: ``write(f)`` fills ``f``."""
    with atomic_open(path, "wb") as f:
        write(f)


def check_output_folder(target: str | os.PathLike, replace: bool = True) -> Path:
    """``target`` as a folder a command may create; with ``replace`` (replaced as a whole) it must be one
    of its own: not the current or home folder, the root or above them, nor a ``.git`` holder.
    :class:`OutputError` otherwise, or when ``target`` or its nearest existing parent is not a folder."""
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
"""Errors of a write the disk refuses (full, quota, file size limit, read-only): one line, exit 2."""
_LEFTOVER = re.compile(r"\.(?P<name>.+)\.cardan-(?P<kind>new|old)-(?P<pid>\d+)-[0-9a-f]+")
_held: dict[str, int] = {}  # lock files this process holds -> nesting depth (the lock is re-entrant)


def write_error(exc: OSError, target: str | os.PathLike) -> OutputError:
    """Write failure ``exc`` of output ``target`` as a one-line :class:`OutputError` (to raise)."""
    return OutputError(f"cannot write {str(target)!r}: {exc.strerror or exc}"
                       + (f" ({exc.filename})" if exc.filename else ""))


def lock_path(target: str | os.PathLike) -> Path:
    """The lock file of an output ``target``: ``.NAME.lock`` next to it."""
    target = Path(os.path.abspath(target))
    return target.with_name(f".{target.name}.lock")


@contextlib.contextmanager
def output_lock(target: str | os.PathLike) -> Iterator[None]:
    """Hold output ``target`` for this process (re-entrant): a second writer gets :class:`OutputError`
    naming this one. An advisory ``flock`` on ``.NAME.lock`` next to it, removed on release; nothing
    locked without ``fcntl`` (Windows) or where the lock file cannot be made (read-only folder)."""
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
    """Remove the siblings ``.NAME.cardan-{new,old}-PID-*`` of ``target`` whose process is gone, first
    restoring an ``old`` one when ``target`` is missing; the leftovers found."""
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
    """libc's ``renameat2`` (Linux >= 3.15, glibc >= 2.28) or None, looked up on first use."""
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
    """Swap existing paths ``a`` and ``b`` in one atomic step (Linux ``renameat2(RENAME_EXCHANGE)``).
    False where the system or file system cannot (the caller then renames twice); ``OSError`` otherwise."""
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
    """Put complete folder ``new`` at ``target`` and remove the previous one; Ctrl-C and SIGTERM wait
    for the renames."""
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
    """Fsync everything under ``folder`` before the swap (a power cut finds no zero-length files)."""
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
    """Yield a new empty sibling folder that replaces ``target`` only when the block succeeds.

    On success its files are fsync'ed and it is exchanged with ``target`` atomically (else two renames,
    :func:`clean_leftovers`); on an exception it is removed. Holds :func:`output_lock` throughout.
    :class:`OutputError` before the block (as :func:`check_output_folder`, or another writer) or after
    (:data:`WRITE_ERRORS`; previous output kept).
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
    """The files :func:`write_result_files` writes: ``timeseries.csv`` when recorded, ``summary.json``."""
    return (["timeseries.csv"] if result.has_table else []) + ["summary.json"]


def write_result_files(result: Result, folder: Path) -> None:
    """Write ``result``'s ``timeseries.csv`` (when recorded; its table is built here) and ``summary.json``
    into existing ``folder``."""
    if result.table is not None:
        result.table.to_csv(folder / "timeseries.csv", index=False, float_format="%.12g")
    (folder / "summary.json").write_text(dumps(result.summary) + "\n", encoding="utf-8")


def write_result(result: Result, out: str | os.PathLike) -> Path:
    """Write ``result``'s folder ``out`` atomically (:func:`atomic_directory`); ``Path(out)``."""
    with atomic_directory(out) as tmp:
        write_result_files(result, tmp)
    return Path(out)
