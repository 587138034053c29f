"""What ``cardan run`` costs beyond importing numpy and Exudyn and its own solve.

    python tests/benchmarks/run_overhead.py [--repeats N] [cardan run arguments ...]
    (default: --name paper-10deg-frictionless --revolutions 1; 5 repeats)

Each repeat times, in fresh interpreters side by side, ``python -c "import numpy, exudyn"`` and the
command with ``--json``, and subtracts the baseline and the run's own ``wall_time_s`` (its solves)
from the command's wall time. Prints the median and every repeat [s]; the target is 0.15 s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

DEFAULT = ["--name", "paper-10deg-frictionless", "--revolutions", "1"]
TARGET_S = 0.15


def timed(command: list[str]) -> tuple[float, str]:
    """Wall time [s] and stdout of ``command``."""
    start = time.perf_counter()
    proc = subprocess.run(command, capture_output=True, text=True, check=True)
    return time.perf_counter() - start, proc.stdout


def overhead(run_args: list[str], repeats: int) -> list[float]:
    """Per repeat: the command's wall time minus the numpy+Exudyn import and its solve [s]."""
    out = []
    for _ in range(repeats):
        base, _ = timed([sys.executable, "-c", "import numpy, exudyn"])
        total, stdout = timed([sys.executable, "-m", "cardan_exudyn.cli", "run", *run_args, "--json"])
        out.append(total - base - json.loads(stdout)["wall_time_s"])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    known, rest = parser.parse_known_args()
    values = overhead(rest or DEFAULT, known.repeats)
    print(f"beyond numpy+exudyn and the solve: median {statistics.median(values):.3f} s "
          f"(target {TARGET_S} s); all {[round(v, 3) for v in values]}")


if __name__ == "__main__":
    main()
