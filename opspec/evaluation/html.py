"""Reports people read: one self-contained HTML file, and the same content as Markdown.

A report is a title and a sequence of :class:`Section` values (paragraphs, lists, tables,
figures). :func:`write_html` renders them with a Jinja2 template (the bundled
``templates/report.html.j2``, or a researcher's own copy restyled) into one file that needs
nothing else: the CSS is inline, each SVG figure is inlined as markup (matplotlib wrote it
from our own data; its text is XML-escaped) and each PNG is embedded as a base64 ``data:``
URI, so the report can be mailed or archived as it is.
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
import contextlib
import functools
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError

__all__ = ["TEMPLATE", "Section", "Table", "prepare_template", "render_html", "write_html",
           "write_markdown"]


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
    ``images``); without one, the text is derived from the file name. ``items`` is a
    bulleted list shown after the paragraphs (key findings, assumptions).
    """

    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    images: tuple[Path, ...] = ()
    captions: tuple[str, ...] = ()
    items: tuple[str, ...] = ()


_NUMERIC = re.compile(r"^(total )?[\s+\-−]?[\d.,]+(e[+-]?\d+)?\s*(%|s|ms|µs|pp|per user)?$"
                      r"|^\[.*\]$|^(nan|inf|–)$", re.IGNORECASE)


def _slug(text: str, index: int) -> str:
    base = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:40]
    return f"s{index}-{base}" if base else f"s{index}"


def _alt(section: Section, index: int, image: Path) -> str:
    if index < len(section.captions) and section.captions[index].strip():
        return section.captions[index]
    words = Path(image).stem.replace("_", " ").replace("-", " ").strip()
    return f"{section.title}: figure {words}" if words else f"{section.title}: figure"


_SVG_START = re.compile(r"<svg\b")


def _figure(section: Section, index: int, image: Path) -> dict[str, object]:
    """What the template needs of one figure: an SVG's markup, to be inlined (vector, and
    its text stays searchable), or a PNG as a ``data:`` URI; the caption; the file name."""
    import markupsafe  # jinja2's own

    caption = _alt(section, index, image)
    if Path(image).suffix.lower() == ".svg":
        data = _read_png(image)
        text = data.decode("utf-8")
        start = _SVG_START.search(text)       # without the XML declaration and DOCTYPE
        svg = markupsafe.Markup(text[start.start():] if start else text)
        # src too: a template written for <img src> keeps working
        return {"svg": svg, "src": "data:image/svg+xml;base64,"
                + base64.b64encode(data).decode("ascii"), "caption": caption,
                "name": Path(image).name}
    return {"svg": "", "src": "data:image/png;base64,"
            + base64.b64encode(_read_png(image)).decode("ascii"),
            "caption": caption, "name": Path(image).name}


def _read_png(image: Path) -> bytes:
    try:
        return Path(image).read_bytes()
    except OSError as error:
        raise EvaluationError(f"cannot embed the figure {image} in the report: "
                              f"{error.strerror or error}",
                              hint="write the figures before the report") from None


def _write(path: Path, text: str) -> Path:
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)   # never leave a half-written report behind
    except OSError as error:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)     # nor the part of it that did fit
        raise EvaluationError(f"cannot write the report {path}: {error.strerror or error}",
                              hint="check that the output folder is writable and the disk "
                                   "is not full") from None
    return path


# ------------------------------------------------------------------------------------ HTML

#: The bundled template (package data): copy it, restyle it, and pass the copy as
#: ``template`` (``opspec evaluate --report-template FILE``).
TEMPLATE = Path(__file__).with_name("templates") / "report.html.j2"


def _numeric_columns(table: Table) -> set[int]:
    """Columns whose every cell is a number (or –): right-aligned. A column that mixes
    numbers and words stays left-aligned, so it reads as one column."""
    width = max((len(r) for r in table.rows), default=0)
    return {i for i in range(1, width)
            if any(str(r[i]).strip() not in {"", "–"} for r in table.rows if i < len(r))
            and all(_NUMERIC.match(str(r[i]).strip() or "–") for r in table.rows
                    if i < len(r))}


def _cell(index: int, text: str, numeric: set[int]) -> dict[str, str]:
    if index == 0:
        return {"tag": "th", "text": text, "class": ""}
    return {"tag": "td", "text": text, "class": "num" if index in numeric else ""}


def _context(title: str, sections: Sequence[Section]) -> dict[str, object]:
    """What the template sees: plain data, every string still unescaped (the template
    environment escapes everything it prints)."""
    ids = [_slug(s.title, i) for i, s in enumerate(sections, start=1)]
    out = []
    for sid, section in zip(ids, sections, strict=True):
        tables = []
        for t in section.tables:
            numeric = _numeric_columns(t)
            tables.append({"caption": t.caption,
                           "headers": [{"text": h, "class": "num" if i in numeric else ""}
                                       for i, h in enumerate(t.headers)],
                           "rows": [[_cell(i, str(c), numeric) for i, c in enumerate(row)]
                                    for row in t.rows]})
        figures = [_figure(section, i, image) for i, image in enumerate(section.images)]
        out.append({"id": sid, "title": section.title, "paragraphs": list(section.paragraphs),
                    "items": list(section.items), "tables": tables, "figures": figures})
    return {"title": title, "sections": out}


