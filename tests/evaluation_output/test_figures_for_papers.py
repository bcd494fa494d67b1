"""Figures a journal accepts: vector (SVG inline in the HTML report, PDF on request), PNG at
200 dpi or more, no titles burnt in (the captions carry them), axes in words with units,
rates within [0, 100] %, each value users had as a bar of its own, intervals on the
day-by-day panels and on the per-activity rates; and the report's table says over how many
users and days."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
from PIL import Image

from opspec.cli import main
from opspec.evaluation import figure_files

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def _evaluate(out: Path, *extra: str) -> None:
    assert main(["evaluate", str(SPEC), "--users", "12", "--days", "3", "--workers", "1",
                 "--out", str(out), "--quiet", "--json", *extra]) == 0


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("paper") / "run"
    _evaluate(out)
    return out


def test_the_html_report_inlines_vector_figures(run: Path) -> None:
    html = (run / "report.html").read_text(encoding="utf-8")
    figures = sorted((run / "figures").iterdir())
    assert figures and all(f.suffix == ".svg" for f in figures)
    assert html.count("<svg") == len(figures)
    assert "data:image/png" not in html
    # self-contained: nothing points the reader to files they do not have
    assert "docs/" not in re.sub(r"<svg.*?</svg>", "", html, flags=re.DOTALL)


def test_figure_texts_are_text_a_reader_can_search_and_copy(run: Path) -> None:
    """A figure's words and numbers are SVG ``<text>`` (found by the browser's search, copied
    into a paper, corrected by a journal's editor), in the font the layout was measured with
    and a sans-serif where that font is missing; not glyph outlines."""
    from lxml import etree

    svg = etree.parse(str(run / "figures" / "A-report_latency_s.svg"))
    texts = svg.getroot().findall(".//{http://www.w3.org/2000/svg}text")
    words = " ".join("".join(t.itertext()) for t in texts)
    assert "report latency (s)" in words and "Histogram" in words
    assert all("'DejaVu Sans'" in t.get("style", "") and "sans-serif" in t.get("style", "")
               for t in texts)


def test_figures_carry_no_titles_and_label_axes_in_words(
        run: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Capture every figure the report draws and read its texts."""
    from opspec.evaluation import report
    from opspec.evaluation.store import ResultStore

    drawn: dict[str, Any] = {}
    original = figure_files.save

    def keep(fig: Any, path: Path) -> Path:
        drawn[Path(path).stem] = fig
        return original(fig, path)

    monkeypatch.setattr(figure_files, "save", keep)
    with ResultStore(run, create=False) as store:
        report.write_report(store)
    for name, fig in drawn.items():
        assert not (fig._suptitle and fig._suptitle.get_text()), name
    latency = drawn["A-report_latency_s"]
    labels = {ax.get_xlabel() for ax in latency.axes}
    assert labels == {"report latency (s)"}
    # a rate's per-user axis stays within [0, 100] %, and each value is a bar of its own
    per_user = drawn["A-per-user"]
    rate_axes = [ax for ax in per_user.axes if "(%)" in ax.get_xlabel()]
    assert rate_axes
    for ax in rate_axes:
        low, high = ax.get_xlim()
        assert 0.0 <= low and high <= 100.0
    # ... and a bar at 0 % (most users never miss a dose) is not drawn under the y axis' line
    renderer = per_user.canvas.get_renderer()
    at_zero = [ax for ax in rate_axes
               if any(s[0][0] == 0.0 for s in ax.collections[0].get_segments())]
    assert at_zero, "no per-user rate panel has a bar at 0 %"
    for ax in at_zero:
        bar = ax.collections[0]
        half = bar.get_linewidth()[0] * per_user.dpi / 72.0 / 2.0
        axis_line = ax.spines["left"].get_window_extent(renderer).x1
        assert axis_line < ax.transData.transform((0.0, 0.0))[0] - half
    # the rates' panels never leave [0, 100] % either (a 99.6 % taken rate included)
    for ax in drawn["A-rates"].axes:
        low, high = ax.get_xlim()
        assert 0.0 <= low and high <= 1.0
    # day-by-day panels: a band (the day's interval) behind each line that is drawn
    days = drawn["A-days"]
    assert all(ax.collections for ax in days.axes)
    assert all("per user" in ax.get_ylabel() for ax in days.axes)
    # the per-activity rates have error bars
    activities = drawn["A-activities"]
    assert any(c.__class__.__name__ == "LineCollection" for c in activities.axes[0].collections)


def test_the_table_says_how_many_users_and_days(run: Path) -> None:
    html = (run / "report.html").read_text(encoding="utf-8")
    assert "Declared metrics of medication_dispenser.xpdl: 12 simulated users × 3 days each" \
        in html
    assert re.search(r'<th scope="col"[^>]*>users</th>', html) and "CI method" in html


@pytest.mark.parametrize("fmt", ["pdf", "png"])
def test_figures_in_pdf_or_png_at_200_dpi(tmp_path: Path, fmt: str) -> None:
    out = tmp_path / "run"
    _evaluate(out, "--figures", fmt)
    written = sorted((out / "figures").glob(f"*.{fmt}"))
    assert len(written) >= 5
    html = (out / "report.html").read_text(encoding="utf-8")
    if fmt == "pdf":
        assert all(f.read_bytes().startswith(b"%PDF") for f in written)
        assert all(f.with_suffix(".svg").is_file() for f in written)   # what the HTML shows
        assert html.count("<svg") == len(written)
    else:
        for f in written:
            with Image.open(f) as image:
                assert image.format == "PNG"
                assert min(image.info["dpi"]) >= 200 - 0.5
        assert html.count("data:image/png;base64,") == len(written)


def test_an_unknown_figure_format_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["evaluate", str(SPEC), "--figures", "gif"])
    assert exit_.value.code == 2
    # one line naming the option, the value and what it takes (no usage block before it)
    assert capsys.readouterr().err == ("opspec evaluate: --figures takes one of svg, pdf, png, "
                                       "not 'gif'\n")


def test_routine_windows_read_as_clock_times(tmp_path: Path) -> None:
    """The report's user-model notes give a routine window as the times of day the model
    file wrote (23:00–07:00), not as seconds after midnight (82800.0–25200.0)."""
    from opspec.evaluation.describe import user_model_notes
    from opspec.usermodels.loader import load_user_model

    path = tmp_path / "routine.users.toml"
    path.write_text('format = "opspec-user-model"\nversion = 1\nname = "routine"\n'
                    '[[routine.windows]]\nname = "asleep"\nstart = "23:00"\nend = "07:00"\n'
                    'notice_factor = 0.25\n[[routine.windows]]\nname = "lunch"\n'
                    'start = "12:30"\nend = "13:15:30"\nnotice_factor = 0.5\n'
                    '[activities.hear]\nduration = 1\n', encoding="utf-8")
    notes = " ".join(user_model_notes(load_user_model(path)))
    assert "Routine window asleep (23:00–07:00)" in notes
    assert "Routine window lunch (12:30–13:15:30)" in notes
    assert "82800" not in notes and "45000" not in notes
