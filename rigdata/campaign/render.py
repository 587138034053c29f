"""A campaign report's document (:mod:`rigdata.campaign.document`) as ``report.md`` (figures linked to
their PNG files) and as one self-contained ``report.html`` (inline CSS, figures as data URIs).
"""

from __future__ import annotations

import base64
import html
import re
from collections.abc import Mapping, Sequence

from cardan_exudyn.report.format import markdown_table
from rigdata.campaign.document import RESOLVABLE, Block, Image, Items, Section, Table, Text

__all__ = ["CSS", "markdown", "html_page"]


def _md_block(block: Block) -> str:
    """One block as markdown; a table's numeric columns right-aligned."""
    if isinstance(block, Text):
        return block.text
    if isinstance(block, Items):
        return "\n".join(f"- {item}" for item in block.items)
    if isinstance(block, Image):
        return f"![{block.caption}]({block.name}.png)\n\n*{block.caption}*"
    rows = [{str(j): _md_cell(cell, block.tones.get((i, j))) for j, cell in enumerate(row)}
            for i, row in enumerate(block.rows)]
    keys = [str(j) for j in range(len(block.headers))]
    right = [key for key, numeric in zip(keys, block.numeric, strict=True) if numeric]
    return markdown_table(rows, keys, headers=block.headers, right=right).rstrip("\n")


def _md_cell(text: str, tone: str | None) -> str:
    """A table cell in markdown: a resolvable verdict in bold."""
    return f"**{text}**" if tone == RESOLVABLE else text


def markdown(title: str, sections: Sequence[Section], images: Sequence[str] = ()) -> str:
    """``report.md``: the document with the figures named in ``images`` as links to their PNG files."""
    lines = [f"# {title}", ""]
    for section in sections:
        if section.title:
            lines += [f"## {section.title}", ""]
        for block in section.blocks:
            if isinstance(block, Image) and block.name not in images:
                continue
            lines += [_md_block(block), ""]
    return "\n".join(lines)


_BOLD = re.compile(r"\*\*(.+?)\*\*")
_CODE = re.compile(r"`([^`]+)`")


def _inline(text: str) -> str:
    """Escaped HTML of a paragraph with ``**bold**`` and ```code```."""
    return _CODE.sub(r"<code>\1</code>", _BOLD.sub(r"<strong>\1</strong>", html.escape(text, quote=False)))


def _html_cell(text: str, numeric: bool, tone: str | None) -> str:
    """One ``<td>``: class ``num`` for a number, the tone's class for a verdict."""
    classes = " ".join(c for c in ("num" if numeric else None, tone) if c)
    return f'<td class="{classes}">{_inline(text)}</td>' if classes else f"<td>{_inline(text)}</td>"


def _html_table(table: Table) -> str:
    """A table in HTML, numbers right-aligned, toned cells coloured."""
    head = "".join(f'<th class="{"num" if n else "text"}">{html.escape(h)}</th>'
                   for h, n in zip(table.headers, table.numeric, strict=True))
    body = []
    for i, row in enumerate(table.rows):
        cells = [_html_cell(cell, table.numeric[j], table.tones.get((i, j))) for j, cell in enumerate(row)]
        body.append("<tr>" + "".join(cells) + "</tr>")
    return (f'<div class="scroll"><table><thead><tr>{head}</tr></thead><tbody>{"".join(body)}</tbody>'
            "</table></div>")


def _html_block(block: Block, images: Mapping[str, bytes]) -> str:
    """One block as HTML; figures inline as base64 PNG."""
    if isinstance(block, Text):
        tone = f' class="{block.tone}"' if block.tone else ""
        return f"<p{tone}>{_inline(block.text)}</p>"
    if isinstance(block, Items):
        return "<ul>" + "".join(f"<li>{_inline(item)}</li>" for item in block.items) + "</ul>"
    if isinstance(block, Image):
        if block.name not in images:
            return ""
        data = base64.b64encode(images[block.name]).decode("ascii")
        return (f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(block.caption)}">'
                f"<figcaption>{_inline(block.caption)}</figcaption></figure>")
    return _html_table(block)


CSS = """
body { font: 15px/1.5 system-ui, -apple-system, "Segoe UI", "DejaVu Sans", sans-serif; color: #1a1a1a;
       max-width: 1500px; margin: 0 auto; padding: 1.5em 2em; }
h1 { font-size: 1.6em; border-bottom: 2px solid #333; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px solid #ccc; padding-bottom: .15em; }
code { font: .9em ui-monospace, "DejaVu Sans Mono", monospace; background: #f3f3f3; padding: 0 .25em; }
.scroll { overflow-x: auto; margin: .8em 0; }
table { border-collapse: collapse; font-size: .88em; }
th, td { border: 1px solid #d0d0d0; padding: .3em .55em; vertical-align: top; }
th { background: #eef1f4; text-align: left; vertical-align: bottom; }
th.num { text-align: right; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafafa; }
td.resolvable, td.not-resolvable, td.calibration, td.failed { white-space: nowrap; }
td.resolvable { background: #fde2df; color: #a30f0f; font-weight: 600; }
td.not-resolvable { background: #e2f3e4; color: #1d5e2a; }
td.calibration { background: #ececec; color: #555; font-style: italic; }
td.failed { background: #fff0c7; color: #6b4a00; font-weight: 600; }
p.banner { background: #b00020; color: #fff; padding: .6em .9em; border-radius: 4px; }
p.banner code { background: rgba(255, 255, 255, .18); color: #fff; }
p.warning { background: #fff4e5; border-left: 4px solid #e65100; padding: .5em .8em; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: .9em; color: #444; font-style: italic; }
"""


def html_page(title: str, sections: Sequence[Section], images: Mapping[str, bytes]) -> str:
    """``report.html``: the document in one self-contained page (inline CSS, figures as data URIs)."""
    parts = [f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{html.escape(title)}"
             f"</title><style>{CSS}</style></head><body>", f"<h1>{html.escape(title)}</h1>"]
    for section in sections:
        if section.title:
            parts.append(f"<h2>{html.escape(section.title)}</h2>")
        parts += [_html_block(block, images) for block in section.blocks]
    parts.append("</body></html>\n")
    return "\n".join(p for p in parts if p)
