"""Interruptions (Ctrl-C, SIGTERM) as exceptions that no layer mistakes for a failure.

SIGTERM raises :class:`Terminated`, a :class:`KeyboardInterrupt`: ``except Exception`` lets both
through and the command exits ``128 + signal`` (130, 143). Exudyn turns an exception in a Python
user function into a failed solve, so :func:`watch_signals` re-raises a signal foreign code swallowed.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType

__all__ = ["Terminated", "SignalWatch", "interruption", "exit_status", "terminate_raises",
           "watch_signals", "deferred_signals"]

WATCHED = (signal.SIGINT, signal.SIGTERM)
"""The signals that interrupt a command."""


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived (the ``cardan`` command's handler, :func:`terminate_raises`)."""

    signum = signal.SIGTERM


def interruption(signum: int) -> KeyboardInterrupt:
    """The exception that stands for signal ``signum``: :class:`Terminated` for SIGTERM."""
    return Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def exit_status(exc: BaseException) -> int:
    """``128 + signal`` for an interruption: 130 (SIGINT) unless the exception carries ``signum``."""
    return 128 + int(getattr(exc, "signum", signal.SIGINT))


def _main_thread() -> bool:
    """Whether this is the main thread, the only one where Python installs and runs handlers."""
    return threading.current_thread() is threading.main_thread()


def _raise_terminated(signum: int, frame: FrameType | None) -> None:
    """SIGTERM's handler within :func:`terminate_raises`."""
    raise Terminated()


@contextlib.contextmanager
def terminate_raises() -> Iterator[None]:
    """Within the block SIGTERM raises :class:`Terminated` (main thread only; an ignored SIGTERM stays
    ignored)."""
    if not _main_thread() or signal.getsignal(signal.SIGTERM) == signal.SIG_IGN:
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


class SignalWatch:
    """The signal (SIGINT or SIGTERM) that arrived within :func:`watch_signals`, or ``None``."""

    def __init__(self) -> None:
        self.signum: int | None = None

    def handler(self, previous: Callable[[int, FrameType | None], object]
                ) -> Callable[[int, FrameType | None], None]:
        """A handler that notes the signal, then runs ``previous`` (the handler it replaces)."""
        def record(signum: int, frame: FrameType | None) -> None:
            self.signum = signum
            previous(signum, frame)

        return record


@contextlib.contextmanager
def watch_signals() -> Iterator[SignalWatch]:
    """Record SIGINT and SIGTERM within the block and raise the interruption on leaving it, whatever
    the block raised or returned. Only Python-handled signals in the main thread; the handler still runs."""
    watch = SignalWatch()
    previous = {}
    if _main_thread():
        for signum in WATCHED:
            handler = signal.getsignal(signum)
            if callable(handler):
                previous[signum] = signal.signal(signum, watch.handler(handler))
    try:
        yield watch
    except BaseException as exc:
        if watch.signum is not None and not isinstance(exc, KeyboardInterrupt):
            raise interruption(watch.signum) from exc
        raise
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    if watch.signum is not None:
        raise interruption(watch.signum)


@contextlib.contextmanager
def deferred_signals() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back within the block (lines that must not be cut in half); one that
    arrived is handled at its end. A noting handler, not a signal mask: Python handles in the main thread."""
    if not _main_thread():
        yield
        return
    pending: list[int] = []
    previous = {}
    for signum in WATCHED:
        handler = signal.getsignal(signum)
        if callable(handler):  # an ignored or default signal is left alone
            previous[signum] = signal.signal(signum, lambda number, frame: pending.append(number))
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if pending:
            previous[pending[0]](pending[0], None)
