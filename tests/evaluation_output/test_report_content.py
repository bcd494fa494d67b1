"""What the evaluation report says: findings in words, definitions, the user model, per-user
distributions, hazards, no internal labels, the same numbers in figures and tables, and a
Jinja2 template a researcher can replace."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import EvaluationError
from opspec.evaluation import report as report_module
from opspec.evaluation import report_design
from opspec.evaluation.describe import describe_metric, describe_selector
from opspec.evaluation.store import ResultStore

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("content") / "run"
    assert main(["evaluate", str(SPEC), "--users", "30", "--days", "2", "--workers", "1",
                 "--out", str(out), "--quiet", "--json"]) == 0
    return out


def _text(path: Path) -> str:
    """The report's visible text, tags removed and entities left as they are."""
    html = path.read_text(encoding="utf-8")
    html = re.sub(r'src="data:[^"]+"', "", html)
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", html))


def test_key_findings_state_estimates_with_intervals_in_words(run: Path) -> None:
    text = _text(run / "report.html")
    assert "Key findings" in text
    assert "30 simulated users of medication_dispenser.xpdl, each followed for 2 days." in text
    assert re.search(r"Share of the doses due that were taken: [\d.]+ % "
                     r"\(95 % confidence interval [\d.]+ % to [\d.]+ %\)", text)
    assert re.search(r"Report latency: [\d.]+ s on average \(95 % confidence "
                     r"interval", text)
    assert re.search(r"Doses missed: [\d.]+ per user over the run", text)
    assert "the spec declares no safety monitors" in text


def test_findings_name_metrics_in_the_words_of_their_figures(run: Path) -> None:
    """A finding names a metric as its figure's axis does ("report latency", the unit said
    with the value), never by its identifier (report_latency_s): the reader of a paper has
    not read the spec."""
    for name in ("report.html", "report.md"):
        text = _text(run / name)
        findings = (text.split("Key findings")[-1].split("What was run")[0]
                    .replace("medication_dispenser.xpdl", "the spec"))
        assert "Report latency:" in findings and "Missed rate per user:" in findings
        identifiers = re.findall(r"\b[a-z]+(?:_[a-z0-9]+)+\b", findings)
        assert not identifiers, f"{name}: findings name metrics by id: {identifiers}"


def test_every_metric_is_defined_in_words(run: Path) -> None:
    text = _text(run / "report.html")
    assert ("time (s) from the first start of activity sound_alarm (workflow notify_workflow) "
            "to the completion of activity wait_report (workflow notify_workflow)") in text
    assert ("Counted in the trace: every completion of activity record_missed (workflow "
            "notify_workflow), per simulated user") in text
    # the spec's own words come first
    assert "A dose counts as missed when the user has not reported within 300 s" in text
    assert "doses_missed divided by doses_due, both summed over all users" in text


def test_user_model_parameters_and_assumptions_are_listed(run: Path) -> None:
    text = _text(run / "report.html")
    assert "Who the simulated users are" in text
    assert "lognormal (median 60 s, sigma 0.6), mean 71.8 s" in text
    assert "omitted with probability 15 % (not heard)" in text
    assert "wrong choice (press_wrong_button) with probability 5 %" in text
    assert "differs from the others only by chance" in text


def test_no_internal_labels(run: Path) -> None:
    for name in ("report.html", "report.md"):
        text = _text(run / name)
        assert "spec (A)" not in text and "(A)" not in text
        assert not re.search(r"\bA: \d", text), f"{name} shows an internal design label"


