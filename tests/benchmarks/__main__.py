"""``python tests/benchmarks NAME [options]``: run one of the project's benchmarks
(``docs/benchmarks.md``; ``--help`` lists them)."""

import sys
from pathlib import Path

TESTS = str(Path(__file__).resolve().parents[1])
# this folder is the script's path entry; its parent makes it the package ``benchmarks``
sys.path[0] = TESTS

from benchmarks.cli import main  # noqa: E402 (after the path is set)

sys.exit(main())