def render_html(title: str, sections: Sequence[Section],
                template: str | Path | None = None) -> str:
    """The report as one HTML document, rendered by Jinja2 (autoescaping on) from
    ``template`` (default: the bundled :data:`TEMPLATE`)."""
    import jinja2

    source, compiled = _template(template)
    try:
        return compiled.render(_context(title, sections))
    except jinja2.TemplateError as error:
        raise _template_fails(source, error) from None


def prepare_template(template: str | Path | None = None) -> None:
    """Read and compile ``template`` now (Jinja2 imported, the template made Python code),
    so that :func:`render_html` finds it ready; what fails here fails there again, with
    its message (``opspec evaluate`` prepares it while its workers run)."""
    _template(template)


def _template(template: str | Path | None) -> tuple[Path, Any]:
    """The template's path and its compiled form, compiled once per text: a changed file
    is compiled again."""
    import jinja2

    from opspec.files import read_text, reason

    source = Path(template) if template is not None else TEMPLATE
    try:
        text = read_text(source)          # a pipe or device is refused, never read (blocks)
    except OSError as error:
        raise EvaluationError(f"cannot read the report template {source}: {reason(error)}",
                              hint="give an existing Jinja2 template (copy "
                              f"{TEMPLATE} to start from)") from None
    try:
        return source, _compiled(text)
    except jinja2.TemplateError as error:
        raise _template_fails(source, error) from None


@functools.lru_cache(maxsize=4)
def _compiled(text: str) -> Any:
    from jinja2 import StrictUndefined
    from jinja2.sandbox import SandboxedEnvironment

    # a template is code: sandboxed, it sees the report's data and cannot reach Python's
    # internals (no ``''.__class__.__mro__``, no calls of unsafe methods)
    env = SandboxedEnvironment(autoescape=True, undefined=StrictUndefined,
                               keep_trailing_newline=True, trim_blocks=True,
                               lstrip_blocks=True)
    return env.from_string(text)


def _template_fails(source: Path, error: Exception) -> EvaluationError:
    line = getattr(error, "lineno", None)
    message = getattr(error, "message", None)
    return EvaluationError(f"{source}{f':{line}' if line else ''}: the report template "
                           f"fails: {message or error}",
                           hint="fix the template, or leave out --report-template to "
                           "use the bundled one")


def write_html(path: Path, title: str, sections: Sequence[Section], *,
               template: str | Path | None = None) -> Path:
    """Write the report as one self-contained HTML file; returns ``path``.

    Raises :class:`~opspec.errors.EvaluationError` when a figure cannot be read, the
    template fails or the file cannot be written (the previous report, if any, is then left
    untouched).
    """
    return _write(path, render_html(title, sections, template))


# -------------------------------------------------------------------------------- Markdown

_MD_SPECIAL = re.compile(r"([\\`*_\[\]|~])")
# what alone makes markup of "<" and "&" in CommonMark: "<" before a letter, "/", "!" or "?"
# (an HTML tag, comment or declaration; an autolink <scheme:…>), "&" starting an entity
# (&amp; &#38; &#x26;); "U < 2" and "Korn & Graubard" are plain text as they are
_MD_MARKUP = re.compile(r"(<)(?=[A-Za-z/!?])|(&)(?=#?[A-Za-z0-9]+;)")
# what would start a block at the beginning of a line: "> ", "# ", "- ", "+ ", "1. ", "2) "
_MD_LINE_START = re.compile(r"^(\s*\d*)(>|(?<=\d)[.)](?=\s|$)|(?<![\d])[#+-](?=\s|$))")


def _md(text: object) -> str:
    """Plain text made inert in Markdown, and left readable: Markdown punctuation
    backslashed, and ``<`` and ``&`` only where they would start markup (a tag such as
    ``<script>`` becomes ``\\<script>``, which shows as written and is no tag; ``U < 2``
    stays as it is, not ``U &lt; 2``).

    With ``[`` and ``]`` escaped no link or image can form, so parentheses stay as they are;
    a leading ``#``, ``>``, ``+``, ``-`` or ``1.`` is escaped so it starts no block.
    """
    escaped = _MD_SPECIAL.sub(r"\\\1", " ".join(str(text).splitlines()))
    escaped = _MD_MARKUP.sub(lambda m: "\\" + (m.group(1) or m.group(2)), escaped)
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
        if section.items:
            lines += [f"- {_md(item)}" for item in section.items] + [""]
        for table in section.tables:
            lines += _md_table(table)
        for i, image in enumerate(section.images):
            rel = Path(os.path.relpath(Path(image).resolve(), folder)).as_posix()
            target = rel.replace(" ", "%20").replace("(", "%28").replace(")", "%29")
            lines += [f"![{_md(_alt(section, i, image))}]({target})", ""]
    return _write(path, "\n".join(lines).rstrip("\n") + "\n")
