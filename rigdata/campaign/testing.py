"""Campaigns in users' pytest suites: :func:`run_campaign` (journalled, so a second session reruns no
model) and :func:`assert_model_valid`, whose failure message is the table of the recordings at fault.
The ``rig_campaign`` fixture (:mod:`rigdata.campaign.plugin`) wraps both; ``docs/pytest.md``.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

from rigdata.campaign.result import CampaignResult, RecordingResult

__all__ = ["cache_folder", "run_campaign", "resolvable_table", "assert_model_valid"]


def cache_folder(campaign_file: str | os.PathLike, root: str | os.PathLike) -> Path:
    """The journal folder of ``campaign_file`` under ``root``: one per campaign file (by absolute path)."""
    path = Path(campaign_file).resolve()
    digest = hashlib.sha256(str(path).encode()).hexdigest()[:16]
    return Path(root) / f"{path.stem}-{digest}"


def run_campaign(campaign_file: str | os.PathLike, cache: str | os.PathLike | None = None,
                 **options: Any) -> CampaignResult:
    """:func:`rigdata.campaign.campaign` of ``campaign_file`` with its journal under ``cache`` (None: none),
    so every model run already made for exactly the same scene is reused.
    """
    from rigdata.campaign.run import campaign

    out = cache_folder(campaign_file, cache) if cache is not None else None
    return campaign(campaign_file, out, **options)


def _row(r: RecordingResult) -> str:
    """One recording as a table row."""
    if r.status != "ok" or r.first is None or r.first.u_val is None:
        return f"| {r.label} | {r.use} | {r.status}: {r.reason} | | | |"
    first = r.first
    low, high = first.model_error_interval
    return (f"| {r.label} | {r.use} | E = {first.comparison_error:+.5f} | k u_val = {r.k * first.u_val:.2g} "
            f"| [{low:+.5f}, {high:+.5f}] | {r.dominant} |")


def resolvable_table(recordings: tuple[RecordingResult, ...]) -> str:
    """A Markdown table of ``recordings``: comparison error, ``k u_val``, interval, dominant source."""
    head = ["| recording | use | comparison error | expanded u_val | model error interval | dominant |",
            "|---|---|---|---|---|---|"]
    return "\n".join(head + [_row(r) for r in recordings])


def assert_model_valid(result: CampaignResult, *, allow_failed: bool = False,
                       allow_rejected: bool = False) -> None:
    """AssertionError listing every validation recording whose model error is resolvable
    (``|E| > k u_val``); also for a recording without a comparison (unless ``allow_failed``) and a
    calibration the data reject (unless ``allow_rejected``).
    """
    problems = []
    if result.resolvable:
        problems.append(f"the model error is resolvable in {len(result.resolvable)} of "
                        f"{len(result.validation)} validation recordings (k = {result.k:.3g}):\n"
                        + resolvable_table(result.resolvable))
    if result.failed and not allow_failed:
        problems.append(f"{len(result.failed)} recordings have no comparison:\n"
                        + resolvable_table(result.failed))
    cal = result.calibration
    if cal is not None and cal.rejected and not allow_rejected:
        problems.append(f"the calibration recordings reject the model: chi-square {cal.chi_square:.3g} on "
                        f"{cal.dof} degrees of freedom, p = {cal.p_value:.3g}")
    if result.calibration_error and not allow_failed:
        problems.append(f"the calibration failed: {result.calibration_error}")
    if problems:
        raise AssertionError("\n\n".join(problems))
