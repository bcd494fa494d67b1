"""What the report's tables say an interval is, where a reader could take one for another:
the per-user mean's t interval beside the estimate's; a paired difference of durations
without an interval; an error rate of an activity the user model cannot do wrongly.

Each test reads the report as a user does (report.md, the HTML's visible text), on the run
an audit of the report used: the dispenser, 20 users x 2 days, compared with itself."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation import report as report_module
from opspec.evaluation.store import ResultStore
from opspec.usermodels.loader import load_user_model

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
POPULATION = ROOT / "specs" / "medication_dispenser.population.toml"


def _evaluate(out: Path, *more: str) -> Path:
    assert main(["evaluate", str(SPEC), "--users", "20", "--days", "2", "--workers", "1",
                 "--out", str(out), "--quiet", *more]) == 0
    return out


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _evaluate(tmp_path_factory.mktemp("labels") / "run", "--compare", str(SPEC))


def _markdown(run: Path) -> str:
    """report.md as read: markdown's escapes taken off."""
    return (run / "report.md").read_text(encoding="utf-8").replace("\\", "")


def _visible(run: Path) -> str:
    """report.html's visible text, tags removed, entities read."""
    import html

    page = re.sub(r'src="data:[^"]+"', "", (run / "report.html").read_text(encoding="utf-8"))
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", page)))


def _section(md: str, title: str) -> str:
    """The first section whose heading holds ``title``, up to the next heading."""
    found = re.search(rf"^## [^\n]*{re.escape(title)}[^\n]*\n(.*?)(?=^## )", md,
                      re.DOTALL | re.MULTILINE)
    assert found, f"no section {title!r}"
    return found.group(1)


def _rows(section: str, header_start: str) -> tuple[list[str], dict[str, list[str]]]:
    """The header and the rows (by first cell) of the table whose header starts so."""
    lines = [line for line in section.splitlines() if line.startswith("|")]
    start = next(i for i, line in enumerate(lines) if line.startswith(header_start))
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines[start:]]
    table = [cells[0]]
    for row in cells[2:]:
        if row and row[0] in {"metric", "activity"}:     # the next table
            break
        table.append(row)
    return table[0], {row[0]: row for row in table[1:]}


# ------------------------------------------------------------------ 1: two intervals

def test_the_per_user_interval_is_labelled_as_the_mean_of_users_values(run: Path) -> None:
    """taken_rate had [97.66 %, 100.00 %] under Estimates and [100.00 %, 100.00 %] under How
    users differ, both headed '95 % CI': the second is the t interval of the mean of the
    users' own rates, a different quantity by a different method, and says so."""
    md = _markdown(run)
    estimates = _section(md, "(first): Estimates")
    spread = _section(md, "(first): How users differ")
    head, est = _rows(estimates, "| metric | kind |")
    assert est["taken_rate"][head.index("95 % CI")] == "[97.66 %, 100.00 %]"
    head, own = _rows(spread, "| metric | users | mean")
    assert "95 % CI" not in head, "the per-user interval is headed as the estimate's"
    column = head.index("95 % CI of that mean (t)")
    assert head[2] == "mean of users' values"
    # marked: 20 users all alike (tests/evaluation/test_no_spread_shown.py)
    assert own["taken_rate (per user)"][column] == "[100.00 %, 100.00 %] †"
    # what it is, in one sentence, and why the two differ
    assert ("'95 % CI of that mean (t)' is a confidence interval of the mean of the users' "
            "own values, every user counting once, by Student's t over those values; it is "
            "not the interval under Estimates") in spread
    assert ("Every user had the same taken_rate and the same missed_rate, so the t interval "
            "of their mean has no width: that is no bound on the rate, whose interval is the "
            "one under Estimates.") in spread
    text = _visible(run)
    assert "95 % CI of that mean (t)" in text and "no bound on the rate" in text


def test_users_who_differ_get_no_sentence_on_a_zero_width_interval(tmp_path: Path) -> None:
    """The sentence on a t interval without width names only metrics whose users all had
    the same value: with a design that misses doses (one alarm less) B's users differ."""
    two = tmp_path / "two_alarms.xpdl"
    text = SPEC.read_text(encoding="utf-8")
    old = "<Expression>alarms &lt; 3</Expression>"
    assert text.count(old) == 1
    two.write_text(text.replace(old, "<Expression>alarms &lt; 2</Expression>"),
                   encoding="utf-8")
    out = _evaluate(tmp_path / "run", "--compare", str(two))
    md = _markdown(out)
    spread = _section(md, "two_alarms.xpdl: How users differ")
    head, own = _rows(spread, "| metric | users | mean")
    column = head.index("95 % CI of that mean (t)")
    low, high = own["taken_rate (per user)"][column].strip("[]").split(", ")
    assert low != high
    assert "is a confidence interval of the mean of the users' own values" in spread
    assert "no width" not in spread
    # ... and with them, the difference of durations has its paired interval
    compared = _section(md, "compared with medication_dispenser.xpdl")
    head, rows = _rows(compared, "| metric |")
    latency = rows["report_latency_s"]
    # (a difference, signed: [-38.55 s, +1.973 s])
    assert re.fullmatch(r"\[[-+]?[\d.]+ s, [-+]?[\d.]+ s\]", latency[head.index("95 % CI")])
    assert latency[head.index("CI method")] in {"paired t", "paired t, few"}
    assert "has no interval" not in compared


