"""The HTML report is one self-contained, escaped, accessible file; Markdown says the same."""

from __future__ import annotations

import base64
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from opspec.errors import EvaluationError
from opspec.evaluation import plots
from opspec.evaluation.html import Section, Table, write_html, write_markdown

HOSTILE = '<script>alert("x")</script> & <img src=http://evil.example/x.png onerror=1>'


class _Collector(HTMLParser):
    """Collects tags with attributes, and the text, of an HTML document."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def parse(path: Path) -> _Collector:
    collector = _Collector()
    collector.feed(path.read_text(encoding="utf-8"))
    collector.close()
    return collector


@pytest.fixture(scope="module")
def figures(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("figures")
    return (plots.latency_figure("report_latency_s", [30.0, 45.0, 60.0, 200.0],
                                 folder / "latency_report_latency_s.png"),
            plots.rates_figure([("doses missed", 0.01, 0.0, 0.03)], folder / "rates.png"))


def report_sections(figures: tuple[Path, Path]) -> list[Section]:
    latency, rates = figures
    table = Table(headers=("metric", "mean", "ci95"),
                  rows=(("doses_taken", "3.92", "[3.90, 3.94]"), (HOSTILE, "1", "x|y")),
                  caption="Per-user metrics")
    return [Section("Summary", paragraphs=("1,000 users over 30 days.", HOSTILE),
                    tables=(table,)),
            Section("Latency", images=(latency,),
                    captions=("Report latency: ECDF and histogram",)),
            Section(HOSTILE, images=(rates,))]


def test_html_report_is_self_contained(tmp_path: Path, figures: tuple[Path, Path]) -> None:
    out = write_html(tmp_path / "report.html", "Dispenser evaluation", report_sections(figures))
    doc = parse(out)
    for tag, attrs in doc.tags:
        for name in ("src", "href"):
            value = attrs.get(name)
            if value is not None:
                assert value.startswith(("data:", "#")), f"<{tag} {name}={value!r}> is external"
        assert tag not in {"script", "link", "iframe", "object"}, f"unexpected <{tag}>"


def test_html_report_embeds_each_figure_byte_for_byte(tmp_path: Path,
                                                      figures: tuple[Path, Path]) -> None:
    out = write_html(tmp_path / "report.html", "t", report_sections(figures))
    images = [attrs for tag, attrs in parse(out).tags if tag == "img"]
    assert len(images) == 2
    for attrs, figure in zip(images, figures, strict=True):
        src = attrs["src"] or ""
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1]) == figure.read_bytes()
        assert (attrs.get("alt") or "").strip(), "every figure has alt text"
    assert images[0]["alt"] == "Report latency: ECDF and histogram"


def test_html_report_escapes_hostile_text(tmp_path: Path, figures: tuple[Path, Path]) -> None:
    out = write_html(tmp_path / "report.html", HOSTILE, report_sections(figures))
    raw = out.read_text(encoding="utf-8")
    assert "<script" not in raw
    assert "<img src=http" not in raw
    doc = parse(out)
    text = "".join(doc.text)
    assert HOSTILE in text, "hostile text is shown literally"
    assert all(tag != "script" for tag, _ in doc.tags)
    assert sum(1 for tag, _ in doc.tags if tag == "img") == 2


def test_html_report_is_accessible(tmp_path: Path, figures: tuple[Path, Path]) -> None:
    out = write_html(tmp_path / "report.html", "Dispenser evaluation", report_sections(figures))
    tags = parse(out).tags
    names = [tag for tag, _ in tags]
    assert names.count("h1") == 1
    assert names.count("h2") == 1 + 3   # contents + one per section
    html_attrs = next(attrs for tag, attrs in tags if tag == "html")
    assert html_attrs.get("lang") == "en"
    assert any(tag == "meta" and attrs.get("name") == "viewport" for tag, attrs in tags)
    assert "caption" in names
    headers = [attrs for tag, attrs in tags if tag == "th"]
    assert {a.get("scope") for a in headers} == {"col", "row"}


def test_html_report_of_no_sections_is_valid(tmp_path: Path) -> None:
    out = write_html(tmp_path / "r.html", "Nothing ran", [])
    doc = parse(out)
    assert "Nothing ran" in "".join(doc.text)


def test_html_report_is_deterministic(tmp_path: Path, figures: tuple[Path, Path]) -> None:
    a = write_html(tmp_path / "a.html", "t", report_sections(figures)).read_bytes()
    b = write_html(tmp_path / "b.html", "t", report_sections(figures)).read_bytes()
    assert a == b


def test_missing_figure_is_an_evaluation_error(tmp_path: Path) -> None:
    section = Section("Latency", images=(tmp_path / "nope.png",))
    with pytest.raises(EvaluationError, match=r"cannot embed the figure .*nope\.png"):
        write_html(tmp_path / "report.html", "t", [section])
    assert not (tmp_path / "report.html").exists()


def test_unwritable_report_is_an_evaluation_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(EvaluationError, match=r"cannot write the report"):
        write_html(blocker / "report.html", "t", [])
    with pytest.raises(EvaluationError, match=r"cannot write the report"):
        write_markdown(blocker / "report.md", "t", [])


def test_markdown_report_links_figures_relative_to_it(tmp_path: Path,
                                                     figures: tuple[Path, Path]) -> None:
    latency, rates = figures
    local = tmp_path / "out"
    local.mkdir()
    copies = [local / latency.name, local / "plots" / rates.name]
    copies[1].parent.mkdir()
    for source, copy in zip(figures, copies, strict=True):
        copy.write_bytes(source.read_bytes())
    out = write_markdown(local / "report.md", "Dispenser evaluation",
                         report_sections((copies[0], copies[1])))
    text = out.read_text(encoding="utf-8")
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert links == ["latency_report_latency_s.png", "plots/rates.png"]
    assert all((local / link).exists() for link in links)


def test_markdown_report_has_the_same_content(tmp_path: Path,
                                              figures: tuple[Path, Path]) -> None:
    text = write_markdown(tmp_path / "report.md", "Dispenser evaluation",
                          report_sections(figures)).read_text(encoding="utf-8")
    assert text.startswith("# Dispenser evaluation\n")
    assert "## Summary" in text and "## Latency" in text
    assert "| metric | mean | ci95 |" in text
    assert "| doses\\_taken | 3.92 | \\[3.90, 3.94\\] |" in text
    assert "**Per-user metrics**" in text
    assert "1,000 users over 30 days." in text


def test_markdown_report_escapes_hostile_text(tmp_path: Path,
                                              figures: tuple[Path, Path]) -> None:
    text = write_markdown(tmp_path / "report.md", HOSTILE,
                          report_sections(figures)).read_text(encoding="utf-8")
    # rendered as a CommonMark viewer does (raw HTML allowed): no tag, the text as written
    from markdown_it import MarkdownIt

    rendered = MarkdownIt("commonmark").enable("table").render(text)
    collector = _Collector()
    collector.feed(rendered)
    collector.close()
    assert "script" not in {tag for tag, _ in collector.tags}
    # the figures' own images only (the hostile one's src is no image)
    assert not [a for tag, a in collector.tags if tag == "img" and "evil" in str(a.get("src"))]
    assert HOSTILE in "".join(collector.text)
    table_lines = [line for line in text.splitlines() if line.startswith("| ")]
    # a "|" inside a cell is escaped, so every row keeps three cells
    assert all(len(re.split(r"(?<!\\)\|", line)) == 5 for line in table_lines)


def test_markdown_writes_plain_text_as_it_reads(tmp_path: Path) -> None:
    """"<" and "&" that start no markup are written as they are (they were "&lt;" and
    "&amp;" in report.md: right once rendered, odd to read raw); one that would start a tag
    or an entity is backslashed, which shows it as written."""
    from markdown_it import MarkdownIt

    plain = "Wilson score interval (U < 2); Korn & Graubard (1998); a -> b"
    markup = "<b>bold</b> &amp; &#38;"
    text = write_markdown(tmp_path / "report.md", "t", [
        Section("Methods", paragraphs=(plain, markup))]).read_text(encoding="utf-8")
    assert plain in text.splitlines()
    assert "&lt;" not in text and "&amp;" not in text.replace(r"\&amp;", "")
    collector = _Collector()
    collector.feed(MarkdownIt("commonmark").render(text))
    collector.close()
    assert "b" not in {tag for tag, _ in collector.tags}
    assert [plain, markup] == [t for t in collector.text if t.strip()][2:]
