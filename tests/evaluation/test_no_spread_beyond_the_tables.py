"""An interval of no width because the few users were all alike is marked (†) with the same
note beyond the summary tables too: in the report's figures (the bands of the counts day by
day, a sweep's bands, the comparison's differences) and their captions, in the input-
uncertainty table, and beside a sweep's unpaired (Welch) interval; ``--json`` carries each
as ``…_no_spread``. The old figures drew such a band as a line with no word, and the old
tables printed [4, 4] bare. The runs are tiny: 3 users of the dispenser, whose doses fall
due on a fixed timer, so every user is due the same number each day."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation.input_uncertainty import _combine, print_input_uncertainty
from opspec.statistics.no_spread import no_spread

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
SMALL = ("--users", "3", "--seed", "1", "--workers", "1")
NOTE = "all 3 users gave the same value, so the interval has no width"


def test_the_days_bands_and_the_comparison_figure_are_marked_with_the_note(evaluate,
                                                                            tmp_path):
    # B's timer has a fifth dose a day: every user is due 4 doses more over 4 days
    five = tmp_path / "five.xpdl"
    five.write_text(SPEC.read_text(encoding="utf-8").replace(
        "timer:08:00,12:00,18:00,22:00", "timer:08:00,10:00,12:00,18:00,22:00"),
        encoding="utf-8")
    out = tmp_path / "c"
    status, doc, err = evaluate(str(SPEC), "--compare", str(five), *SMALL, "--days", "4",
                                "--user-model", str(USERS), "--out", str(out))
    assert status == 0, err
    # 4 doses due each day to each of the 3 users: each day's band is [4, 4]
    days = (out / "figures" / "A-days.svg").read_text(encoding="utf-8")
    assert ">doses due †<" in days
    assert f">† {NOTE}: it shows no spread between users, not<" in days
    report = (out / "report.md").read_text(encoding="utf-8")
    assert (f"so rare outcomes are visible. † {NOTE}: it shows no spread between users, not a "
            "value known exactly.") in report
    html = (out / "report.html").read_text(encoding="utf-8")
    assert f"so rare outcomes are visible. † {NOTE}" in html
    # the comparison's figure marks every difference its table marks, and says why once
    differences = doc["compare"]["difference"]
    assert differences["doses_due"]["ci95"] == [4.0, 4.0]
    shown = sum(1 for d in differences.values()
                if (d["ci95_no_spread"] or {}).get("too_few_users"))
    compared = (out / "figures" / "comparison.svg").read_text(encoding="utf-8")
    assert ">+4  [+4, +4] †<" in compared
    assert compared.count("] †<") == shown
    assert compared.count(">† all 3 users gave the same difference between the designs, so "
                          "the interval has no width") == 1


def test_a_sweep_marks_its_bands_and_its_unpaired_interval(evaluate, tmp_path):
    out = tmp_path / "s"
    status, doc, err = evaluate(str(SPEC), *SMALL, "--days", "1", "--user-model", str(USERS),
                                "--out", str(out), "--sweep",
                                "user.activities.hear_alarm.omission.probability=15%,0%")
    assert status == 0, err
    # both values' users all due 4 doses: Welch's interval of the difference is [0, 0]
    diff = doc["sweep"]["values"][1]["difference"]["doses_due"]
    assert diff["unpaired_ci95"] == [0.0, 0.0]
    assert diff["unpaired_ci95_no_spread"] == {
        "users": 3, "share_unlike_ci95_high": pytest.approx(0.7076, abs=1e-4),
        "too_few_users": True}
    # one whose users differ has none
    assert doc["sweep"]["values"][1]["difference"]["report_latency_s"][
        "unpaired_ci95_no_spread"] is None
    report = (out / "report.md").read_text(encoding="utf-8")
    # no width ratio when the unpaired interval has no width: the mark says why
    assert ("| 0 % | 4 | \\[4, 4\\] † | t | +0 | \\[-1.23, +1.23\\] | paired t ∪ Garwood "
            "| – † |") in report
    assert "judged by. † " + NOTE in report                  # the figure's caption
    sweep = (out / "figures" / "sweep.svg").read_text(encoding="utf-8")
    assert ">95 % interval †<" in sweep and f">† {NOTE}: it shows" in sweep


@pytest.fixture(scope="module")
def fitted(tmp_path_factory) -> Path:
    """A model fitted to 2 days of one person following the reference user, 2 redraws."""
    folder = tmp_path_factory.mktemp("fitted")
    trace, model = folder / "person.jsonl", folder / "person.users.toml"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(SPEC), "--user-model", "dispenser-reference", "--days", "2",
                     "--seed", "11", "--trace", str(trace), "--timeline", "none"]) in (0, 1)
        assert main(["fit", str(trace), "-o", str(model), "--draws", "2"]) == 0
    return model


def test_the_input_uncertainty_table_marks_each_interval_of_no_width(evaluate, fitted,
                                                                     tmp_path):
    out = tmp_path / "iu"
    status, doc, err = evaluate(str(SPEC), *SMALL, "--days", "1", "--user-model", str(fitted),
                                "--input-uncertainty", "2", "--users-per-draw", "2",
                                "--out", str(out))
    assert status == 0, err
    due = doc["input_uncertainty"]["metrics"]["doses_due"]
    assert due["ci95"] == due["ci95_with_parameters"] == due["direct_bootstrap_ci95"] == [4, 4]
    assert due["ci95_no_spread"] == doc["metrics"]["doses_due"]["ci95_no_spread"]
    assert due["ci95_with_parameters_no_spread"]["users"] == 3     # the ordinary users'
    assert due["direct_bootstrap_ci95_no_spread"]["users"] == 4    # the 2 draws' 2 users
    latency = doc["input_uncertainty"]["metrics"]["report_latency_s"]
    assert latency["ci95_with_parameters_no_spread"] is None
    assert latency["direct_bootstrap_ci95_no_spread"] is None
    note = ("† all the users of each marked interval (3 or 4) gave the same value, so the "
            "interval has no width")
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "| doses\\_due | 4 | \\[4, 4\\] † | \\[4, 4\\] † | \\[4, 4\\] † | 0 % |" in report
    assert report.count(note) == 1
    text = io.StringIO()
    print_input_uncertainty(text, doc["input_uncertainty"])
    row = next(line for line in text.getvalue().splitlines() if "doses_due" in line)
    assert row.count("[4, 4] †") == 3
    assert text.getvalue().count(note) == 1


def test_equal_draws_of_users_who_differ_are_not_no_spread():
    # two draws whose estimates are both 4 but whose users differ (variance 0.5 each): the
    # bootstrap interval [4, 4] is no spread among alike users; the widened interval is, as
    # the 3 ordinary users were all alike and the parameters add nothing
    out = _combine(4.0, [4.0, 4.0], 0.0, 3, [(4.0, 0.5), (4.0, 0.5)], 0.95,
                   ordinary_no_spread=no_spread([4.0, 4.0], 3), draw_users=4)
    assert out["direct_bootstrap_ci95"] == [4.0, 4.0]
    assert out["direct_bootstrap_ci95_no_spread"] is None
    assert out["ci95_with_parameters"] == [4.0, 4.0]
    assert out["ci95_with_parameters_no_spread"]["users"] == 3


def test_a_figure_with_nothing_marked_is_asked_for_as_before():
    from opspec.evaluation.no_spread_notes import figure_marks

    assert figure_marks({"alarms": [{"ci95_no_spread": None}], "none": []}) == {}
    marks = figure_marks({"doses due": [None, {"ci95_no_spread": no_spread([4, 4], 3)}],
                          "alarms": [{"ci95_no_spread": None}]})
    assert marks["no_spread"] == ["doses due"]
    assert marks["no_spread_note"].startswith("† " + NOTE)
