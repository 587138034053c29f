"""The walk of a ``cardan`` command through the project's modules, as ``sys.setprofile`` sees it.

    python tests/benchmarks/walk.py [--all] [cardan arguments ...]   (default: run --name paper-10deg)

Prints, for the command run in this process:

- the modules in the order they are first entered (a Python function of the module called), each
  with the module it was entered from;
- every switch between project modules by a call, ``caller -> callee`` with its count;
- the trips back: calls into a module that is already on the call stack below another module
  (``A -> B -> A``), each with the first stack it happened on. None means the modules' calls
  form layers: once the walk leaves a module downwards, only a return brings it back.

Project modules are those of ``reference``, ``cardan_exudyn`` and ``rigdata``; what runs while a
module is imported is not recorded (an import is not a step of the walk); calls through other
code (numpy, Exudyn's C++ loop calling the friction coupling's user function) count as a switch
between the project modules on either side. Without ``--all`` only the modules that run the
command (``cardan_exudyn`` but its studies and reports) are listed; ``--all`` lists every one.
"""

from __future__ import annotations

import contextlib
import io
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("reference", "cardan_exudyn", "rigdata")
IMPORT = "(import)"
"""The stack entry of a module body being executed: what runs under it is not recorded."""


class Walk:
    """Records first entries, call switches and trips back between project modules."""

    def __init__(self) -> None:
        self.first: dict[str, str] = {}       # module -> the module it was first entered from
        self.switches: Counter[tuple[str, str]] = Counter()
        self.trips: dict[tuple[str, ...], int] = {}
        self._stack: list[str | None] = []    # per Python frame: its project module, or None

    @staticmethod
    def module(frame) -> str | None:
        """The project module of a frame's function; None for other code; :data:`IMPORT` for a
        module's own body."""
        if frame.f_code.co_name == "<module>":
            return IMPORT
        name = frame.f_globals.get("__name__", "")
        return name if name.split(".")[0] in PACKAGES else None

    def current(self) -> str | None:
        return next((m for m in reversed(self._stack) if m not in (None, IMPORT)), None)

    def __call__(self, frame, event: str, arg) -> None:
        if event == "call":
            self._enter(self.module(frame))
        elif event == "return" and self._stack:
            self._stack.pop()

    def _enter(self, callee: str | None) -> None:
        caller = self.current()
        if callee is not None and callee != caller and IMPORT not in self._stack and callee != IMPORT:
            self.first.setdefault(callee, caller or "(start)")
            if caller is not None:
                self.switches[caller, callee] += 1
            if callee in self._stack:
                self._trip(callee)
        self._stack.append(callee)

    def _trip(self, callee: str) -> None:
        """Count the path from ``callee``'s frame on the stack up to the call back into it."""
        below = self._stack[self._stack.index(callee):]
        path: list[str] = []
        for m in below:
            if m not in (None, IMPORT) and (not path or path[-1] != m):
                path.append(m)
        key = (*path, callee)
        self.trips[key] = self.trips.get(key, 0) + 1


def walk(argv: list[str]) -> Walk:
    """Run ``cardan`` with ``argv`` in this process (its output swallowed) under the profiler."""
    sys.path.insert(0, str(ROOT))
    from cardan_exudyn.cli import main

    recorder = Walk()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        sys.setprofile(recorder)
        try:
            main(argv)
        except SystemExit:
            pass
        finally:
            sys.setprofile(None)
    return recorder


def runs_the_command(module: str) -> bool:
    """The modules that run a command: cardan_exudyn but its studies and reports."""
    return module.startswith("cardan_exudyn") and not module.startswith(
        ("cardan_exudyn.studies", "cardan_exudyn.report"))


def report(recorder: Walk, everything: bool) -> str:
    keep = (lambda m: True) if everything else runs_the_command
    lines = ["first entries (module <- entered from):"]
    lines += [f"  {i:2d}. {m} <- {src}" for i, (m, src) in
              enumerate(((m, s) for m, s in recorder.first.items() if keep(m)), start=1)]
    lines.append("call switches (caller -> callee: calls):")
    lines += [f"  {a} -> {b}: {n}" for (a, b), n in recorder.switches.items() if keep(a) and keep(b)]
    trips = {path: n for path, n in recorder.trips.items() if everything or any(map(keep, path))}
    lines.append(f"trips back: {len(trips) or 'none'}")
    lines += [f"  {' -> '.join(path)}: {n}" for path, n in trips.items()]
    return "\n".join(lines)


if __name__ == "__main__":
    args = sys.argv[1:]
    everything = "--all" in args
    args = [a for a in args if a != "--all"] or ["run", "--name", "paper-10deg"]
    print(report(walk(args), everything))
