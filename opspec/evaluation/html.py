"""Reports people read: one self-contained HTML file, and the same content as Markdown.

A report is a title and a sequence of :class:`Section` values (paragraphs, tables, figures).
:func:`write_html` writes one file that needs nothing else: the CSS is inline and each PNG
is embedded as a base64 ``data:`` URI, so the report can be mailed or archived as it is.
:func:`write_markdown` writes the same content as GitHub-flavoured Markdown that links the
PNG files by relative path (keep them next to it).

All text (titles, paragraphs, cells, captions) is plain text and is escaped: a metric or
activity name such as ``<script>`` shows up literally and never becomes markup. The output
is deterministic (no dates, no random ids), so two runs with the same results give the same
bytes.

Accessibility: one ``h1``, an ``h2`` per section, a table of contents, ``caption`` and
``th scope`` in tables, ``alt`` text on every figure, dark text on white (contrast above
WCAG AA), and a layout that reflows on a phone (tables scroll sideways inside their box).
"""

from __future__ import annotations

import base64
import html
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from opspec.errors import EvaluationError

__all__ = ["Section", "Table", "write_html", "write_markdown"]


@dataclass(frozen=True)
class Table:
    """A table of plain-text cells; ``rows`` should have as many cells as ``headers``."""

    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    caption: str = ""


@dataclass(frozen=True)
class Section:
    """One titled part of a report: paragraphs, then tables, then figures (PNG files).

    ``captions`` optionally gives each image its caption and alt text (same order as
    ``images``); without one, the text is derived from the file name.
    """

    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    images: tuple[Path, ...] = ()
    captions: tuple[str, ...] = ()


_CSS = """
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { margin: 0 auto; max-width: 72rem; padding: 1rem 1.25rem 3rem;
  font: 1rem/1.55 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial,
  sans-serif; color: #111; background: #fff; }
h1 { font-size: 1.75rem; line-height: 1.25; margin: 0.5rem 0 1rem; }
h2 { font-size: 1.35rem; margin: 2.25rem 0 0.75rem; padding-bottom: 0.25rem;
  border-bottom: 2px solid #0b3d91; }
p { margin: 0.5rem 0; max-width: 48rem; }
nav ol { padding-left: 1.25rem; }
a { color: #0b3d91; }
a:focus, a:hover { outline: 2px solid #0b3d91; outline-offset: 2px; }
.table-wrap { overflow-x: auto; margin: 1rem 0; border: 1px solid #bbb; }
table { border-collapse: collapse; width: 100%; font-variant-numeric: tabular-nums; }
caption { caption-side: top; text-align: left; font-weight: 600; padding: 0.5rem 0.6rem; }
th, td { padding: 0.4rem 0.6rem; border-bottom: 1px solid #ccc; text-align: left;
  vertical-align: top; }
thead th { background: #e8edf5; border-bottom: 2px solid #555; }
tbody th { font-weight: 600; }
tbody tr:nth-child(even) { background: #f6f6f6; }
td.num { text-align: right; white-space: nowrap; }
figure { margin: 1.25rem 0; }
figure img { display: block; max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.95rem; color: #333; margin-top: 0.35rem; }
@media (max-width: 40rem) { body { padding: 0.75rem; } h1 { font-size: 1.45rem; } }
"""

_NUMERIC = re.compile(r"^[\s+\-−]?[\d.,]+(e[+-]?\d+)?\s*(%|s|ms|µs)?$|^\[.*\]$|^(nan|inf)$",
                      re.IGNORECASE)


def _esc(text: object) -> str:
    return html.escape(str(text), quote=True)


def _slug(text: str, index: int) -> str:
    base = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:40]
    return f"s{index}-{base}" if base else f"s{index}"


def _alt(section: Section, index: int, image: Path) -> str:
    if index < len(section.captions) and section.captions[index].strip():
        return section.captions[index]
    words = Path(image).stem.replace("_", " ").replace("-", " ").strip()
    return f"{section.title}: figure {words}" if words else f"{section.title}: figure"


def _read_png(image: Path) -> bytes:
    try:
        return Path(image).read_bytes()
    except OSError as error:
        raise EvaluationError(f"cannot embed the figure {image} in the report: "
                              f"{error.strerror or error}",
                              hint="write the figures before the report") from None


def _write(path: Path, text: str) -> Path:
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)   # never leave a half-written report behind
    except OSError as error:
        raise EvaluationError(f"cannot write the report {path}: {error.strerror or error}",
                              hint="check that the output folder is writable and the disk "
                                   "is not full") from None
    return path


# ------------------------------------------------------------------------------------ HTML