def test_two_designs_are_named_by_their_files(tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    assert main(["evaluate", str(SPEC), "--compare", str(SPEC), "--users", "8", "--days", "1",
                 "--workers", "1", "--out", str(out), "--quiet", "--json"]) == 0
    text = _text(out / "report.html")
    assert "Evaluation of medication_dispenser.xpdl" in text
    assert "(second) compared with" in text and "no metric differs" in text
    assert "(A)" not in text and not re.search(r"\bA: \d", text)
    assert not re.search(r"\b[AB] − [AB]\b", text)
    # the comparison figure names each metric as the other figures do, not by its id
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "taken rate (pp)" in html and "taken_rate (pp)" not in html


def test_per_user_distributions_and_own_scales_are_shown(run: Path) -> None:
    html = (run / "report.html").read_text(encoding="utf-8")
    assert "How users differ" in html
    assert "Distribution over users of each user&#39;s own value" in html
    assert (run / "figures" / "A-per-user.svg").is_file()
    assert "each metric on its own scale, so rare outcomes are visible" in html


def test_markdown_says_the_same(run: Path) -> None:
    md = (run / "report.md").read_text(encoding="utf-8")
    assert "## Key findings" in md and "## Who the simulated users are" in md
    assert "figures/A-per-user.svg" in md


def test_figures_draw_the_tables_numbers_and_say_when_they_sample(
        run: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from opspec.evaluation import plots

    seen: dict[str, object] = {}
    original = plots.latency_figure

    def spy(metric, values, path, *, marks=None, total=None, **words):  # type: ignore[no-untyped-def]
        seen.update(metric=metric, n=len(values), marks=marks, total=total)
        return original(metric, values, path, marks=marks, total=total, **words)

    monkeypatch.setattr(plots, "latency_figure", spy)
    monkeypatch.setattr(report_design, "PLOT_SAMPLE", 50)
    with ResultStore(run, create=False) as store:
        from opspec.evaluation.summary import summarise_design

        summary = summarise_design(store, "A", 2.0)["report_latency_s"]
        path = report_module.write_report(store)
    latency = summary["n"]
    assert latency > 100
    assert seen["total"] == latency and int(seen["n"]) <= 50 + 1  # type: ignore[call-overload]
    assert seen["marks"] == {"mean": summary["mean"], "median": summary["median"],
                             "p95": summary["p95"]}
    text = _text(path)
    assert f"of the {latency:,} observations; mean, median and p95 are of all" in text


def test_summaries_passed_in_are_not_computed_again(run: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    from opspec.evaluation.summary import summarise_design, summarise_monitors

    with ResultStore(run, create=False) as store:
        given = {"A": {"metrics": summarise_design(store, "A", 2.0),
                       "monitors": summarise_monitors(store, "A", 2.0)}}

        def fail(*_: object, **__: object) -> None:
            raise AssertionError("computed again")

        monkeypatch.setattr(report_module, "summarise_design", fail)
        monkeypatch.setattr(report_module, "summarise_monitors", fail)
        assert report_module.write_report(store, given).is_file()


def test_a_researchers_template_restyles_the_report(run: Path, tmp_path: Path) -> None:
    template = tmp_path / "mine.html.j2"
    template.write_text("<html><body class=mine><h1>{{ title }}</h1>{% for s in sections %}"
                        "<h2>{{ s.title }}</h2>{% for f in s.figures %}<img src=\"{{ f.src }}\">"
                        "{% endfor %}{% endfor %}</body></html>", encoding="utf-8")
    status = main(["evaluate", "--resume", "--out", str(run), "--quiet", "--json",
                   "--report-template", str(template)])
    assert status == 0
    html = (run / "report.html").read_text(encoding="utf-8")
    assert html.startswith("<html><body class=mine><h1>Evaluation of medication_dispenser")
    assert "<h2>Key findings</h2>" in html and "data:image/svg+xml;base64," in html
    # back to the bundled template
    assert main(["evaluate", "--resume", "--out", str(run), "--quiet", "--json"]) == 0
    assert "<!DOCTYPE html>" in (run / "report.html").read_text(encoding="utf-8")


def test_a_broken_template_is_a_clear_error(run: Path, tmp_path: Path) -> None:
    template = tmp_path / "broken.html.j2"
    template.write_text("<h1>{{ title }</h1>\n{% for %}", encoding="utf-8")
    with ResultStore(run, create=False) as store, pytest.raises(
            EvaluationError, match=r"broken\.html\.j2:\d+: the report template fails"):
        report_module.write_report(store, template=template)
    with ResultStore(run, create=False) as store, pytest.raises(
            EvaluationError, match=r"cannot read the report template"):
        report_module.write_report(store, template=tmp_path / "missing.html.j2")


def test_the_template_ships_with_the_package() -> None:
    from opspec.evaluation.html import TEMPLATE

    assert TEMPLATE.is_file()
    pyproject = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert '"**/*.html.j2"' in pyproject and "jinja2>=3.1" in pyproject


def test_words_for_selectors_and_metrics_without_detail() -> None:
    assert describe_selector({"event": "process.started", "process": "p"}) == (
        "the start of workflow p")
    assert describe_selector({"event": "activity.omitted", "activity": "hear"}) == (
        "the omission of activity hear")
    assert describe_metric({"name": "x", "kind": "count", "description": "Pills taken"}
                           ).startswith("Pills taken. A count of trace events")
    assert describe_metric({"name": "x", "kind": "count", "select": {
        "event": "process.started", "process": "p"}}) == (
        "Counted in the trace: every start of workflow p, per simulated user over the whole "
        "run.")
    last = describe_metric({"name": "d", "kind": "duration", "unit": "s",
                            "start": {"event": "activity.started", "activity": "a",
                                      "which": "last"},
                            "end": {"event": "activity.completed", "activity": "b"}})
    assert last.startswith("Measured in the trace: time (s) from the last start of activity a to the completion of "
                           "activity b")


def test_a_count_of_events_of_any_other_kind_reads_whole() -> None:
    # the dispenser's device_faults counts device.fault events: its report said "every ult
    # event" when the article was cut by its length ("the " is four letters, "a " two)
    assert describe_metric({"name": "device_faults", "kind": "count", "select": {
        "event": "device.fault"}}) == (
        "Counted in the trace: every device.fault event, per simulated user over the whole "
        "run.")
    first = describe_metric({"name": "d", "kind": "duration", "unit": "s",
                             "start": {"event": "device.fault", "which": "first"},
                             "end": {"event": "activity.completed", "activity": "b"}})
    assert first.startswith("Measured in the trace: time (s) from the first device.fault "
                            "event to the completion of activity b")
