"""Recordings name the instance acted on, so a replay does the same thing to the same
instance; old recordings without the tags still replay; a script naming what the spec lacks
is refused before anything opens."""

from __future__ import annotations

import json

import pytest
from walkthrough_inputs import SPEC

from opspec.errors import ConfigurationError
from opspec.testing.script import load_script
from opspec.tui.replay import instance_tag, load_recording, tagged_action
from opspec.tui.session import WalkSession

KINDS = ("activity.", "process.", "trigger.", "deadline.")


def trace(session: WalkSession) -> list[tuple]:
    return [(e.time, e.kind, e.process, e.instance, e.activity) for e in session.events
            if e.kind.startswith(KINDS)]


def newest(session: WalkSession, activity: str):
    return max((o for o in session.offers if o.item.activity == activity),
               key=lambda o: o.item.instance)


def test_a_replay_acts_on_the_same_instance_when_identical_offers_wait(compiled, tmp_path):
    record = tmp_path / "pick.json"
    session = WalkSession(compiled, record=record)
    session.skip_until_user()                     # 08:00: the first alarm
    while session.now < 8 * 3600 + 600:           # ignore it and the 08:05 re-alarm
        session.skip_to_next_event()
    offer = newest(session, "hear_alarm")         # answer the 08:10 alarm
    session.act(offer)
    for activity in ("walk_to_dispenser", "choose_button"):
        session.run_to(session.now + 30)
        session.act(next(o for o in session.offers if o.item.activity == activity))
    session.run_to(session.now + 600)
    session.close()
    steps = json.loads(record.read_text(encoding="utf-8"))["steps"]
    assert steps[0][1] == f"complete hear_alarm #{offer.item.instance}"

    again = WalkSession(compiled, replay=load_recording(record, compiled))
    again.run_to(session.now)
    assert trace(again) == trace(session)         # instances included


def test_a_recording_without_instance_tags_still_replays(compiled, tmp_path):
    old = tmp_path / "old.json"
    old.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"],'
                   ' ["at 28890.0", "complete walk_to_dispenser"],'
                   ' ["at 28890.0", "choose press_report"]]}', encoding="utf-8")
    session = WalkSession(compiled, replay=load_recording(old, compiled))
    session.run_to(9 * 3600)
    assert session.sim.metrics.values()["report_latency_s"]["mean"] == pytest.approx(90.0)


def test_the_script_language_accepts_a_recording_with_tags(compiled, tmp_path):
    record = tmp_path / "tagged.json"
    record.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete '
                      'hear_alarm #4"], ["at 28890.0", "fail walk_to_dispenser #4 tripped"]]}',
                      encoding="utf-8")
    script = load_script(record)                   # what `opspec run --script` reads
    assert [s.target for s in script.steps] == ["hear_alarm", "walk_to_dispenser"]
    assert script.steps[1].exception == "tripped"


@pytest.mark.parametrize(("action", "instance"), [
    (tagged_action("complete", "hear_alarm", 6), 6),
    (tagged_action("fail", "take_pill", 12, "dropped"), 12),
    ("complete hear_alarm", None),
    ("complete weigh weight=71.5", None),
], ids=["complete", "fail-with-exception", "untagged", "data-field"])
def test_the_instance_tag_reads_back(action, instance):
    assert instance_tag(action) == instance


def test_replaying_a_script_that_names_what_the_spec_lacks_is_refused(compiled, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"steps": [["at 10", "complete nonexistent_activity"]]}', encoding="utf-8")
    with pytest.raises(ConfigurationError, match="nonexistent_activity.*spec does not have"):
        load_recording(bad, compiled)


def test_the_walkthrough_command_refuses_a_replay_with_unknown_names(tmp_path, capsys):
    from opspec.cli import main

    bad = tmp_path / "bad.json"
    bad.write_text('{"steps": [["at 10", "complete nonexistent_activity"]]}', encoding="utf-8")
    assert main(["walkthrough", str(SPEC), "--replay", str(bad)]) == 2
    assert "nonexistent_activity" in capsys.readouterr().err


def test_opspec_run_script_honours_the_instance_tags_too(compiled, tmp_path, capsys):
    """The same recording through `opspec run --script`: the tagged step waits for its own
    instance's offer (the 08:10 alarm), not the first hear_alarm offered (08:00)."""
    from opspec.cli import main

    record = tmp_path / "pick.json"
    session = WalkSession(compiled, record=record)
    session.skip_until_user()
    while session.now < 8 * 3600 + 600:
        session.skip_to_next_event()
    offer = newest(session, "hear_alarm")
    session.act(offer)
    session.close()
    trace_file = tmp_path / "run.jsonl"
    status = main(["run", str(SPEC), "--until", str(9 * 3600), "--script", str(record),
                   "--trace", str(trace_file), "--json"])
    capsys.readouterr()
    assert status == 0
    heard = [json.loads(line) for line in trace_file.read_text(encoding="utf-8").splitlines()
             if '"activity.completed"' in line and '"hear_alarm"' in line]
    assert [(e["instance"], e["time"]) for e in heard] == [(offer.item.instance,
                                                            pytest.approx(session.now))]


def test_the_walkthrough_command_refuses_record_with_replay(tmp_path, capsys):
    """A replay records nothing: ``--record`` with it was silently ignored (no file, no word),
    so a researcher who asked for the replay's recording found none."""
    from opspec.cli import main

    rec = tmp_path / "rec.json"
    rec.write_text('{"otherwise": "wait", "steps": [["at 28800", "complete hear_alarm"]]}',
                   encoding="utf-8")
    out = tmp_path / "again.json"
    assert main(["walkthrough", str(SPEC), "--replay", str(rec), "--record", str(out)]) == 2
    err = capsys.readouterr().err
    assert "with --replay: a replay records nothing" in err and "--trace" in err
    assert not out.exists()
