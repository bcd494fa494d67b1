"""An interval of no width because the few users of a run all gave the same value is not
presented as certainty: the terminal's tables, the report, a comparison's and a sweep's tables
mark it (†) and say once, in plain words, what it means; ``--json`` carries it as
``ci95_no_spread``. Three users of one day of the dispenser (seed 1) all had 4 doses due, 4
taken and one alarm per dose: [4, 4] and [1, 1], which the old tables printed bare."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation import summary, tables
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.store import ResultStore

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
SMALL = ("--users", "3", "--days", "1", "--seed", "1", "--workers", "1",
         "--user-model", str(USERS))
NOTE = "all 3 users gave the same value, so the interval has no width"


def test_json_says_which_intervals_have_no_width_and_over_how_many_users(evaluate, tmp_path):
    status, doc, err = evaluate(str(SPEC), *SMALL, "--out", str(tmp_path / "o"), report=False)
    assert status == 0, err
    metrics = doc["metrics"]
    for name in ("doses_due", "alarms_per_dose"):
        assert metrics[name]["ci95"][0] == metrics[name]["ci95"][1]
        assert metrics[name]["ci95_no_spread"] == {
            "users": 3, "share_unlike_ci95_high": pytest.approx(0.7076, abs=1e-4),
            "too_few_users": True}
    # an interval with a width, and a proportion's (Wilson's never collapses), say nothing
    assert metrics["report_latency_s"]["ci95_no_spread"] is None
    assert metrics["taken_rate"]["ci95_no_spread"] is None
    # the mean of the users' own rates does collapse: every user took every dose
    assert metrics["taken_rate"]["per_user"]["ci95_no_spread"]["users"] == 3


def test_the_terminal_table_and_the_report_mark_it_and_say_once_why(capsys, tmp_path):
    out = tmp_path / "o"
    assert main(["evaluate", str(SPEC), *SMALL, "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    rows = {line.split()[0]: line for line in text.splitlines() if line[:1].isalpha()}
    assert "[4, 4] †" in rows["doses_due"] and "[1, 1] †" in rows["alarms_per_dose"]
    assert "†" not in rows["report_latency_s"] and "†" not in rows["taken_rate"]
    assert text.count(NOTE) == 1
    assert "more users are needed to estimate its interval" in text
    assert "up to 70.8 % of users could give another value" in text
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "| doses\\_due | count | 4 per user | \\[4, 4\\] † |" in report
    # under Estimates and How users differ, and in the caption of the counts day by day
    assert report.count(NOTE) == 3
    assert "Alarms per dose due: 1 (95 % confidence interval 1 to 1; all 3 users gave" in report
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "[4, 4] †" in html and NOTE in html


def _paired_store(folder: Path) -> ResultStore:
    store = ResultStore(folder, create=True)
    store.put("metrics", [{"name": "alarms", "kind": "count"}])
    store.add_many([ReplicationRecord(design, user, "done", metrics={
        "alarms": {"kind": "count", "total": total + (4 if design == "B" else 0)}})
        for design in ("A", "B") for user, total in enumerate([2, 3, 5])])
    return store


def test_a_difference_every_user_shares_is_marked_in_the_comparison(tmp_path):
    from opspec.evaluation.no_spread_notes import no_spread_note

    # every user 4 alarms more in B: 12 discordant events, paired t on differences all 4
    store = _paired_store(tmp_path / "c")
    diff = summary.compare_designs(store)["alarms"]
    store.close()
    # (4 give or take the last digit: the linearised differences are summed in floating point)
    assert diff["ci95"] == pytest.approx([4.0, 4.0], rel=1e-12)
    assert diff["ci95_no_spread"]["too_few_users"]
    (row,) = tables.comparison_rows({"alarms": diff})
    assert row[4] == "[+4, +4] †"
    note = no_spread_note([diff])
    assert note.startswith("† all 3 users gave the same difference between the designs")


def test_a_sweep_marks_it_says_so_once_and_decides_no_target_on_it(capsys, tmp_path):
    status = main(["evaluate", str(SPEC), *SMALL, "--out", str(tmp_path / "s"), "--quiet",
                   "--sweep", "user.activities.hear_alarm.omission.probability=15%,0%",
                   "--target", "alarms_per_dose < 1.5"])
    assert status == 0
    text = capsys.readouterr().out
    sweep = text[text.index("sweep of"):]
    assert "4         [4, 4] †" in sweep
    assert sweep.count(NOTE) == 1
    # one alarm per dose in every user's run at both values: no value is shown to meet the
    # target (the old answer: met with every value)
    target = sweep[sweep.index("target alarms_per_dose"):]
    assert "[1, 1] †  undecided" in target and "meets" not in target
    assert ("undecided at 15 %, 0 % (the 95 % interval contains the target, or has no width "
            "because the users were all alike: more users would tell)") in target


def test_many_users_all_alike_are_not_marked():
    from opspec.evaluation.no_spread_notes import no_spread_note

    # 1,000 users all due 120 doses (the README's run): the exact bound of the share of users
    # who could differ is 0.37 %, and the interval is shown as it was
    spread = {"users": 1000, "share_unlike_ci95_high": 0.00368, "too_few_users": False}
    s = {"kind": "count", "mean": 120.0, "ci95": [120.0, 120.0], "ci95_method": "t",
         "ci95_no_spread": spread, "sd": 0.0, "median": 120.0, "p95": 120.0, "users": 1000,
         "total": 120000}
    (row,) = tables.metric_rows({"doses_due": s})
    assert row[3] == "[120, 120]"
    assert no_spread_note([s]) is None


def test_one_note_for_intervals_over_different_numbers_of_users():
    from opspec.evaluation.no_spread_notes import no_spread_note
    from opspec.statistics.no_spread import no_spread

    # a population's subgroups: 6 independent users and all 8 alike
    note = no_spread_note([{"ci95_no_spread": no_spread([4.0, 4.0], 8)},
                           {"ci95_no_spread": no_spread([4.0, 4.0], 6)}, {"ci95": [1, 2]}])
    assert note.startswith("† all the users of each marked interval (6 or 8) gave the same "
                           "value")
    assert "with 6 users all alike (the fewest), up to 45.9 % of users" in note
