"""The pytest plugin of cardan-exudyn (entry point ``pytest11``; ``-p no:cardan_exudyn`` leaves it out).

Session fixtures ``cardan_scene`` and ``cardan_run``, the marker ``cardan_slow`` and the options
``--cardan-skip-slow``, ``--cardan-no-cache``, ``--cardan-runs``. See ``docs/pytest.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from cardan_exudyn.testing.runner import CachingRunner
    from reference.scene.scene import Scene

__all__ = ["SceneFactory", "RUNNER", "MARKER", "cardan_scene", "cardan_run"]

RUNNER = pytest.StashKey["CachingRunner"]()
"""Where the session's runner lives on the config (the fixture and the terminal summary)."""
MARKER = "cardan_slow"
"""The marker of tests with slow engine runs (skipped by ``--cardan-skip-slow``)."""


def pytest_addoption(parser: pytest.Parser) -> None:
    """The ``--cardan-*`` options."""
    group = parser.getgroup("cardan", "cardan-exudyn (Cardan-joint engine runs)")
    group.addoption("--cardan-skip-slow", action="store_true", default=False,
                    help=f"skip the tests marked {MARKER} (slow engine runs)")
    group.addoption("--cardan-no-cache", action="store_true", default=False,
                    help="run the engine on every cardan_run call, instead of once per scene, "
                         "engine and options in the session")
    group.addoption("--cardan-runs", action="store_true", default=False,
                    help="list the session's engine runs in the terminal summary: scene, engine, "
                         "status, mean efficiency, wall time, results reused from the cache")


def pytest_configure(config: pytest.Config) -> None:
    """Register :data:`MARKER`."""
    config.addinivalue_line("markers", f"{MARKER}: a test with slow engine runs; "
                                       "skipped with --cardan-skip-slow")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """With ``--cardan-skip-slow``, skip the collected ``items`` marked :data:`MARKER`."""
    if not config.getoption("cardan_skip_slow"):
        return
    skip = pytest.mark.skip(reason=f"{MARKER}: skipped by --cardan-skip-slow")
    for item in items:
        if item.get_closest_marker(MARKER) is not None:
            item.add_marker(skip)


class SceneFactory:
    """``cardan_scene(source, **changes) -> Scene``: :func:`~cardan_exudyn.testing.scenes.make_scene`
    with relative file paths taken from the rootdir; a bad scene fails the test with one line."""

    def __init__(self, root: Path) -> None:
        self.root = root

    def __call__(self, source: str | Path | Scene, **changes: Any) -> Scene:
        __tracebackhide__ = True
        # pytest imports this module at every start, in suites that never use it too: the
        # harness (numpy, the scene model, the engines) is imported when a fixture is first used
        from cardan_exudyn.testing.scenes import make_scene
        from reference.scene.validation import SceneError

        try:
            return make_scene(source, self.root, **changes)
        except SceneError as exc:
            message = f"cardan_scene: {exc}"
        pytest.fail(message, pytrace=False)  # outside the except: no chained traceback


@pytest.fixture(scope="session")
def cardan_scene(pytestconfig: pytest.Config) -> SceneFactory:
    """A factory of scenes: ``cardan_scene("rig", revolutions=1.0)``,
    ``cardan_scene("tests/joint.toml", numerics__accuracy=1e-6)`` (paths from the rootdir)."""
    return SceneFactory(pytestconfig.rootpath)


@pytest.fixture(scope="session")
def cardan_run(pytestconfig: pytest.Config) -> CachingRunner:
    """The session's :class:`~cardan_exudyn.testing.runner.CachingRunner`: ``cardan_run(scene,
    engine="exudyn", options=None) -> Result``, each run once, each call its own copy.
    """
    if RUNNER not in pytestconfig.stash:
        from cardan_exudyn.testing.runner import CachingRunner  # on first use, as make_scene

        pytestconfig.stash[RUNNER] = CachingRunner(cache=not pytestconfig.getoption("cardan_no_cache"))
    return pytestconfig.stash[RUNNER]


def pytest_terminal_summary(terminalreporter: Any, exitstatus: int, config: pytest.Config) -> None:
    """With ``--cardan-runs``, the session's engine runs as a table at the end of the report."""
    runner = config.stash.get(RUNNER, None)
    if runner is None or not config.getoption("cardan_runs"):
        return
    from cardan_exudyn.report.format import markdown_table  # the runner imported it already

    terminalreporter.write_sep("-", "cardan-exudyn engine runs")
    rows = [{"scene": r.scene, "revolutions": r.revolutions, "engine": r.engine, "dt [s]": r.dt,
             "status": r.status.value, "mean efficiency": r.mean_efficiency,
             "wall [s]": r.wall_time_s, "reused": r.reused} for r in runner.records]
    if rows:
        columns = ["scene", "revolutions", "engine", "dt [s]", "status", "mean efficiency",
                   "wall [s]", "reused"]
        formats = {"revolutions": "g", "dt [s]": ".4g", "mean efficiency": ".6f", "wall [s]": ".2f"}
        table = markdown_table(rows, columns, formats)
        for line in table.splitlines():
            terminalreporter.write_line(line)
    terminalreporter.write_line(f"{runner.runs} engine run(s), {runner.reused} result(s) reused "
                                "from the cache")
