"""A walkthrough study driven by Textual's Pilot: three participants, two variants of the
dispenser (re-alarm after 300 s, or after 30 s), counterbalanced orders, every session
recorded under its participant and variant, one session broken off and resumed, and the
paired comparison of the two designs at the end."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.tui.study import finish_session, latin_square, load_protocol, session_app, summary
from study_sessions import perform


def test_williams_squares_balance_first_places_and_carry_over() -> None:
    """Williams (1949): in a Latin square for an even number n of treatments each treatment
    precedes every other exactly once; for odd n the square and its mirror image do so
    twice. Each row is an order (a permutation) and each treatment is in each position
    equally often."""
    for k in (2, 3, 4, 5, 6):
        rows = latin_square(k)
        assert all(sorted(r) == list(range(k)) for r in rows)
        for position in range(k):
            column = [r[position] for r in rows]
            assert all(column.count(t) == len(rows) // k for t in range(k))
        follows = {(r[i], r[i + 1]) for r in rows for i in range(k - 1)}
        pairs = [(r[i], r[i + 1]) for r in rows for i in range(k - 1)]
        assert len(follows) == k * (k - 1)                   # every ordered pair occurs
        assert all(pairs.count(p) == (1 if k % 2 == 0 else 2) for p in follows)


@pytest.mark.slow          # seven Textual sessions
def test_three_participants_two_variants(protocol_file: Path, capsys) -> None:
    protocol = load_protocol(protocol_file)
    assert [v.id for v in protocol.order("P01")] == ["A", "B"]
    assert [v.id for v in protocol.order("P02")] == ["B", "A"]      # counterbalanced
    assert [v.id for v in protocol.order("P03")] == ["A", "B"]

    # P03 breaks off their first session half-way
    first = protocol.pending("P03")[0]
    app, walk = session_app(protocol, first)
    asyncio.run(perform(app, walk, until_end=False))
    assert not finish_session(first, walk)
    assert protocol.pending("P03")[0] == first                      # still to do

    for participant in protocol.participants:
        for session in protocol.pending(participant):
            app, walk = session_app(protocol, session)
            told = asyncio.run(perform(app, walk))
            assert told == session.variant.told
            assert finish_session(session, walk)
    rec = protocol.recordings
    for participant in ("P01", "P02", "P03"):
        for variant in ("A", "B"):
            assert (rec / participant / f"{variant}.json").is_file()
            header = json.loads((rec / participant / f"{variant}.trace.jsonl")
                                .read_text().splitlines()[0])
            assert header["person"] == participant
    # the broken-off attempt is kept apart, the session was done again in full
    assert (rec / "P03" / "A.partial-1.json").is_file()
    assert not protocol.pending("P03")

    doc = summary(protocol)
    comparison = doc["comparisons"][0]
    assert (comparison["a"], comparison["b"]) == ("A", "B")
    assert comparison["participants"] == ["P01", "P02", "P03"]
    alarms = comparison["metrics"]["alarms_per_dose"]
    assert alarms["participants"] == 3
    # a re-alarm after 30 s rings more often for the same people than after 5 minutes
    assert alarms["b"] > alarms["a"]
    assert alarms["difference"] == pytest.approx(alarms["b"] - alarms["a"])
    # the command prints the same, paired over the three participants
    assert main(["study", str(protocol_file)]) == 0
    out = capsys.readouterr().out
    assert "B - A, paired over 3 participant(s)" in out
    assert "alarms_per_dose" in out


def test_a_protocol_naming_a_missing_spec_is_refused(tmp_path: Path, capsys) -> None:
    protocol = tmp_path / "study.toml"
    protocol.write_text('[study]\nparticipants = ["P1"]\n[[variants]]\nid = "A"\n'
                        'spec = "nowhere.xpdl"\n', encoding="utf-8")
    assert main(["study", str(protocol)]) == 2
    err = capsys.readouterr().err
    # at the line the key is written on, so that an editor jumps to it
    assert f"{protocol}:5: variants[0].spec: no spec at" in err


def test_a_protocol_key_error_is_placed_at_its_line(tmp_path: Path, capsys) -> None:
    protocol = tmp_path / "study.toml"
    (tmp_path / "pill.xpdl").write_text("", encoding="utf-8")   # found; never read
    protocol.write_text('[study]\nparticipants = ["P1"]\ndays = -2\n[[variants]]\nid = "A"\n'
                        'spec = "pill.xpdl"\n', encoding="utf-8")
    assert main(["study", str(protocol)]) == 2
    assert f"{protocol}:3: study.days: must be a positive number" in (
        capsys.readouterr().err)


def test_an_unknown_participant_is_refused(protocol_file: Path, capsys) -> None:
    assert main(["study", str(protocol_file), "--participant", "P99"]) == 2
    assert "participant 'P99' is not in the protocol" in capsys.readouterr().err
