"""The report of a validation campaign (:func:`write_report`): ``results.json``, ``results.csv``, the
figures (:mod:`rigdata.campaign.figures`), and the document (:mod:`rigdata.campaign.content`) rendered
as ``report.md`` and ``report.html`` (:mod:`rigdata.campaign.render`), each file replaced atomically.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cardan_exudyn.jsonable import dumps
from cardan_exudyn.outputs import atomic_open
from rigdata.campaign.content import document
from rigdata.campaign.figures import FIGURES, png
from rigdata.campaign.render import html_page, markdown
from rigdata.campaign.result import CampaignResult

__all__ = ["write_report"]


def _figures(data: Mapping[str, Any]) -> dict[str, bytes]:
    """Each figure the data support as PNG bytes, by stem (no residuals without a calibration)."""
    return {name: png(draw(data)) for name, draw in FIGURES.items()
            if name != "residuals" or data.get("calibration")}


def _write_text(path: Path, text: str) -> None:
    """``text`` to ``path`` as UTF-8, atomically."""
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def write_report(result: CampaignResult, out: str | os.PathLike) -> dict[str, Path]:
    """Write the campaign's report into folder ``out`` (made if missing), each file replaced atomically.

    Files: ``results.json`` (:meth:`CampaignResult.as_dict`), ``results.csv``
    (:meth:`CampaignResult.table`), ``efficiency.png``, ``model_error.png``, ``budget.png``,
    ``residuals.png`` (with a calibration only; a stale one is removed), ``report.md`` and the
    self-contained ``report.html``. Other files in ``out`` (the journal) are kept.

    Returns
    -------
    dict of str to Path
        Each file written, by name.
    """
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    data = json.loads(dumps(result.as_dict()))
    written = {"results.json": folder / "results.json", "results.csv": folder / "results.csv"}
    _write_text(written["results.json"], dumps(data) + "\n")
    _write_text(written["results.csv"], result.table().to_csv(index=False))
    images = _figures(data)
    for name in FIGURES:
        path = folder / f"{name}.png"
        if name in images:
            with atomic_open(path, "wb") as f:
                f.write(images[name])
            written[path.name] = path
        elif path.is_file():
            path.unlink()
    title, sections = document(data)
    written["report.md"] = folder / "report.md"
    _write_text(written["report.md"], markdown(title, sections, tuple(images)))
    written["report.html"] = folder / "report.html"
    _write_text(written["report.html"], html_page(title, sections, images))
    return written
