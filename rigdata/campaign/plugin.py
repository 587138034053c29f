"""The pytest plugin of rigdata (entry point ``pytest11``; ``-p no:rigdata`` leaves it out): the session
fixture ``rig_campaign(path, **options)`` runs a campaign once per session, its model runs journalled in
pytest's cache across sessions (``--rig-campaign-no-cache``: none). ``docs/pytest.md``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

__all__ = ["rig_campaign"]


def pytest_addoption(parser: pytest.Parser) -> None:
    """The ``--rig-campaign-*`` options."""
    group = parser.getgroup("rigdata", "rigdata (validation campaigns)")
    group.addoption("--rig-campaign-no-cache", action="store_true", default=False,
                    help="run every model of a campaign again instead of reusing pytest's cache")


@pytest.fixture(scope="session")
def rig_campaign(request: pytest.FixtureRequest) -> Callable[..., Any]:
    """``rig_campaign(path, **options) -> CampaignResult``: relative paths from the rootdir; each campaign
    file runs once per session; ``options`` as for :func:`rigdata.campaign.campaign`.
    """
    from rigdata.campaign.testing import run_campaign

    config = request.config
    cache = getattr(config, "cache", None)  # None under -p no:cacheprovider: no journal across sessions
    keep = cache is not None and not config.getoption("rig_campaign_no_cache")
    root = cache.mkdir("rigdata-campaign") if keep else None
    done: dict[tuple, Any] = {}

    def run(path: str | Path, **options: Any) -> Any:
        target = Path(path)
        if not target.is_absolute():
            target = Path(config.rootpath) / target
        key = (str(target.resolve()), tuple(sorted(options.items())))
        if key not in done:
            done[key] = run_campaign(target, root, **options)
        return done[key]

    return run