# ------------------------------------------------------------------ 2: a difference without CI

def test_a_duration_difference_without_interval_says_why(run: Path) -> None:
    """The spec compared with itself: every user's latencies are the same in both designs,
    and a paired interval of durations needs 2 users who differ (docs/evaluation.md); the
    table says so instead of a bare '–' beside counts that have intervals."""
    md = _markdown(run)
    compared = _section(md, "(second) compared with ")
    head, rows = _rows(compared, "| metric |")
    latency = rows["report_latency_s"]
    assert latency[head.index("difference")] == "0 s"
    assert latency[head.index("95 % CI")] == "–"
    assert latency[head.index("CI method")] == "none: fewer than 2 users differ"
    assert rows["alarms"][head.index("95 % CI")] == "[-0.1844, +0.1844]"
    assert ("report_latency_s has no interval ('–'): fewer than 2 users' durations differ "
            "between the designs") in compared
    assert "none: fewer than 2 users differ" in _visible(run)


def test_the_terminal_table_says_why_too(capsys: pytest.CaptureFixture[str],
                                         tmp_path: Path) -> None:
    assert main(["evaluate", str(SPEC), "--users", "4", "--days", "1", "--workers", "1",
                 "--out", str(tmp_path / "run"), "--compare", str(SPEC)]) == 0
    cells = next(re.split(r"\s{2,}", line.strip()) for line in capsys.readouterr().out
                 .splitlines() if line.startswith("report_latency_s") and "–" in line)
    assert cells[-2:] == ["–", "none: fewer than 2 users differ"]


# ------------------------------------------------------------------ 3: wrong per offer

def test_an_activity_the_model_cannot_do_wrongly_has_no_error_rate(run: Path) -> None:
    """hear_alarm, walk_to_dispenser and take_pill have no wrong action in the user model:
    their '0.00 % [0.00 %, 2.01 %]' read as a measured error rate; choose_button's rate is
    per offer (re-offers after a wrong press included), and the report says so."""
    md = _markdown(run)
    actions = _section(md, "(first): The user's actions")
    head, rows = _rows(actions, "| activity |")
    wrong = head.index("wrong per offer [95 % CI]")
    for activity in ("hear_alarm", "walk_to_dispenser", "take_pill"):
        assert rows[activity][wrong] == "–", activity
    assert rows["hear_alarm"][head.index("omitted per offer [95 % CI]")].startswith("14.44 %")
    assert rows["choose_button"][head.index("offered")] == "164"
    assert rows["choose_button"][wrong] == "2.44 % [0.95 %, 6.10 %]"
    assert ("Both are per offer, re-offers included: a choice offered again after a wrong "
            "button counts each time") in actions
    assert ("'–': the user model has no wrong action (a wrong choice or a slip) for the "
            "activity, so it cannot be done wrongly") in actions
    assert "'–' where the user model has no wrong action, as in the table" in actions


def test_a_model_file_changed_since_the_run_leaves_the_rates_shown(tmp_path: Path) -> None:
    """What the report says of the model rests on the file the run used: changed since, it
    is not known which activities could go wrong, and every counted rate is shown."""
    model = tmp_path / "user.toml"
    shutil.copy(USERS, model)
    out = _evaluate(tmp_path / "run", "--user-model", str(model))
    head, rows = _rows(_section(_markdown(out), "The user's actions"), "| activity |")
    assert rows["hear_alarm"][head.index("wrong per offer [95 % CI]")] == "–"
    model.write_text(model.read_text(encoding="utf-8") + "\n# edited after the run\n",
                     encoding="utf-8")
    with ResultStore(out, create=False) as store:
        report_module.write_report(store)
    actions = _section(_markdown(out), "The user's actions")
    head, rows = _rows(actions, "| activity |")
    assert rows["hear_alarm"][head.index("wrong per offer [95 % CI]")].startswith("0.00 % [")
    assert "'–': the user model has no wrong action" not in actions


def test_which_activities_a_model_can_do_wrongly() -> None:
    from opspec.evaluation.describe import can_do_wrongly

    plain = load_user_model(str(USERS))
    assert can_do_wrongly(plain, "choose_button") is True
    assert can_do_wrongly(plain, "hear_alarm") is False
    assert can_do_wrongly(plain, "not_in_the_model") is None
    people = load_user_model(str(POPULATION))
    assert can_do_wrongly(people, "choose_button") is True
    assert can_do_wrongly(people, "walk_to_dispenser") is False
