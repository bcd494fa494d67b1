"""An evaluation of one simulated user (``--users 1``): the intervals that need the spread
between users are '–', and the table says why, in the terminal and in the report; "1 users"
is "1 user". The dashes stood there unexplained beside the exact intervals of the counts
with few events and of the proportions."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
NOTE = ("– (no interval) for alarms, report_latency_s, alarms_per_dose: one simulated user "
        "shows no spread between users to compute it from; evaluate two users or more")


@pytest.fixture(scope="module")
def one_user(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Path]:
    out = tmp_path_factory.mktemp("one") / "run"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["evaluate", str(SPEC), "--users", "1", "--days", "2", "--workers", "1",
                     "--quiet", "--out", str(out)]) == 0
    return printed.getvalue(), out


def test_the_terminal_says_why_an_interval_is_missing(one_user: tuple[str, Path]) -> None:
    text, _ = one_user
    assert NOTE in text
    assert ", 1 user x 2 days," in text and "over the 1 user (the independent units)" in text
    assert "\n1 replication in " in text


def test_the_report_says_it_too(one_user: tuple[str, Path]) -> None:
    report = (one_user[1] / "report.md").read_text(encoding="utf-8")
    assert NOTE.replace("_", "\\_") in report
    assert "1 simulated user × 2 days each" in report


def test_two_users_need_no_such_note() -> None:
    from opspec.evaluation.tables import one_user_note

    metrics = {"alarms": {"ci95": [None, None]}}
    assert one_user_note(metrics, 2) is None
    assert one_user_note(metrics, 1) is not None
