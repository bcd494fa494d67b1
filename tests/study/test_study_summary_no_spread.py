"""A study's summary says of an interval of no width what `opspec evaluate` says of it
(docs/evaluation.md, *Intervals of no width*): three participants who all gave the same value
make `[131.1, 131.1] s`, which read as a value known exactly; it is marked `†`, one note in
evaluate's words says what the mark means, and `--json` carries `ci95_no_spread` beside
every `ci95`. Before, the summary printed such intervals bare.

The sessions' metrics are given (their traces are not what is under test): every
participant took 131.1 s to report in A and 49.76 s in B, rang 5 alarms for 4 doses in A and
10 in B, and missed 0 doses in A and 0, 1 or 2 in B."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import opspec.tui.study_summary
from opspec.cli import main
from opspec.evaluation.no_spread_notes import no_spread_note
from opspec.statistics.no_spread import unlike_share_high
from opspec.tui.study import load_protocol

MISSED = {"P01": 0.0, "P02": 1.0, "P03": 2.0}


@pytest.fixture
def all_done(protocol_file: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    protocol = load_protocol(protocol_file)
    for participant in protocol.participants:
        for session in protocol.sessions(participant):
            session.done_marker.parent.mkdir(parents=True, exist_ok=True)
            session.done_marker.write_text(json.dumps({"spec": str(session.variant.spec)}),
                                           encoding="utf-8")

    def pairs(session) -> dict[str, tuple[float, float]]:
        if session.variant.id == "A":
            return {"report_latency_s": (131.1, 1.0), "alarms_per_dose": (5.0, 4.0),
                    "doses_missed": (0.0, 1.0)}
        return {"report_latency_s": (49.76, 1.0), "alarms_per_dose": (10.0, 4.0),
                "doses_missed": (MISSED[session.participant], 1.0)}

    monkeypatch.setattr(opspec.tui.study_summary, "session_pairs", pairs)
    return protocol_file


def test_an_interval_of_participants_all_alike_is_marked_and_explained(
        all_done: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["study", str(all_done)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "  report_latency_s: 131.1 s (95 % CI [131.1, 131.1] s †; n = 3)" in lines
    assert ("  alarms_per_dose: 1.25 -> 2.5, difference +1.25 (95 % CI [+1.25, +1.25] †; "
            "n = 3)") in lines
    assert ("  report_latency_s: 131.1 s -> 49.76 s, difference -81.34 s (95 % CI [-81.34, "
            "-81.34] s †; n = 3)") in lines
    # an interval with a width is not marked
    missed = [line for line in lines if line.startswith("  doses_missed:")]
    assert len(missed) == 3 and not any("†" in line for line in missed)
    # one note, last, in the words opspec evaluate writes under its tables
    assert lines[-2] == ""
    assert lines[-1] == (
        "† all 3 users gave the same value (or the same difference between the designs), so "
        "the interval has no width: it shows no spread between users, not a value known "
        "exactly. Unless the spec fixes the value (a count of events on a fixed schedule), "
        "more users are needed to estimate its interval: with 3 users all alike, up to "
        "70.8 % of users could give another value (exact 95 % bound).")
    # A and B each two, the two differences, the note
    assert sum("†" in line for line in lines) == 2 + 2 + 2 + 1


def test_the_json_carries_ci95_no_spread_beside_every_ci95(
        all_done: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["study", str(all_done), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    alike = {"users": 3, "share_unlike_ci95_high": pytest.approx(unlike_share_high(3)),
             "too_few_users": True}
    for variant in ("A", "B"):
        metrics = doc["variants"][variant]["metrics"]
        assert metrics["report_latency_s"]["ci95_no_spread"] == alike
        assert metrics["alarms_per_dose"]["ci95_no_spread"] == alike
    assert doc["variants"]["B"]["metrics"]["doses_missed"]["ci95_no_spread"] is None
    rows = doc["comparisons"][0]["metrics"]
    assert rows["report_latency_s"]["ci95_no_spread"] == alike
    assert rows["alarms_per_dose"]["ci95_no_spread"] == alike
    assert rows["doses_missed"]["ci95_no_spread"] is None
    # the note the text ends with is evaluate's own, from these very rows
    assert no_spread_note([*doc["variants"]["A"]["metrics"].values(),
                           *rows.values()]).startswith("† all 3 users gave the same value")
