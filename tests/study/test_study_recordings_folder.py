"""A recordings folder that already holds sessions done with another spec (another study's
folder, or a protocol edited after its sessions): `opspec study` refuses, naming the marker,
instead of counting them as done and replaying their traces with the wrong metrics."""

from __future__ import annotations

import json
from pathlib import Path

from opspec.cli import main
from opspec.tui.study import load_protocol


def _mark_done(protocol_file: Path, participant: str, variant: str, spec: str) -> Path:
    protocol = load_protocol(protocol_file)
    session = next(s for s in protocol.sessions(participant) if s.variant.id == variant)
    session.done_marker.parent.mkdir(parents=True, exist_ok=True)
    session.done_marker.write_text(json.dumps({"participant": participant, "variant": variant,
                                               "spec": spec}), encoding="utf-8")
    return session.done_marker


def test_sessions_done_with_another_spec_are_refused(protocol_file: Path, capsys) -> None:
    marker = _mark_done(protocol_file, "P02", "B", "/elsewhere/vacuum_cleaner.xpdl")
    for extra in ([], ["--json"], ["--participant", "P01"]):
        assert main(["study", str(protocol_file), *extra]) == 2
        err = capsys.readouterr().err
        assert (f"{marker}: session B of P02 was recorded with vacuum_cleaner.xpdl, but "
                "variant B is now dispenser-30s.xpdl") in err
        assert "give this study a folder of its own" in err


def test_the_same_spec_in_another_folder_is_the_same(protocol_file: Path, capsys) -> None:
    # a study folder moved to another machine: the spec's path differs, its name does not
    marker = _mark_done(protocol_file, "P02", "B", "/old/place/dispenser-30s.xpdl")
    trace = marker.with_suffix(".trace.jsonl")
    assert main(["run", str(protocol_file.parent / "dispenser-30s.xpdl"), "--days", "1",
                 "--trace", str(trace)]) == 0
    capsys.readouterr()
    assert main(["study", str(protocol_file), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["status"]["P02"]["B"] is True


def test_a_done_session_whose_trace_is_gone_or_cut_is_named(protocol_file: Path,
                                                            capsys) -> None:
    marker = _mark_done(protocol_file, "P02", "B", "dispenser-30s.xpdl")
    trace = marker.with_suffix(".trace.jsonl")
    assert main(["study", str(protocol_file)]) == 2          # was an internal error
    err = capsys.readouterr().err
    assert f"{trace}: the trace of a session marked done cannot be read" in err
    assert "delete B.done to run the session again" in err
    assert main(["run", str(protocol_file.parent / "dispenser-30s.xpdl"), "--days", "1",
                 "--trace", str(trace)]) == 0
    text = trace.read_text(encoding="utf-8")
    trace.write_text(text[:len(text) // 2].rstrip("\n")[:-7], encoding="utf-8")
    capsys.readouterr()
    assert main(["study", str(protocol_file)]) == 2          # was summarised as whole
    assert f"{trace}: the trace of a session marked done ends in a cut line" in \
        capsys.readouterr().err


def test_a_marker_that_names_no_spec_is_refused(protocol_file: Path, capsys) -> None:
    marker = _mark_done(protocol_file, "P01", "A", "x")
    marker.write_text("{}", encoding="utf-8")
    assert main(["study", str(protocol_file)]) == 2
    assert f"{marker}: this session's done marker does not say" in capsys.readouterr().err


def test_a_participant_put_before_others_is_refused(protocol_file: Path, capsys) -> None:
    # P02 did B first (row 2 of the square); a participant inserted before P02 moves P02
    # to row 3, A first: the rest of P02's sessions would run out of balance
    marker = _mark_done(protocol_file, "P02", "B", "dispenser-30s.xpdl")
    written = json.loads(marker.read_text(encoding="utf-8"))
    marker.write_text(json.dumps({**written, "position": 1}), encoding="utf-8")
    text = protocol_file.read_text(encoding="utf-8")
    protocol_file.write_text(text.replace('["P01", "P02", "P03"]',
                                          '["P01", "P00", "P02", "P03"]'), encoding="utf-8")
    assert main(["study", str(protocol_file)]) == 2
    err = capsys.readouterr().err
    assert (f"{marker}: P02 did variant B as session 1, but the protocol now puts it at 2: "
            "the participants' order changed") in err
    assert "add new participants at its end" in err
