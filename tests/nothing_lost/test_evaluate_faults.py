"""A run-time fault reaches the estimate: `opspec evaluate` of a spec whose condition divides
by zero on a rare branch (the dispenser's second re-alarm) fails the replications that reach
it — counted, named with the fault's file:line in the terminal, ``--json`` and the report,
exit status 1 — computes every number from the complete replications only, and ``--resume``
does not take the failed ones as done. No dose goes missing from the books:
taken + missed + failed = due."""

from __future__ import annotations

import json
import re
import sqlite3
from pathlib import Path

from opspec.cli import main


def _evaluate(capsys, *args: str) -> tuple[int, str, str]:
    status = main(["evaluate", *args])
    out = capsys.readouterr()
    return status, out.out, out.err


def _total(metrics: dict, name: str) -> int:
    return int(metrics[name]["total"])


def test_a_fault_on_a_rare_branch_fails_the_evaluation_and_loses_no_dose(
        broken_spec: Path, fault_site: str, tmp_path: Path, capsys) -> None:
    out = tmp_path / "run"
    status, stdout, _ = _evaluate(capsys, str(broken_spec), "--users", "6", "--days", "3",
                                  "--seed", "2", "--workers", "1", "--out", str(out), "--json")
    assert status == 1
    doc = json.loads(stdout)
    where = fault_site
    counts = doc["replications"]
    assert counts["planned"] == 6 and counts["failed"] == len(doc["failed"]) >= 1
    assert counts["complete"] + counts["failed"] == 6 and counts["complete"] >= 1
    for failed in doc["failed"]:
        assert failed["kind"] == "fault"
        assert failed["error"].startswith(f"fault: {where}: activity 'R'")
        assert "division by zero" in failed["error"]
    # every number is of the complete replications only
    assert doc["metrics"]["doses_due"]["users"] == counts["complete"]

    with sqlite3.connect(out / "results.sqlite") as db:
        rows = [(status_, error, json.loads(metrics)) for status_, error, metrics in
                db.execute("SELECT status, error, metrics FROM replication")]
        # a failed replication leaves no sample, outcome or activity row behind to leak
        # into the report's figures
        failed_users = [u for (u,) in db.execute(
            "SELECT user FROM replication WHERE status = 'failed'")]
        for table in ("sample", "outcome", "activity"):
            assert not db.execute(f"SELECT COUNT(*) FROM {table} WHERE user IN "
                                  f"({','.join('?' * len(failed_users))})",
                                  failed_users).fetchone()[0]
    complete = [m for s, _, m in rows if s == "done"]
    failed = [(e, m) for s, e, m in rows if s == "failed"]
    assert len(failed) == counts["failed"]
    due = sum(_total(m, "doses_due") for _, _, m in rows)
    taken = sum(_total(m, "doses_taken") for m in complete)
    missed = sum(_total(m, "doses_missed") for m in complete)
    failed_doses = sum(_total(m, "doses_due") for _, m in failed)
    assert taken + missed + failed_doses == due
    # within a failed replication, each fault is one dose neither taken nor missed
    for error, m in failed:
        more = re.search(r"\(and (\d+) more faults? in this run\)", error)
        faults = 1 + (int(more.group(1)) if more else 0)
        assert _total(m, "doses_taken") + _total(m, "doses_missed") + faults == _total(
            m, "doses_due")
    # the estimate is the complete replications' own
    assert doc["metrics"]["doses_due"]["total"] == sum(_total(m, "doses_due")
                                                       for m in complete)

    html = (out / "report.html").read_text(encoding="utf-8")
    assert "Failed replications" in html and "division by zero" in html
    assert f"{where}" in html

    # --resume runs the failed replications again (the same seed: the same fault), and
    # the terminal output names it
    args = ("--resume", "--out", str(out), "--quiet")
    status, terminal, _ = _evaluate(capsys, *args)
    assert status == 1
    assert f"{counts['failed']} of 6 replications FAILED" in terminal
    assert "complete replications only" in terminal
    assert re.search(rf"A/\d+: fault: {re.escape(where)}: .*division by zero", terminal)
    assert "fix the spec" in terminal

    # a store written before faults failed a replication: status done, the fault in the
    # error column. --resume runs those again instead of accepting them as done.
    with sqlite3.connect(out / "results.sqlite") as db:
        db.execute("UPDATE replication SET status = 'done' WHERE status = 'failed'")
    status, again, _ = _evaluate(capsys, *args, "--json")
    assert status == 1
    resumed = json.loads(again)
    assert resumed["failed"] == doc["failed"]
    assert resumed["replications"] == counts


