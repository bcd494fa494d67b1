"""Monitors a spec declares (``opspec:Monitor``) outside tests: `opspec evaluate` turns them into
hazards with intervals (table, JSON, report), `opspec run` lists their violations, and
`opspec validate` rejects one it cannot read — at the attribute's line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from evaluation_inputs import SPEC, USERS_TOML

from opspec.cli import main
from opspec.properties.language import clock

ANCHOR = "  <ExtendedAttributes>\n    <ExtendedAttribute Name=\"opspec:Metrics\">"


def spec_with(tmp_path: Path, *monitors: str) -> Path:
    """The dispenser spec with ``monitors`` declared at package level (and its user model)."""
    text = SPEC.read_text(encoding="utf-8")
    assert ANCHOR in text
    lines = "".join(f'    <ExtendedAttribute Name="opspec:Monitor" Value="{m}"/>\n'
                    for m in monitors)
    path = tmp_path / "dispenser_monitored.xpdl"
    path.write_text(text.replace(ANCHOR, ANCHOR.split("\n")[0] + "\n" + lines
                                 + ANCHOR.split("\n")[1]), encoding="utf-8")
    (tmp_path / "dispenser_monitored.users.toml").write_text(
        USERS_TOML.read_text(encoding="utf-8"), encoding="utf-8")
    return path


def test_evaluation_reports_each_monitor_as_a_hazard_per_user_day(evaluate, tmp_path):
    # 4 h between doses exactly: a late report followed by an on-time one violates min_gap
    # 4h; nothing can bring two dispenses within 3.75 h.
    spec = spec_with(tmp_path, "min_gap dispense 4h", "min_gap dispense 3.75h")
    status, doc, _ = evaluate(str(spec), "--users", "20", "--days", "3", "--seed", "2",
                              "--workers", "1", "--out", str(tmp_path / "out"),
                              report=False)    # the report's monitors: test below
    assert status == 0                      # violations are findings, not a failed run
    tight, loose = doc["monitors"]["min_gap dispense 4h"], doc["monitors"]["min_gap dispense 3.75h"]
    assert tight["users"] == loose["users"] == 20
    assert tight["violations"] > 0 and 0 < tight["users_affected"] <= 20
    assert tight["per_user_day"] == pytest.approx(tight["violations"] / 60)
    lo, hi = tight["ci95"]
    assert 0 < lo < tight["per_user_day"] < hi
    assert tight["first"]["message"].startswith("activity dispense at d1 ")
    assert loose["violations"] == 0 and loose["users_affected"] == 0
    # no violation still bounds the hazard: the exact Poisson upper limit, 3.689 / 60 user-days
    assert loose["ci95"] == [0.0, pytest.approx(3.689 / 60, rel=1e-3)]
    low, high = tight["share_affected_ci95"]
    assert low <= tight["share_affected"] <= high


def test_monitor_counts_do_not_depend_on_the_number_of_workers(evaluate, tmp_path):
    spec = spec_with(tmp_path, "min_gap dispense 4h")
    args = [str(spec), "--users", "8", "--days", "2", "--seed", "4"]
    _, one, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"), report=False)
    _, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"), report=False)
    assert one["monitors"] == two["monitors"]


def test_summary_table_and_report_show_the_monitors(tmp_path, capsys):
    spec = spec_with(tmp_path, "min_gap dispense 4h")
    out = tmp_path / "out"
    status = main(["evaluate", str(spec), "--users", "10", "--days", "2", "--workers", "1",
                   "--out", str(out), "--quiet"])
    printed = capsys.readouterr().out
    assert status == 0
    assert "monitors (opspec:Monitor in the spec; violations per user-day):" in printed
    row = next(line for line in printed.splitlines() if line.startswith("min_gap dispense 4h"))
    assert " of 10 (" in row and "[" in row
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "Safety monitors the spec declares" in report
    assert "min\\_gap dispense 4h" in report


def test_a_spec_without_monitors_has_an_empty_monitors_object(evaluate, tmp_path):
    status, doc, _ = evaluate(str(SPEC), "--users", "2", "--days", "1", "--workers", "1",
                              "--out", str(tmp_path / "out"), report=False)
    assert status == 0 and doc["monitors"] == {}


def test_a_bad_monitor_stops_the_evaluation_before_it_starts(tmp_path, capsys):
    spec = spec_with(tmp_path, "min_gap dispence 4h")
    out = tmp_path / "out"
    status = main(["evaluate", str(spec), "--users", "2", "--days", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2
    assert f"{spec}:" in err and "'dispence'" in err and "its activities are:" in err
    assert not out.exists()
    assert "Traceback" not in err


def test_run_lists_the_violations_of_each_monitor(tmp_path, capsys):
    spec = spec_with(tmp_path, "min_gap dispense 4h", "never notify_caregiver")
    # the user reports 8 min after the first alarm each time: the next dose is < 4 h later
    steps = tmp_path / "late.toml"
    steps.write_text('otherwise = "complete"\nsteps = [["after trg_2 480s", "press_report"]]\n',
                     encoding="utf-8")
    status = main(["run", str(spec), "--until", str(13 * 3600), "--script", str(steps),
                   "--timeline", "none"])
    printed = capsys.readouterr().out
    assert status == 0
    assert "monitor min_gap dispense 4h: 1 violation(s)" in printed
    assert "monitor never notify_caregiver: no violation" in printed
    status = main(["run", str(spec), "--until", str(13 * 3600), "--script", str(steps),
                   "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert doc["monitors"]["min_gap dispense 4h"]["violations"] == 1
    assert doc["monitors"]["never notify_caregiver"] == {"violations": 0, "first": []}


@pytest.mark.parametrize("monitor, message", [
    ("min_gap dispence 4h", "the spec has no activity, trigger or process 'dispence'"),
    ("min_gap dispense whenever", "cannot read duration 'whenever': not a duration"),
    ("at most twice", "cannot read the monitor 'at most twice'"),
], ids=["unknown-name", "bad-duration", "unreadable"])
def test_validate_reports_a_bad_monitor_at_its_line(monitor, message, tmp_path, capsys):
    spec = spec_with(tmp_path, monitor)
    line = spec.read_text(encoding="utf-8").splitlines().index(
        f'    <ExtendedAttribute Name="opspec:Monitor" Value="{monitor}"/>') + 1
    status = main(["validate", str(spec)])
    out = capsys.readouterr().out
    assert status == 1
    assert f"{spec}:{line}: error: " in out and message in out and "Traceback" not in out


def test_times_in_messages_never_show_sixty_seconds():
    # times are shown to the millisecond (opspec.clock.clock_time); what rounds up rounds
    # into the next minute or day, never to ":60"
    assert clock(12 * 3600 + 59.96) == "d1 12:00:59.960"
    assert clock(12 * 3600 + 59.9996) == "d1 12:01:00"
    assert clock(86_399.9997) == "d2 00:00:00"
    assert clock(8 * 3600 + 0.04) == "d1 08:00:00.040"