def _html_table(table: Table) -> list[str]:
    out = ['<div class="table-wrap" role="region" tabindex="0"'
           + (f' aria-label="{_esc(table.caption)}">' if table.caption else ">"),
           "<table>"]
    if table.caption:
        out.append(f"<caption>{_esc(table.caption)}</caption>")
    out.append("<thead><tr>" + "".join(f'<th scope="col">{_esc(h)}</th>'
                                       for h in table.headers) + "</tr></thead>")
    out.append("<tbody>")
    for row in table.rows:
        cells = []
        for i, cell in enumerate(row):
            text = _esc(cell)
            if i == 0:
                cells.append(f'<th scope="row">{text}</th>')
            elif _NUMERIC.match(str(cell).strip() or "x"):
                cells.append(f'<td class="num">{text}</td>')
            else:
                cells.append(f"<td>{text}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table></div>")
    return out


def write_html(path: Path, title: str, sections: Sequence[Section]) -> Path:
    """Write the report as one self-contained HTML file; returns ``path``.

    Raises :class:`~opspec.errors.EvaluationError` when a figure cannot be read or the file
    cannot be written (the previous report, if any, is then left untouched).
    """
    parts = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             f"<title>{_esc(title)}</title>", f"<style>{_CSS}</style>", "</head>", "<body>",
             "<header>", f"<h1>{_esc(title)}</h1>", "</header>"]
    ids = [_slug(s.title, i) for i, s in enumerate(sections, start=1)]
    if len(sections) > 1:
        parts.append('<nav aria-label="Contents"><h2 id="contents">Contents</h2><ol>')
        parts.extend(f'<li><a href="#{sid}">{_esc(s.title)}</a></li>'
                     for sid, s in zip(ids, sections, strict=True))
        parts.append("</ol></nav>")
    parts.append("<main>")
    for sid, section in zip(ids, sections, strict=True):
        parts.append(f'<section aria-labelledby="{sid}">')
        parts.append(f'<h2 id="{sid}">{_esc(section.title)}</h2>')
        parts.extend(f"<p>{_esc(p)}</p>" for p in section.paragraphs)
        for table in section.tables:
            parts.extend(_html_table(table))
        for i, image in enumerate(section.images):
            data = base64.b64encode(_read_png(image)).decode("ascii")
            alt = _esc(_alt(section, i, image))
            parts.append(f'<figure><img src="data:image/png;base64,{data}" alt="{alt}">'
                         f"<figcaption>{alt}</figcaption></figure>")
        parts.append("</section>")
    parts.extend(["</main>", "</body>", "</html>", ""])
    return _write(path, "\n".join(parts))


# -------------------------------------------------------------------------------- Markdown

_MD_SPECIAL = re.compile(r"([\\`*_\[\]|~])")
# what would start a block at the beginning of a line: "> ", "# ", "- ", "+ ", "1. ", "2) "
_MD_LINE_START = re.compile(r"^(\s*\d*)(>|(?<=\d)[.)](?=\s|$)|(?<![\d])[#+-](?=\s|$))")


def _md(text: object) -> str:
    """Plain text made inert in Markdown: HTML escaped, Markdown punctuation backslashed.

    With ``[`` and ``]`` escaped no link or image can form, so parentheses stay as they are;
    a leading ``#``, ``>``, ``+``, ``-`` or ``1.`` is escaped so it starts no block.
    """
    escaped = html.escape(" ".join(str(text).splitlines()), quote=False)
    escaped = _MD_SPECIAL.sub(r"\\\1", escaped)
    return _MD_LINE_START.sub(lambda m: m.group(1) + "\\" + m.group(2), escaped)


def _md_table(table: Table) -> list[str]:
    out = []
    if table.caption:
        out += [f"**{_md(table.caption)}**", ""]
    width = max(1, len(table.headers), *(len(r) for r in table.rows))
    headers = list(table.headers) + [""] * (width - len(table.headers))
    out.append("| " + " | ".join(_md(h) for h in headers) + " |")
    out.append("|" + "|".join(" --- " for _ in headers) + "|")
    for row in table.rows:
        cells = list(row) + [""] * (width - len(row))
        out.append("| " + " | ".join(_md(c) for c in cells) + " |")
    out.append("")
    return out


def write_markdown(path: Path, title: str, sections: Sequence[Section]) -> Path:
    """Write the report as Markdown, linking each PNG by its path relative to ``path``."""
    path = Path(path)
    folder = path.parent.resolve()
    lines = [f"# {_md(title)}", ""]
    for section in sections:
        lines += [f"## {_md(section.title)}", ""]
        for paragraph in section.paragraphs:
            lines += [_md(paragraph), ""]
        for table in section.tables:
            lines += _md_table(table)
        for i, image in enumerate(section.images):
            rel = Path(os.path.relpath(Path(image).resolve(), folder)).as_posix()
            target = rel.replace(" ", "%20").replace("(", "%28").replace(")", "%29")
            lines += [f"![{_md(_alt(section, i, image))}]({target})", ""]
    return _write(path, "\n".join(lines).rstrip("\n") + "\n")
