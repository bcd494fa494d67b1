"""Every number a figure of the report prints is the number its table prints.

A reader of a paper compares a figure's labels with the table next to it; a figure that says
99.6 % where the table says 99.61 %, or that was drawn from another computation, is an error
a reviewer finds. The report is read as a reader gets it (report.html, figures inline as
SVG): the tables' cells and each figure's texts (``<text>`` elements; glyph outlines, each
preceded by a comment holding the text, are read as well), and each number a figure states
as a value — not an axis tick — is looked up in the table it belongs to:

- the outcome rates: each panel's "estimate [low, high]" is the estimates table's estimate
  and 95 % CI of the metric the panel is labelled with;
- each user's own value: "mean over users X" is the per-user table's mean of that metric;
- the distribution of a duration: "mean = X", "median = X", "p95 = X" are the estimates
  table's estimate, median and p95;
- the user's actions: each activity's omission and error bar labels are the per-activity
  table's rates, in the table's order.
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import pytest
from lxml import html as lxml_html

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> lxml_html.HtmlElement:
    out = tmp_path_factory.mktemp("numbers") / "run"
    assert main(["evaluate", str(SPEC), "--users", "16", "--days", "3", "--seed", "2",
                 "--workers", "1", "--out", str(out), "--quiet", "--json"]) == 0
    return lxml_html.fromstring((out / "report.html").read_bytes())


def cell(node: lxml_html.HtmlElement) -> str:
    return " ".join(node.text_content().split())


def table(page: lxml_html.HtmlElement, caption: str) -> dict[str, dict[str, str]]:
    """The table whose caption starts with ``caption``: first cell → {header: cell}."""
    for found in page.iter("table"):
        title = found.find("caption")
        if title is not None and cell(title).startswith(caption):
            headers = [cell(th) for th in found.find("thead").iter("th")]
            rows = {}
            for tr in found.find("tbody").iter("tr"):
                cells = [cell(c) for c in tr if c.tag in ("th", "td")]
                rows[cells[0]] = dict(zip(headers, cells, strict=True))
            return rows
    raise AssertionError(f"no table captioned {caption!r}")


def figure_texts(page: lxml_html.HtmlElement, caption: str) -> list[str]:
    """The texts of the figure whose caption starts with ``caption``, in drawing order."""
    for figure in page.iter("figure"):
        title = figure.find("figcaption")
        if title is not None and cell(title).startswith(caption):
            svg = figure.find(".//svg")
            assert svg is not None, f"figure {caption!r} is not inline SVG"
            texts = []
            for node in svg.iter():
                if node.tag is lxml_html.HtmlComment or callable(node.tag):
                    texts.append(" ".join(str(node.text or "").split()))
                elif node.tag == "text":
                    texts.append(cell(node))
            return [t for t in texts if t]
    raise AssertionError(f"no figure captioned {caption!r}")


def words(metric: str) -> str:
    return metric.replace("_", " ")


def test_outcome_rates_are_the_estimates_tables(report: lxml_html.HtmlElement) -> None:
    estimates = table(report, "Declared metrics of")
    texts = figure_texts(report, "Outcome rates with 95 % confidence intervals")
    shown = {}
    for before, text in itertools.pairwise(texts):
        match = re.fullmatch(r"(.+?) \[(.+?), (.+?)\]", text)
        if match:
            shown[before] = match.groups()         # the panel's label comes just before
    rates = {words(m): row for m, row in estimates.items() if row["estimate"].endswith("%")}
    assert rates and set(shown) == set(rates), (shown, rates)
    for label, (value, low, high) in shown.items():
        assert value == rates[label]["estimate"]
        assert f"[{low}, {high}]" == rates[label]["95 % CI"]


def test_each_users_own_values_are_the_per_user_tables(report: lxml_html.HtmlElement) -> None:
    per_user = table(report, "Each user's own mean duration or ratio")
    texts = figure_texts(report, "Distribution over users of each user's own value")
    means = {}
    for text in texts:
        match = re.fullmatch(r"(.+?)(, mean per user)?: mean over users (.+?) \(dashed line\)",
                             text)
        if match:
            means[match.group(1)] = match.group(3)
    rows = {words(m.split(" (")[0]).removesuffix(" s"): row for m, row in per_user.items()}
    assert means and set(means) == set(rows), (means, rows)
    for label, mean in means.items():
        assert mean == rows[label]["mean of users' values"], label
    # a panel of discrete values labels each bar with its number of users (drawn after the
    # axis' "users" label, before the panel's title): together, every user of the table
    counted: dict[str, int] = {}
    bars: list[int] = []
    for text in texts:
        if text == "users":
            bars = []
        elif re.fullmatch(r"\d+", text):
            bars.append(int(text))
        elif (match := re.fullmatch(r"(.+?)(, mean per user)?: mean over users .*", text)):
            if bars:
                counted[match.group(1)] = sum(bars)
            bars = []
    assert counted, "no panel of discrete values labels its bars"
    for label, users in counted.items():
        assert users == int(rows[label]["users"]), label


def test_a_durations_marks_are_the_estimates_tables(report: lxml_html.HtmlElement) -> None:
    estimates = table(report, "Declared metrics of")
    durations = [m for m, row in estimates.items() if row["kind"] == "duration"]
    assert durations
    for metric in durations:
        # the caption names the metric as its axis does (report_latency_s: "report latency")
        texts = figure_texts(report, f"Distribution of {words(metric).removesuffix(' s')}")
        marks = dict(re.fullmatch(r"(mean|median|p95) = (.+)", t).groups()  # type: ignore[union-attr]
                     for t in texts if re.fullmatch(r"(mean|median|p95) = .+", t))
        row = estimates[metric]
        assert marks == {"mean": row["estimate"], "median": row["median"], "p95": row["p95"]}


def test_the_users_actions_are_the_per_activity_tables(report: lxml_html.HtmlElement) -> None:
    activities = table(report, "Per-activity rates of the user's lane")
    texts = figure_texts(report, "The user's activities: omission and error rates")
    # the bar labels are drawn after the axes (their ticks, then the activities' names)
    last_name = max(i for i, t in enumerate(texts) if t in activities)
    labels = [t for t in texts[last_name + 1:] if re.fullmatch(r"\d+\.\d+ %|–", t)]
    expected = [row[column].split(" [")[0] for row in activities.values()
                for column in ("omitted per offer [95 % CI]", "wrong per offer [95 % CI]")]
    # an activity the user model cannot do wrongly has no error rate in the table ('–'), and
    # none in the figure either: '–' where its bar would be, as its caption says
    assert "–" in expected
    assert sorted(labels) == sorted(expected)
    assert any("'–' where the user model has no wrong action, as in the table"
               in cell(title) for title in report.iter("figcaption"))
    # the bars are labelled with the table's activities, in its order
    assert [t for t in texts if t in activities] == list(activities)
